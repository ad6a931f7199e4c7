#!/usr/bin/env bash
# No failed write replaces a good image: render, reference, capture, converge, sweep, compare's
# error map and the viewer's --screenshot each write once, then again under a full disk (ulimit -f:
# past it write() fails, and SIGXFSZ must not kill vplview). The second run must exit 2 with one line
# on stderr, leave the first files byte for byte and leave no temporary. Then: a target that is a
# folder, and a folder vplview may not write in (as user nobody when run as root: chmod does not
# stop root), and names that say another image format than the one written. Usage (CTest):
# atomic_writes.sh PATH/TO/vplview REPO_ROOT.
set -u
exe=$1; repo=$2
scene=$repo/scenes/cornell_box.gltf
tmp=$(mktemp -d); trap 'chmod -R u+w "$tmp"; rm -rf "$tmp"' EXIT
chmod 755 "$tmp"
fail() { echo "FAIL: $*"; exit 1; }
small=(--spp 1 --width 32 --height 24 --threads 1)

# NAME BLOCKS OUTPUTS... -- ARGS: runs vplview ARGS twice, the second time under ulimit -f BLOCKS
# (1 KiB blocks: 1 lets a write start and fail part-way); OUTPUTS are the files the first run wrote,
# which the second must leave alone.
full_disk() {
  local name=$1 blocks=$2; shift 2
  local outputs=()
  while [ "$1" != -- ]; do outputs+=("$1"); shift; done; shift
  "$@" > /dev/null 2> "$tmp/err" || fail "$name: the first run failed: $(cat "$tmp/err")"
  mkdir -p "$tmp/before"
  for f in "${outputs[@]}"; do [ -s "$f" ] || fail "$name: $f was not written"; cp "$f" "$tmp/before/$(basename "$f")"; done
  # stderr through a pipe: the limit applies to regular files, and the message must get out.
  (ulimit -f "$blocks"; exec "$@" 2>&1 > /dev/null < /dev/null) | cat > "$tmp/err"; local rc=${PIPESTATUS[0]}
  [ $rc = 2 ] || fail "$name: exit $rc under a full disk (153 = killed by SIGXFSZ): $(head -c 1000 "$tmp/err")"
  [ "$(grep -c . "$tmp/err")" = 1 ] || fail "$name: not one line: $(cat "$tmp/err")"
  grep -q 'cannot write (File too large)' "$tmp/err" || fail "$name: $(cat "$tmp/err")"
  for f in "${outputs[@]}"; do cmp -s "$f" "$tmp/before/$(basename "$f")" || fail "$name: $f changed"; done
  local left; left=$(find "$(dirname "${outputs[0]}")" -name '*.tmp')
  [ -z "$left" ] || fail "$name: temporaries left: $left"
  echo "ok: $name: $(cat "$tmp/err")"
}

mkdir "$tmp/out"
o=$tmp/out
full_disk render 1 "$o/r.exr" -- "$exe" render "$scene" --mode brdf "${small[@]}" --out "$o/r.exr"
# The EXR, written first, fails: the PNG is not reached and must stay too.
full_disk "render --png" 1 "$o/r.exr" "$o/r.png" -- "$exe" render "$scene" --mode brdf "${small[@]}" --out "$o/r.exr" --png "$o/r.png"
full_disk reference 1 "$o/ref.exr" -- "$exe" reference "$scene" "${small[@]}" --out "$o/ref.exr"
full_disk capture 1 "$o/c.png" -- "$exe" capture "$scene" --mode brdf "${small[@]}" --out "$o/c.png"
full_disk compare 1 "$o/err.png" -- "$exe" compare "$o/r.exr" "$o/ref.exr" --error-map "$o/err.png"
# The CSV is smaller than a block and is replaced (whole); the plot does not fit and must stay.
full_disk converge 1 "$o/conv/converge.png" -- \
  "$exe" converge "$scene" --reference "$o/ref.exr" --modes brdf --times 0.05 --threads 1 --out-dir "$o/conv"
full_disk sweep 0 "$o/sweep/sweep.csv" "$o/sweep/sweep.md" -- \
  "$exe" sweep "$scene" --reference "$o/ref.exr" --modes brdf --times 0.05 --threads 1 --vary --seed=2 --out-dir "$o/sweep"

# The viewer's --screenshot, in a virtual X server (the limit applies to vplview only).
if command -v xvfb-run > /dev/null; then
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"  # the GL driver's allocations (viewer_window.sh)
  # vplview's own exit status goes to $tmp/rc: xvfb-run's would hide it when its clean-up fails
  # (exit 5, seen once under AddressSanitizer).
  shot() { rm -f "$tmp/rc"
           timeout 180 xvfb-run -a -s "-screen 0 320x240x24" bash -c '(ulimit -f "$1"; shift 2; exec "$@"); echo $? > "$2"' _ \
             "$1" "$tmp/rc" "$exe" "$scene" --width 64 --height 48 --threads 1 --screenshot "$o/shot.png" --screenshot-after 0.5
           return "$(cat "$tmp/rc" 2>/dev/null || echo 124)"; }
  shot unlimited > /dev/null 2> "$tmp/err" || fail "screenshot: the first run failed: $(cat "$tmp/err")"
  cp "$o/shot.png" "$tmp/shot.png"
  # No byte at all may be written: at 1 KiB a slow build's first frames (the quarter-size quick
  # stage, flat blocks) compress to a PNG that fits, as seen under AddressSanitizer. stderr goes
  # through a pipe, which the file-size limit does not cover.
  shot 0 2>&1 > /dev/null | cat > "$tmp/err"; rc=${PIPESTATUS[0]}
  grep -v '^vplview: note' "$tmp/err" > "$tmp/err2"
  [ $rc = 2 ] && [ "$(grep -c . "$tmp/err2")" = 1 ] && grep -q 'cannot write (File too large)' "$tmp/err2" ||
    fail "screenshot: exit $rc: $(cat "$tmp/err")"
  cmp -s "$o/shot.png" "$tmp/shot.png" || fail "screenshot: the earlier file changed"
  [ -z "$(find "$o" -name '*.tmp')" ] || fail "screenshot: a temporary was left"
  echo "ok: viewer --screenshot: $(cat "$tmp/err2")"
else
  echo "note: xvfb-run is missing: the viewer's --screenshot was not checked"
fi

# A name that says another format than the one written: refused before rendering, nothing written.
wrong_name() {
  local name=$1 target=$2; shift 2
  "$@" > /dev/null 2> "$tmp/err"; local rc=$?
  [ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ] && grep -q "name it" "$tmp/err" && [ ! -e "$target" ] ||
    fail "$name: exit $rc: $(cat "$tmp/err")"
  echo "ok: $name: $(cat "$tmp/err")"
}
wrong_name "render --out x.png" "$tmp/x.png" "$exe" render "$scene" --mode brdf "${small[@]}" --out "$tmp/x.png"
wrong_name "render --png x.exr" "$tmp/x.exr" "$exe" render "$scene" --mode brdf "${small[@]}" --out "$tmp/y.exr" --png "$tmp/x.exr"
wrong_name "capture --out x.EXR" "$tmp/x.EXR" "$exe" capture "$scene" --mode brdf "${small[@]}" --out "$tmp/x.EXR"
"$exe" render "$scene" --mode brdf "${small[@]}" --out "$tmp/upper.EXR" --png "$tmp/upper.PNG" > /dev/null 2> "$tmp/err" &&
  [ -s "$tmp/upper.EXR" ] && [ -s "$tmp/upper.PNG" ] || fail "render --out upper.EXR --png upper.PNG: $(cat "$tmp/err")"

# A target that is a folder.
mkdir "$tmp/folder.exr"
"$exe" render "$scene" --mode brdf "${small[@]}" --out "$tmp/folder.exr" > /dev/null 2> "$tmp/err"; rc=$?
[ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ] && [ -d "$tmp/folder.exr" ] || fail "folder target: exit $rc: $(cat "$tmp/err")"
echo "ok: a folder as the target: $(cat "$tmp/err")"

# A folder vplview may not write in, holding an earlier image it could overwrite in place (mode 666).
mkdir "$tmp/locked"
cp "$o/r.exr" "$tmp/locked/r.exr"
chmod 666 "$tmp/locked/r.exr"; chmod 555 "$tmp/locked"
as_user=()
if [ "$(id -u)" = 0 ]; then
  command -v setpriv > /dev/null || { echo "SKIP: root without setpriv: chmod cannot stop root, the locked folder is unchecked"; exit 77; }
  as_user=(setpriv --reuid=65534 --regid=65534 --clear-groups)
fi
"${as_user[@]}" "$exe" render "$scene" --mode brdf "${small[@]}" --out "$tmp/locked/r.exr" > /dev/null 2> "$tmp/err" < /dev/null; rc=$?
[ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ] && grep -q 'Permission denied' "$tmp/err" ||
  fail "locked folder: exit $rc: $(cat "$tmp/err")"
cmp -s "$o/r.exr" "$tmp/locked/r.exr" || fail "locked folder: the earlier file changed"
[ "$(ls -A "$tmp/locked")" = r.exr ] || fail "locked folder: $(ls -A "$tmp/locked")"
echo "ok: a folder vplview may not write in${as_user:+ (as user nobody)}: $(cat "$tmp/err")"
