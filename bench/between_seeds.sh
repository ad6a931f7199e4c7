#!/usr/bin/env bash
# Variants of vplview scored without a reference: each seed renders once, and the score is the relMSE
# between the images of two seeds (`vplview compare A B`: twice the variance for an unbiased estimator,
# where DESIGN.md §4 has the reference), one line per pair. For scenes whose converged reference would
# take longer than the comparison (the skylit hall, lamp_rooms), and for equal-spp comparisons.
#
# Usage: bench/between_seeds.sh BUILD_DIR OUT 'BUDGET' 'SEEDS' 'LABEL|FLAGS;LABEL|FLAGS...' SCENE...
#   BUDGET: vplview's own flag, '--time 10' or '--spp 64'; SEEDS: '1 2 3'. The Cornell box renders at
#   256x256, other scenes at 320x240, 2 threads, max depth 32; images and JSON lines stay in OUT.
#   Prints per run: spp, seconds, rays, the join depth `--join-depth auto` kept; then per pair: relMSE.
# Example: bench/between_seeds.sh build /tmp/bs '--spp 64' '1 2 3' 'every|--mode mis --join-depth -1;auto|--mode mis' lamp_rooms
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
source "$here/bench/lib.sh"
[ $# -ge 6 ] || { sed -n 2,11p "$0" >&2; exit 2; }
build=$1 out=$2 budget=$3 seeds=$4 variants=$5
shift 5
exe=$build/vplview
IFS=';' read -ra configs <<< "$variants"
read -ra budgetFlags <<< "$budget"
mkdir -p "$out"
for name in "$@"; do
  scene=$(scene_file "$here" "$build" "$name" between_seeds)
  size=(--width 320 --height 240)
  [ "$name" = cornell_box ] && size=(--width 256 --height 256)
  for seed in $seeds; do
    for config in "${configs[@]}"; do
      label=${config%%|*}
      read -ra flags <<< "${config#*|}"
      run=$out/${name}_${label}_$seed
      "$exe" render "$scene" "${flags[@]}" "${budgetFlags[@]}" "${size[@]}" --threads 2 --seed "$seed" --max-depth 32 \
        --out "$run.exr" | tail -1 > "$run.json"
      echo "$name $label seed $seed $(python3 -c 'import json,sys; j=json.load(open(sys.argv[1])); print("spp", j["spp"], "seconds", round(j["seconds"], 3), "rays", j["rays"], "join_depth", j.get("join_depth_chosen", "-"))' "$run.json")"
    done
  done
  for config in "${configs[@]}"; do
    label=${config%%|*}
    for a in $seeds; do
      for b in $seeds; do
        [ "$a" -lt "$b" ] || continue
        echo "$name $label pair $a-$b relmse $("$exe" compare "$out/${name}_${label}_$a.exr" "$out/${name}_${label}_$b.exr" | json relmse)"
      done
    done
  done
done
