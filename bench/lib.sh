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

# The end of a reference's name before .exr: nothing for brdf's, _MODE for another mode's.
ref_suffix() { [ "${1:-brdf}" = brdf ] || echo "_$1"; }

# The path of a scene's converged reference (`vplview reference`, brdf unless MODE is given), made on
# first use and cached in OUT as ref_NAME_HASH_revR_WxH_SPPspp_dDEPTH[_MODE].exr, so that a changed scene never
# reuses an old one, nor a reference made before a fix that changed converged images (R, REF_REVISION). A guided mode converges to the same image (the mode-agreement tests) with far less
# error per second on scenes lit indirectly, where a brdf reference's own error would dominate.
# Usage: ref=$(cached_reference EXE SCENE_FILE NAME OUT W H SPP DEPTH THREADS [MODE]); progress goes to stderr.
# 2: shadow rays aimed at the light point (23d3a35); before, lights seen at grazing angles were too dark
# (lamp_rooms 0.7 %).
REF_REVISION=2
cached_reference() {
  local exe=$1 scene=$2 name=$3 out=$4 w=$5 h=$6 spp=$7 depth=$8 threads=$9 mode=${10:-brdf}
  local ref=$out/ref_${name}_$(scene_hash "$scene")_rev${REF_REVISION}_${w}x${h}_${spp}spp_d${depth}$(ref_suffix "$mode").exr
  if [ ! -f "$ref" ]; then
    echo "$(date -Is) $name: $mode reference, $spp spp, depth $depth (cached as $(basename "$ref"))" >&2
    "$exe" reference "$scene" --mode "$mode" --spp "$spp" --width "$w" --height "$h" --threads "$threads" \
      --max-depth "$depth" --out "$ref.tmp.exr" >/dev/null
    mv "$ref.tmp.exr" "$ref"
  fi
  echo "$ref"
}
