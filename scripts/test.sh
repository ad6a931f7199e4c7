#!/usr/bin/env bash
# Sets up, builds and runs the whole test suite through CTest.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup.sh"
cd "${VPLVIEW_BUILD:-$here/build}"
ctest --output-on-failure --parallel "$(nproc)" --timeout 900 "$@"
