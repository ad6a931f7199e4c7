#!/usr/bin/env bash
# vplview against Cycles at equal samples per pixel (issue 15's second goal): the noise of one sample,
# whatever it costs. Complements bench/vs_cycles.sh (equal time), whose cached references it reuses.
#
#   bench/vs_cycles_equal_spp.sh BUILD_DIR OUT_DIR [SPP...]        (default: 64 1024)
#
# OUT_DIR must hold the reference bench/vs_cycles.sh made (ref_SCENE_*.exr); run that first.
# For every scene in SCENES (cornell_box door_ajar), spp and seed: Cycles, then vplview in each of
# MODES (brdf mis), all at the same spp, scored with `vplview compare` against that reference.
# Writes OUT_DIR/equal_spp_SPP.csv and prints a Markdown table of relMSE ratios (vplview ÷ Cycles).
# Environment: SEEDS ("1 2"), THREADS (2), MAX_DEPTH (32), CYCLES_RENDER, REF_MODE (brdf: the reference's mode, as
# bench/vs_cycles.sh names it; e.g. REF_MODE=mis takes ref_SCENE_*_mis.exr).
set -euo pipefail
build=$(cd "${1:?usage: vs_cycles_equal_spp.sh BUILD_DIR OUT_DIR [SPP...]}" && pwd)
out=$(cd "${2:?usage: vs_cycles_equal_spp.sh BUILD_DIR OUT_DIR [SPP...]}" && pwd)
shift 2
counts=${*:-64 1024}
here=$(cd "$(dirname "$0")/.." && pwd)
exe=$build/vplview
cycles=${CYCLES_RENDER:-$here/../shared/tools/cycles/cycles-render}
SCENES=${SCENES:-cornell_box door_ajar}; MODES=${MODES:-brdf mis}
SEEDS=${SEEDS:-1 2}; THREADS=${THREADS:-2}; MAX_DEPTH=${MAX_DEPTH:-32}; REF_MODE=${REF_MODE:-brdf}
[ -x "$exe" ] || { echo "vs_cycles_equal_spp: no $exe" >&2; exit 2; }
[ -x "$cycles" ] || { echo "vs_cycles_equal_spp: no $cycles (set CYCLES_RENDER)" >&2; exit 2; }
for n in $counts; do [[ $n =~ ^[1-9][0-9]*$ ]] || { echo "vs_cycles_equal_spp: '$n' is not a sample count" >&2; exit 2; }; done
. "$here/bench/lib.sh"
csv=$out/equal_spp_${counts// /_}.csv
echo "scene,spp,renderer,mode,seed,seconds,relmse" > "$csv"
refs=()  # "scene: reference file" for the table's footnote

for name in $SCENES; do
  scene=$here/scenes/$name.gltf
  if [ "$name" = cornell_box ]; then W=256 H=256; else W=320 H=240; fi
  ref=$(ls "$out"/ref_"${name}"_*_rev${REF_REVISION}_${W}x${H}_*spp_d${MAX_DEPTH}$(ref_suffix "$REF_MODE").exr 2>/dev/null | head -1)
  [ -n "$ref" ] || { echo "vs_cycles_equal_spp: no reference for $name in $out (run bench/vs_cycles.sh first)" >&2; exit 2; }
  refs+=("$name: $(basename "$ref")")
  for n in $counts; do
    for seed in $SEEDS; do
      img=$out/spp_${name}_${n}_cycles_seed$seed.exr
      secs=$("$cycles" "$scene" "$img" --width $W --height $H --spp $n --seed $seed --max-bounces $((MAX_DEPTH - 1)) \
                --threads $THREADS | json seconds)
      echo "$name,$n,cycles,path,$seed,$secs,$("$exe" compare "$img" "$ref" | json relmse)" | tee -a /dev/stderr >> "$csv"
      for mode in $MODES; do
        img=$out/spp_${name}_${n}_${mode}_seed$seed.exr
        secs=$("$exe" render "$scene" --mode $mode --spp $n --width $W --height $H --threads $THREADS --seed $seed \
                  --max-depth $MAX_DEPTH --out "$img" | json seconds)
        echo "$name,$n,vplview,$mode,$seed,$secs,$("$exe" compare "$img" "$ref" | json relmse)" | tee -a /dev/stderr >> "$csv"
      done
    done
  done
done

python3 - "$csv" "$MODES" "${refs[@]}" <<'PY'
import csv, sys
from statistics import mean
rows = list(csv.DictReader(open(sys.argv[1])))
modes = sys.argv[2].split()
keys = sorted({(r["scene"], int(r["spp"])) for r in rows})
print("| scene | spp | Cycles relMSE | " + " | ".join(f"{m} relMSE ÷ Cycles" for m in modes) + " | " +
      " | ".join(f"{m} seconds ÷ Cycles" for m in modes) + " |")
print("|---|---|---|" + "---|" * (2 * len(modes)))
for scene, n in keys:
    g = lambda renderer, mode: [r for r in rows if r["scene"] == scene and int(r["spp"]) == n and r["renderer"] == renderer and r["mode"] == mode]
    c = g("cycles", "path")
    crel, csec = mean(float(r["relmse"]) for r in c), mean(float(r["seconds"]) for r in c)
    rel = [f"**{mean(float(r['relmse']) for r in g('vplview', m)) / crel:.2f}**" for m in modes]
    sec = [f"{mean(float(r['seconds']) for r in g('vplview', m)) / csec:.2f}" for m in modes]
    print(f"| {scene} | {n} | {crel:.4g} | " + " | ".join(rel) + " | " + " | ".join(sec) + " |")
print("\nMeans over seeds; relMSE (DESIGN.md §4) against the cached vplview references of bench/vs_cycles.sh (" +
      "; ".join(sys.argv[3:]) + "). Seconds are whole renders; quote them only from an idle machine.")
PY
