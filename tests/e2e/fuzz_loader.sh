#!/usr/bin/env bash
# The glTF loading path under libFuzzer with ASan + UBSan: builds fuzz/ with clang in its own folder
# (BUILD/fuzz), runs every input of fuzz/regressions/ once, then fuzzes from fuzz/corpus/ for
# FUZZ_SECONDS (60). Any crash, leak, timeout or out-of-memory fails the test; its input is left in
# BUILD/fuzz/artifacts/. Skips (77) when clang or its fuzzer runtime (libclang-rt-14-dev) is missing.
# Usage (CTest): fuzz_loader.sh PATH/TO/vplview REPO_ROOT.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
fuzz=$build/fuzz
seconds=${FUZZ_SECONDS:-60}
fail() { echo "FAIL: $*"; exit 1; }

cc=$(command -v clang-14 || command -v clang); cxx=$(command -v clang++-14 || command -v clang++)
[ -n "$cxx" ] && [ -n "$cc" ] || { echo "SKIP: clang is not installed (scripts/setup.sh installs it)"; exit 77; }
probe=$(mktemp -d); trap 'rm -rf "$probe"' EXIT
echo 'extern "C" int LLVMFuzzerTestOneInput(const char*, unsigned long) { return 0; }' > "$probe/p.cpp"
"$cxx" -fsanitize=fuzzer "$probe/p.cpp" -o "$probe/p" 2>/dev/null ||
  { echo "SKIP: $cxx has no libFuzzer runtime (Debian: libclang-rt-14-dev)"; exit 77; }

CC=$cc CXX=$cxx cmake -S "$repo" -B "$fuzz" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVPLVIEW_FUZZ=ON >/dev/null ||
  fail "configuring the fuzz build"
cmake --build "$fuzz" --target fuzz_gltf_loader --parallel 1 >/dev/null || fail "the fuzz build failed"
exe=$fuzz/fuzz/fuzz_gltf_loader

# libFuzzer's own default exit code for a finding is 77, CTest's skip code here: map every failure to 1.
shopt -s nullglob
regressions=("$repo"/fuzz/regressions/*)
if [ ${#regressions[@]} -gt 0 ]; then
  "$exe" -rss_limit_mb=2048 -timeout=10 "${regressions[@]}" > "$fuzz/regressions.log" 2>&1 ||
    { tail -40 "$fuzz/regressions.log"; fail "a regression input crashes again (log: $fuzz/regressions.log)"; }
  echo "ok: ${#regressions[@]} regression inputs"
fi
mkdir -p "$fuzz/corpus" "$fuzz/artifacts"  # the working corpus grows here; fuzz/corpus/ stays the seeds
"$exe" -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1 \
  -artifact_prefix="$fuzz/artifacts/" "$fuzz/corpus" "$repo/fuzz/corpus" > "$fuzz/fuzz.log" 2>&1 ||
  { grep -v -E "^#[0-9]+" "$fuzz/fuzz.log" | tail -60; fail "the fuzzer found a problem (log: $fuzz/fuzz.log)"; }
grep -E "^stat::(number_of_executed_units|peak_rss_mb)" "$fuzz/fuzz.log"
echo "ok: ${seconds} s of fuzzing without a finding"
