#!/usr/bin/env bash
# Variants of vplview at equal time against one reference per scene, one seed: the quick A/B of a
# sampling change (bench/vs_cycles.sh is the full table against Cycles).
#
# Usage: bench/equal_time.sh BUILD_DIR REF_DIR SECONDS SEED 'LABEL|FLAGS;LABEL|FLAGS...' SCENE...
#   REF_DIR holds ref_SCENE_*_revR_*.exr (the references bench/vs_cycles.sh caches, R = REF_REVISION; with REF_MODE=MODE set, the
#   ones it made with that REF_MODE, ref_SCENE_*_MODE.exr, else the brdf ones); the Cornell box renders at
#   256x256, other scenes at 320x240, 2 threads, max depth 32. Prints one line per scene and variant:
#   scene, label, spp, mis's BSDF probability (learned: the mean), the join depth --join-depth auto chose, relMSE.
# Example: bench/equal_time.sh build OUT/vs_cycles 10 1 'brdf|--mode brdf;mis|--mode mis' cornell_box door_ajar
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
source "$here/bench/lib.sh"
[ $# -ge 6 ] || { sed -n 2,10p "$0" >&2; exit 2; }
build=$1 refs=$2 seconds=$3 seed=$4 variants=$5
shift 5
exe=$build/vplview
IFS=';' read -ra configs <<< "$variants"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
for name in "$@"; do
  scene=$(scene_file "$here" "$build" "$name" equal_time)
  if [ -n "${REF_MODE:-}" ] && [ "$REF_MODE" != brdf ]; then
    ref=$(ls "$refs"/ref_"$name"_*_rev"$REF_REVISION"_*_"$REF_MODE".exr 2>/dev/null | head -1 || true)
  else
    ref=$(ls "$refs"/ref_"$name"_*_rev"$REF_REVISION"_*.exr 2>/dev/null | grep -Ev '_(metropolis|mis|mixture|preview)[.]exr$' | head -1 || true)
  fi
  [ -n "$ref" ] || { echo "equal_time: no reference ref_${name}_*_rev${REF_REVISION}_*.exr in $refs (bench/lib.sh)" >&2; exit 2; }
  size=(--width 320 --height 240)
  [ "$name" = cornell_box ] && size=(--width 256 --height 256)
  for config in "${configs[@]}"; do
    label=${config%%|*}
    read -ra flags <<< "${config#*|}"
    "$exe" render "$scene" "${flags[@]}" --time "$seconds" "${size[@]}" --threads 2 --seed "$seed" --max-depth 32 \
      --out "$tmp/img.exr" 2>/dev/null | tail -1 > "$tmp/run.json"
    read -r spp prob depth < <(python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print(j["spp"], j.get("bsdf_prob", "-"), j.get("join_depth_chosen") if j.get("join_depth_chosen") is not None else "-")' "$tmp/run.json")
    rel=$("$exe" compare "$tmp/img.exr" "$ref" | json relmse)
    echo "$name $label seed $seed spp $spp bsdf_prob ${prob:-none} join_depth ${depth:--} relmse $rel"
  done
done
