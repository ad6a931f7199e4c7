#!/usr/bin/env bash
# Russian roulette rules at equal time (issue 15): `vplview render --time T` with each rule and start
# depth, runs alternating within a seed so that a change in the machine's load hits every variant,
# scored with `vplview compare` (DESIGN.md §4 relMSE) against a converged `vplview reference`.
#
#   bench/roulette.sh BUILD_DIR OUT_DIR [SECONDS]        (default budget: 10)
#
# Environment: VARIANTS ("throughput:3 sqrt:3 throughput:1 sqrt:1 throughput:5 sqrt:5", rule:start),
# SCENES ("cornell_box door_ajar two_rooms"), MODES ("brdf"), SEEDS ("1 2 3"), THREADS (2),
# REF_SPP (4096), SIZE ("256 256" for the Cornell box, else "320 240", as bench/vs_cycles.sh).
# The reference (throughput:3, the rule does not change what the image converges to) is cached in
# OUT_DIR by the scene's content hash. Writes OUT_DIR/roulette.csv and prints a Markdown table:
# per variant the mean spp and the mean relMSE over seeds divided by the first variant's.
set -euo pipefail
build=$(cd "${1:?usage: roulette.sh BUILD_DIR OUT_DIR [SECONDS]}" && pwd)
out=${2:?usage: roulette.sh BUILD_DIR OUT_DIR [SECONDS]}
budget=${3:-10}
here=$(cd "$(dirname "$0")/.." && pwd)
exe=$build/vplview
VARIANTS=${VARIANTS:-throughput:3 sqrt:3 throughput:1 sqrt:1 throughput:5 sqrt:5}
SCENES=${SCENES:-cornell_box door_ajar two_rooms}; MODES=${MODES:-brdf}
SEEDS=${SEEDS:-1 2 3}; THREADS=${THREADS:-2}; REF_SPP=${REF_SPP:-4096}
[ -x "$exe" ] || { echo "roulette: no $exe" >&2; exit 2; }
[[ $budget =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "roulette: '$budget' is not a number of seconds" >&2; exit 2; }
mkdir -p "$out"; out=$(cd "$out" && pwd)
csv=$out/roulette.csv
echo "scene,mode,rule,start,seed,budget,spp,relmse" > "$csv"
. "$here/bench/lib.sh"

for name in $SCENES; do
  scene=$(scene_file "$here" "$build" "$name" roulette)
  if [ -n "${SIZE:-}" ]; then read -r W H <<<"$SIZE"; elif [ "$name" = cornell_box ]; then W=256 H=256; else W=320 H=240; fi
  ref=$(cached_reference "$exe" "$scene" "$name" "$out" $W $H "$REF_SPP" 32 0)
  for mode in $MODES; do
    for seed in $SEEDS; do
      for v in $VARIANTS; do
        rule=${v%%:*}; start=${v##*:}
        img=$out/${name}_${mode}_${rule}_${start}_seed$seed.exr
        spp=$("$exe" render "$scene" --mode $mode --time "$budget" --width $W --height $H --threads $THREADS \
                 --seed $seed --roulette $rule --rr-start $start --out "$img" | json spp)
        rel=$("$exe" compare "$img" "$ref" | json relmse)
        echo "$name,$mode,$rule,$start,$seed,$budget,$spp,$rel" | tee -a /dev/stderr >> "$csv"
      done
    done
  done
done

python3 - "$csv" "$VARIANTS" <<'PY'
import csv, sys
from statistics import mean
rows = list(csv.DictReader(open(sys.argv[1])))
variants = [tuple(v.split(":")) for v in sys.argv[2].split()]
keys = sorted({(r["scene"], r["mode"]) for r in rows}, key=lambda k: (k[0], k[1]))
print("| scene | mode | " + " | ".join(f"{r} from depth {s}" for r, s in variants) + " |")
print("|---|---|" + "---|" * len(variants))
for scene, mode in keys:
    def pick(rule, start):
        return [r for r in rows if r["scene"] == scene and r["mode"] == mode and r["rule"] == rule and r["start"] == start]
    base = mean(float(r["relmse"]) for r in pick(*variants[0]))
    cells = []
    for v in variants:
        g = pick(*v)
        cells.append(f"{mean(float(r['relmse']) for r in g) / base:.2f} ({mean(float(r['spp']) for r in g):.0f} spp)")
    print(f"| {scene} | {mode} | " + " | ".join(cells) + " |")
print(f"\nrelMSE ÷ {variants[0][0]} from depth {variants[0][1]} (means over seeds), at {rows[0]['budget']} s each; mean spp in brackets.")
PY
