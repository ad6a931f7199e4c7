#!/usr/bin/env bash
# Sets up, builds and opens the viewer on the built-in Cornell box (extra arguments go to vplview);
# with no display it captures the same scene headlessly through the viewer's display code (OSMesa)
# and prints where the picture went.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup.sh"
exe=${VPLVIEW_BUILD:-$here/build}/vplview
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec "$exe" "$@"
fi
out=${VPLVIEW_OUT:-$here/build/cornell.png}
"$exe" capture "$here/scenes/cornell_box.gltf" --mode mis --time 10 --width 640 --height 480 --out "$out" "$@"
echo "no display: captured the Cornell box headlessly to $out" >&2
