#!/usr/bin/env bash
# Equal-time relMSE of every mode against a high-spp brdf reference (DESIGN.md §4), preprocessing
# included. Usage: bench/measure_modes.sh BUILD_DIR OUT_DIR [SECONDS...]   (default budgets: 10 60)
# Writes OUT_DIR/modes.csv (scene,mode,budget_s,spp,relmse,bias) and prints a markdown table.
set -euo pipefail
build=${1:?build dir}; out=${2:?output dir}; shift 2
budgets=${*:-10 60}
exe=$build/vplview
here=$(cd "$(dirname "$0")/.." && pwd)
W=${W:-320}; H=${H:-240}; REF_SPP=${REF_SPP:-2048}; THREADS=${THREADS:-2}
mkdir -p "$out"
scenes="$here/scenes/cornell_box.gltf $here/scenes/two_rooms.gltf $here/scenes/cornell_glossy.gltf $build/scenes/interior.glb"
echo "scene,mode,budget_s,spp,relmse,bias" > "$out/modes.csv"
for scene in $scenes; do
  name=$(basename "${scene%.*}")
  ref=$out/${name}_ref.exr
  [ -f "$ref" ] || "$exe" render "$scene" --mode brdf --spp "$REF_SPP" --width $W --height $H --threads $THREADS --seed 1000 --out "$ref" >/dev/null
  for t in $budgets; do
    for mode in brdf metropolis mis mixture; do
      "$exe" render "$scene" --mode $mode --time "$t" --width $W --height $H --threads $THREADS --seed 7 \
          --out "$out/${name}_${mode}_${t}.exr" > "$out/run.json"
      spp=$(python3 -c "import json,sys; print(json.loads(open(sys.argv[1]).read().splitlines()[-1])['spp'])" "$out/run.json")
      "$exe" compare "$out/${name}_${mode}_${t}.exr" "$ref" > "$out/cmp.json"
      python3 - "$out/cmp.json" "$name" "$mode" "$t" "$spp" >> "$out/modes.csv" <<'PY'
import json, sys
j = json.loads(open(sys.argv[1]).read().splitlines()[-1])
print(f"{sys.argv[2]},{sys.argv[3]},{sys.argv[4]},{sys.argv[5]},{j['relmse']:.5g},{j['bias']:.4f}")
PY
    done
  done
done
python3 - "$out/modes.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("| scene | budget | " + " | ".join(f"{m} relMSE (spp)" for m in ["brdf", "metropolis", "mis", "mixture"]) + " |")
print("|---|---|---|---|---|---|")
keys = sorted({(r["scene"], int(r["budget_s"])) for r in rows}, key=lambda k: (k[0], k[1]))
for scene, t in keys:
    cells = []
    for m in ["brdf", "metropolis", "mis", "mixture"]:
        r = [x for x in rows if x["scene"] == scene and x["mode"] == m and int(x["budget_s"]) == t][0]
        cells.append(f"{float(r['relmse']):.4f} ({r['spp']})")
    print(f"| {scene} | {t} s | " + " | ".join(cells) + " |")
PY
