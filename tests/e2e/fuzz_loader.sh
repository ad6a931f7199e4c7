#!/usr/bin/env bash
# The glTF loading path under libFuzzer with ASan + UBSan: builds fuzz/ with clang in its own folder
# (BUILD/fuzz), runs every input of fuzz/regressions/ once in fuzz_gltf_loader and of
# fuzz/regressions_textures/ in fuzz_texture, then fuzzes the loader from fuzz/corpus/ for
# FUZZ_SECONDS (60) and the texture path from fuzz/corpus_textures/ for FUZZ_TEXTURE_SECONDS (15).
# Any crash, leak, timeout or out-of-memory fails the test; its input is left in
# BUILD/fuzz/artifacts/. Skips (77) when clang or its fuzzer runtime (libclang-rt-14-dev) is missing.
# Usage (CTest): fuzz_loader.sh PATH/TO/vplview REPO_ROOT.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
fuzz=$build/fuzz
seconds=${FUZZ_SECONDS:-60}
texture_seconds=${FUZZ_TEXTURE_SECONDS:-15}
fail() { echo "FAIL: $*"; exit 1; }

cc=$(command -v clang-14 || command -v clang); cxx=$(command -v clang++-14 || command -v clang++)
[ -n "$cxx" ] && [ -n "$cc" ] || { echo "SKIP: clang is not installed (scripts/setup.sh installs it)"; exit 77; }
probe=$(mktemp -d); trap 'rm -rf "$probe"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' > "$probe/p.cpp"
"$cxx" -fsanitize=fuzzer "$probe/p.cpp" -o "$probe/p" 2>/dev/null ||
  { echo "SKIP: $cxx has no libFuzzer runtime (Debian: libclang-rt-14-dev)"; exit 77; }

CC=$cc CXX=$cxx cmake -S "$repo" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVPLVIEW_FUZZ=ON >/dev/null ||
  fail "configuring the fuzz build"
cmake --build "$fuzz" --target fuzz_gltf_loader fuzz_texture --parallel 1 >/dev/null || fail "the fuzz build failed"

# libFuzzer's own default exit code for a finding is 77, CTest's skip code here: map every failure to 1.
# replay TARGET DIR: every input of DIR once; run TARGET SECONDS SEEDS: fuzzing from a working corpus.
shopt -s nullglob
replay() {
  local inputs=("$2"/*)
  [ ${#inputs[@]} -gt 0 ] || return 0
  "$fuzz/fuzz/$1" -rss_limit_mb=2048 -timeout=10 "${inputs[@]}" > "$fuzz/$1.regressions.log" 2>&1 ||
    { tail -40 "$fuzz/$1.regressions.log"; fail "a regression input crashes $1 again (log: $fuzz/$1.regressions.log)"; }
  echo "ok: ${#inputs[@]} regression inputs of $1"
}
run() {
  mkdir -p "$fuzz/$1.corpus" "$fuzz/artifacts"  # the working corpus grows here; the seeds stay as they are
  "$fuzz/fuzz/$1" -max_total_time="$2" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
    -artifact_prefix="$fuzz/artifacts/" "$fuzz/$1.corpus" "$3" > "$fuzz/$1.log" 2>&1 ||
    { grep -v -E "^#[0-9]+" "$fuzz/$1.log" | tail -60; fail "the fuzzer found a problem in $1 (log: $fuzz/$1.log)"; }
  grep -E "^stat::(number_of_executed_units|peak_rss_mb)" "$fuzz/$1.log"
  echo "ok: $2 s of $1 without a finding"
}
replay fuzz_gltf_loader "$repo/fuzz/regressions"
replay fuzz_texture "$repo/fuzz/regressions_textures"
run fuzz_gltf_loader "$seconds" "$repo/fuzz/corpus"
run fuzz_texture "$texture_seconds" "$repo/fuzz/corpus_textures"
