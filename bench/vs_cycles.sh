#!/usr/bin/env bash
# vplview against the peer, Blender's Cycles, at equal time (issue 15; DESIGN.md §4 relMSE).
#
#   bench/vs_cycles.sh BUILD_DIR OUT_DIR [SECONDS...]        (default budgets: 10 60)
#
# For every built-in scene that Cycles renders exactly (../shared/tools/cycles/README.md; the others
# are refused by cycles-render and listed as skipped): a converged vplview reference (`vplview
# reference`, cached in OUT_DIR under the scene's content hash, size, spp and depth), then for each
# budget and seed, alternating: Cycles at a fixed spp chosen from two probes so that it takes about the
# budget, then vplview brdf and mis with --time set to the seconds Cycles reported. Every image is
# scored with `vplview compare IMAGE REF` (relMSE and relative bias).
# Writes OUT_DIR/vs_cycles.csv (one row per render; rows of budgets or scenes not rerun are kept, so
# 10 and 60, or one scene, can be run again separately) and OUT_DIR/vs_cycles.md (tables for the
# README), and prints the latter.
#
# Environment: MODES ("brdf mis"; MODE+RULE runs with --roulette RULE, e.g. brdf+vpl), THREADS (2), SEEDS ("1 2"), MAX_DEPTH (32 = vplview's default; Cycles gets
# --max-bounces MAX_DEPTH-1), SCENES (names to run, default all built-in), REF_SPP (overrides the
# per-scene reference spp below), REF_MODE (the reference's mode, brdf; mis converges to the same image
# with far less error per second where the light arrives indirectly, so its reference is not the main
# error of the mis row), REF_THREADS (0 = all cores), CYCLES_RENDER (path of cycles-render),
# CODE (how the tables name the code measured; default: the repository's commit).
# The reference cache is keyed by the scene's bytes, not by vplview's code: delete OUT_DIR/ref_*.exr
# when a change alters what the renderer converges to.
# Needs Blender (apt-get install -y blender python3-numpy). A benchmark, not a test: run it on an idle machine.
set -euo pipefail
build=$(cd "${1:?usage: vs_cycles.sh BUILD_DIR OUT_DIR [SECONDS...]}" && pwd)
out=${2:?usage: vs_cycles.sh BUILD_DIR OUT_DIR [SECONDS...]}
shift 2
budgets=${*:-10 60}
here=$(cd "$(dirname "$0")/.." && pwd)
exe=$build/vplview
cycles=${CYCLES_RENDER:-$here/../shared/tools/cycles/cycles-render}
MODES=${MODES:-brdf mis}; THREADS=${THREADS:-2}; SEEDS=${SEEDS:-1 2}; MAX_DEPTH=${MAX_DEPTH:-32}; REF_THREADS=${REF_THREADS:-0}; REF_MODE=${REF_MODE:-brdf}
[ -x "$exe" ] || { echo "vs_cycles: no $exe (cmake --build BUILD_DIR --target vplview)" >&2; exit 2; }
[ -x "$cycles" ] || { echo "vs_cycles: no $cycles (set CYCLES_RENDER)" >&2; exit 2; }
command -v blender >/dev/null || { echo "vs_cycles: Blender is missing: apt-get install -y blender python3-numpy" >&2; exit 2; }
# Debian's blender runs the system Python, whose numpy the script imports but blender only recommends.
dpkg-query -W -f='${Status}' python3-numpy 2>/dev/null | grep -q "install ok installed" ||
  { echo "vs_cycles: Blender's Python has no numpy: apt-get install -y python3-numpy" >&2; exit 2; }
for t in $budgets; do
  [[ $t =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "vs_cycles: '$t' is not a number of seconds" >&2; exit 2; }
done
mkdir -p "$out"
out=$(cd "$out" && pwd)
log=$out/vs_cycles.log
csv=$out/vs_cycles.csv
md=$out/vs_cycles.md
skipped=$out/vs_cycles_skipped.txt
header="scene,budget,renderer,mode,seed,seconds,spp,samples_per_s,relmse,bias,width,height,ref_spp,ref_mode"

# Sizes (the issue's measurements) and reference spp per scene; other scenes: 320x240, 8192 spp.
size_of() { case $1 in cornell_box) echo "256 256";; *) echo "320 240";; esac; }
ref_spp_of() { if [ -n "${REF_SPP:-}" ]; then echo "$REF_SPP"; else case $1 in cornell_box) echo 16384;; *) echo 8192;; esac; fi; }

. "$here/bench/lib.sh"

# Keep the rows of budgets not in this run.
tmp_csv=$(mktemp)
echo "$header" > "$tmp_csv"
if [ -f "$csv" ]; then
  python3 - "$csv" "$budgets" "${SCENES:-}" >> "$tmp_csv" <<'PY'
import csv, sys
rerun = {float(b) for b in sys.argv[2].split()}
scenes = set(sys.argv[3].split())  # empty: every scene is rerun
rows = list(csv.reader(open(sys.argv[1])))
for r in rows[1:]:
    if r and (float(r[1]) not in rerun or (scenes and r[0] not in scenes)):
        print(",".join(r + ["brdf"] * (14 - len(r))))  # rows from before the ref_mode column
PY
fi
mv "$tmp_csv" "$csv"
: > "$skipped.new"
ran=$(mktemp)  # the scenes this run tried: their old entries in the skipped list are stale

scenes=()
for f in "$here"/scenes/*.gltf "$build"/scenes/*.glb; do [ -f "$f" ] && scenes+=("$f"); done
echo "$(date -Is) vs_cycles: budgets $budgets, seeds $SEEDS, threads $THREADS, max depth $MAX_DEPTH" | tee -a "$log"
for scene in "${scenes[@]}"; do
  name=$(basename "${scene%.*}")
  if [ -n "${SCENES:-}" ] && [[ " $SCENES " != *" $name "* ]]; then continue; fi
  echo "^$name:" >> "$ran"
  read -r W H < <(size_of "$name")
  bounces=$((MAX_DEPTH - 1))
  # Probe Cycles at 16 and 64 spp: refused scenes exit 2 here; the two times give the cost per spp and
  # the fixed cost (scene sync, kernel set-up, EXR write: about 1.7 s on the Cornell box) that choose
  # the spp for each budget.
  probe=()
  for n in 16 64; do
    if ! res=$("$cycles" "$scene" "$out/probe.exr" --width "$W" --height "$H" --spp $n --seed 99 \
                 --max-bounces $bounces --threads "$THREADS" 2>"$out/probe.err"); then
      why=$(tr '\n' ' ' < "$out/probe.err" | sed 's/.*NotImplementedError: //; s/ *$//' | cut -c1-200)
      echo "$name: refused by cycles-render ($why)" | tee -a "$log" >> "$skipped.new"
      continue 2
    fi
    probe+=("$(json seconds <<<"$res")")
  done
  read -r per_spp fixed < <(python3 -c "
import sys
a, b = map(float, sys.argv[1:])
p = (b - a) / 48
if p <= 0.0 or a - 16 * p < 0.0: p = b / 64   # noise: no fixed part
print(p, max(a - 16 * p, 0.0))" "${probe[@]}")
  echo "$name ${W}x$H: Cycles probes at 16 and 64 spp: ${probe[*]} s -> $per_spp s/spp + $fixed s" | tee -a "$log"

  rspp=$(ref_spp_of "$name")
  ref=$(cached_reference "$exe" "$scene" "$name" "$out" "$W" "$H" "$rspp" "$MAX_DEPTH" "$REF_THREADS" "$REF_MODE" 2>> "$log")

  for t in $budgets; do
    cspp=$(python3 -c "import sys; t, f, p = map(float, sys.argv[1:]); print(max(1, round((t - f) / p)))" "$t" "$fixed" "$per_spp")
    for seed in $SEEDS; do
      img=$out/${name}_${t}s_cycles_seed$seed.exr
      read -r secs spp < <("$cycles" "$scene" "$img" --width "$W" --height "$H" --spp "$cspp" --seed "$seed" \
                              --max-bounces $bounces --threads "$THREADS" | json seconds spp)
      read -r rel bias < <("$exe" compare "$img" "$ref" | json relmse bias)
      sps=$(python3 -c "import sys; w, h, n, s = map(float, sys.argv[1:]); print(f'{w * h * n / s:.6g}')" "$W" "$H" "$spp" "$secs")
      echo "$name,$t,cycles,path,$seed,$secs,$spp,$sps,$rel,$bias,$W,$H,$rspp,$REF_MODE" | tee -a "$log" >> "$csv"
      for mode in $MODES; do
        img=$out/${name}_${t}s_${mode}_seed$seed.exr
        flags="--mode ${mode%%+*}"
        [[ $mode == *+* ]] && flags="$flags --roulette ${mode#*+}"
        read -r vsecs vspp < <("$exe" render "$scene" $flags --time "$secs" --width "$W" --height "$H" \
                                  --threads "$THREADS" --seed "$seed" --max-depth "$MAX_DEPTH" --out "$img" | json seconds spp)
        read -r rel bias < <("$exe" compare "$img" "$ref" | json relmse bias)
        sps=$(python3 -c "import sys; w, h, n, s = map(float, sys.argv[1:]); print(f'{w * h * n / s:.6g}')" "$W" "$H" "$vspp" "$vsecs")
        echo "$name,$t,vplview,$mode,$seed,$vsecs,$vspp,$sps,$rel,$bias,$W,$H,$rspp,$REF_MODE" | tee -a "$log" >> "$csv"
      done
    done
  done
done
rm -f "$out/probe.exr" "$out/probe.err"
# Skipped scenes: keep earlier notes for scenes not probed in this run.
if [ -f "$skipped" ] && [ -s "$ran" ]; then grep -v -f "$ran" "$skipped" >> "$skipped.new" || true
elif [ -f "$skipped" ]; then cat "$skipped" >> "$skipped.new"; fi
rm -f "$ran"
sort -u "$skipped.new" > "$skipped"; rm -f "$skipped.new"

if [ -z "${CODE:-}" ]; then
  CODE="commit $(git -C "$here" rev-parse --short HEAD 2>/dev/null || echo "?")"
  git -C "$here" status --porcelain --untracked-files=no 2>/dev/null | grep -q . && CODE="$CODE (with uncommitted changes)"
fi
cpu=$(grep -m1 "model name" /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')
python3 - "$csv" "$skipped" "$THREADS" "$MAX_DEPTH" "$CODE" "$cpu" "$(nproc)" "$out" > "$md" <<'PY'
import csv, os, sys
from statistics import mean
path, skipped, threads, depth, commit, cpu, cores, out = sys.argv[1:]
rows = list(csv.DictReader(open(path)))
for r in rows:
    for k in ("budget", "seconds", "spp", "samples_per_s", "relmse", "bias"):
        r[k] = float(r[k])
def group(scene, budget, renderer, mode):
    return [r for r in rows if r["scene"] == scene and r["budget"] == budget and r["renderer"] == renderer and r["mode"] == mode]
def fmt(x):
    return f"{x:.3g}" if x < 1000 else f"{x / 1e6:.2f} M" if x >= 1e6 else f"{x:.0f}"
order = {"cornell_box": 0, "two_rooms": 1, "door_ajar": 2}
keys = sorted({(r["scene"], r["budget"]) for r in rows}, key=lambda k: (order.get(k[0], 9), k[0], k[1]))
modes = list(dict.fromkeys(r["mode"] for r in rows if r["renderer"] == "vplview"))
print("## vplview against Cycles at equal time\n")
print(f"`bench/vs_cycles.sh BUILD_DIR OUT_DIR [SECONDS...]`: Cycles 3.4.1 (`../shared/tools/cycles/cycles-render`, CPU) at a fixed spp")
print(f"that takes about the budget, then vplview's modes ({', '.join(f'`{m}`' for m in modes)}; MODE+RULE: `--roulette RULE`) with `--time` = Cycles' seconds, alternating, {threads} threads each,")
print(f"max depth {depth} (Cycles `--max-bounces {int(depth) - 1}`); relMSE (DESIGN.md §4) against a converged vplview `reference`.")
print(f"Ratios are vplview ÷ Cycles of the means over seeds (samples/s: width × height × spp ÷ seconds, set-up included).")
print(f"Code: {commit}; {cpu}, {cores} cores. Timings on a shared machine are noisy.\n")
print("| scene | budget | Cycles spp | " + " | ".join(f"{m} spp | {m} samples/s ÷ Cycles | {m} relMSE ÷ Cycles" for m in modes) + " |")
print("|---|---|---|" + "---|---|---|" * len(modes))
for scene, budget in keys:
    c = group(scene, budget, "cycles", "path")
    if not c:
        continue
    cells = [f"{mean(r['spp'] for r in c):.0f}"]
    for mode in modes:
        v = group(scene, budget, "vplview", mode)
        if not v:
            cells += ["", "", ""]
            continue
        cells += [f"{mean(r['spp'] for r in v):.0f}",
                  f"{mean(r['samples_per_s'] for r in v) / mean(r['samples_per_s'] for r in c):.2f}",
                  f"**{mean(r['relmse'] for r in v) / mean(r['relmse'] for r in c):.2f}**"]
    print(f"| {scene} | {budget:g} s | " + " | ".join(cells) + " |")
print()
for scene, budget in keys:
    c = group(scene, budget, "cycles", "path")
    w, h = (c[0]["width"], c[0]["height"]) if c else ("?", "?")
    print(f"### {scene}, {w}×{h}, {budget:g} s\n")
    print("| renderer | seeds | seconds | spp | samples/s | relMSE per seed | mean relMSE | bias | samples/s ÷ Cycles | relMSE ÷ Cycles |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for renderer, mode, label in [("cycles", "path", "Cycles")] + [("vplview", m, f"vplview {m}") for m in modes]:
        g = group(scene, budget, renderer, mode)
        if not g:
            continue
        sps, rel = mean(r["samples_per_s"] for r in g), mean(r["relmse"] for r in g)
        ratio = lambda a, b: f"{a / b:.2f}" if c and b > 0 else ""
        print(f"| {label} | {', '.join(r['seed'] for r in g)} | {mean(r['seconds'] for r in g):.1f} | {mean(r['spp'] for r in g):.0f} | "
              f"{fmt(sps)} | {', '.join('%.4g' % r['relmse'] for r in g)} | {rel:.4g} | {mean(r['bias'] for r in g):+.4f} | "
              f"{ratio(sps, mean(r['samples_per_s'] for r in c))} | {ratio(rel, mean(r['relmse'] for r in c))} |")
    n = int(c[0]["ref_spp"]) if c else 0
    ref_mode = (c[0].get("ref_mode") or "brdf") if c else "brdf"
    b = group(scene, budget, "vplview", ref_mode)
    if b and n:
        # An unbiased estimate's relMSE falls as 1/spp: the reference's own error is about its mode's row's times
        # that row's spp / n, and it adds to every row's relMSE (pulling the ratios towards 1).
        est = mean(r["relmse"] for r in b) * mean(r["spp"] for r in b) / n
        low = min(r["relmse"] for r in rows if r["scene"] == scene and r["budget"] == budget)
        print(f"\nReference: {n} spp vplview {ref_mode}; its own relMSE ≈ {est:.2g} ({ref_mode}'s × spp / {n}), {100 * est / low:.0f} % of the lowest relMSE above.")
    print()
if os.path.exists(skipped) and os.path.getsize(skipped):
    print("Skipped (no exact Cycles counterpart):\n")
    for line in open(skipped):
        print(f"- {line.strip()}")
PY
echo "$(date -Is) vs_cycles: done; $csv, $md" | tee -a "$log"
cat "$md"
