#!/usr/bin/env bash
# vplview sweep end to end: one CSV row per setting (the defaults first), a markdown table, the JSON
# line, and bad --vary input refused with exit 2 and one line before any rendering.
# Usage (CTest): sweep_cli.sh PATH/TO/vplview REPO_ROOT.
set -u
exe=$1; repo=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
scene=$repo/scenes/cornell_box.gltf
fail() { echo "FAIL: $*"; exit 1; }
"$exe" reference "$scene" --spp 64 --width 40 --height 30 --out "$tmp/ref.exr" >/dev/null || fail "reference"
"$exe" sweep "$scene" --reference "$tmp/ref.exr" --modes mis --times 0.3 --vary --clusters=20,100 \
    --vary --bsdf-prob=0.25 --out-dir "$tmp/out" > "$tmp/stdout" || fail "sweep exited $?"
tail -1 "$tmp/stdout" | python3 -c "import json,sys; j=json.load(sys.stdin); assert j['runs'] == 4, j" || fail "JSON line"
python3 - "$tmp/out/sweep.csv" "$tmp/out/sweep.md" <<'PY' || fail "CSV or table"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [(r["parameter"], r["value"]) for r in rows] == [("defaults", "-"), ("--clusters", "20"), ("--clusters", "100"),
                                                       ("--bsdf-prob", "0.25")], rows
for r in rows:
    assert r["mode"] == "mis" and int(r["spp"]) > 0 and float(r["relmse"]) > 0 and abs(float(r["bias"])) < 0.5, r
table = open(sys.argv[2]).read().splitlines()
assert len(table) == 2 + len(rows) and table[2].startswith("| defaults |") and table[2].endswith("| 1.00 |"), table
print("sweep ok:", len(rows), "rows")
PY
bad() {
  "$exe" "$@" > /dev/null 2> "$tmp/err"; rc=$?
  [ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ] || fail "'$*' gave exit $rc: $(cat "$tmp/err")"
}
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --clusters=abc --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --no-such-flag=1 --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary clusters --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --clusters= --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --mode=brdf --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --threads=1,2 --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/missing.exr" --vary --clusters=5 --out-dir "$tmp/x"
bad sweep "$scene" --reference "$tmp/ref.exr" --vary --clusters=5 --width 41 --out-dir "$tmp/x"
echo "ok: sweep"
