# Helpers shared by the benchmark scripts (sourced, not run).

# The last line of a command's output is one JSON object: print the given keys of it, space-separated.
json() { python3 -c 'import json,sys; j=json.loads(sys.stdin.read().strip().splitlines()[-1]); print(" ".join(str(j[k]) for k in sys.argv[1:]))' "$@"; }

# The file of a built-in scene: scenes/NAME.gltf, else BUILD/scenes/NAME.glb (generated at build time).
# Exits with 2 when neither exists. Usage: scene_file REPO BUILD NAME WHO
scene_file() {
  local f=$1/scenes/$3.gltf
  [ -f "$f" ] || f=$2/scenes/$3.glb
  [ -f "$f" ] || { echo "$4: no scene $3" >&2; exit 2; }
  echo "$f"
}

# A scene's content hash (its .bin too, when there is one): the key of cached references.
scene_hash() { local bin=${1%.*}.bin; cat "$1" $([ -f "$bin" ] && echo "$bin") | sha1sum | cut -c1-10; }
