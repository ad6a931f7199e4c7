#!/usr/bin/env bash
# Sets up, builds and opens the viewer on the built-in Cornell box; with no display it renders
# the same scene headlessly and prints where the image went.
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
"$here/scripts/setup.sh"
exe=${VPLVIEW_BUILD:-$here/build}/vplview
if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] && "$exe" --help 2>/dev/null | grep -q -- --screenshot; then
  exec "$exe" "$@"
fi
out=${VPLVIEW_OUT:-$here/build/cornell}
"$exe" render "$here/scenes/cornell_box.gltf" --mode brdf --time 10 --out "$out.exr" --png "$out.png" "$@"
echo "no display: rendered the Cornell box headlessly to $out.png and $out.exr" >&2
