#!/usr/bin/env bash
# The whole test suite again under AddressSanitizer + UndefinedBehaviorSanitizer, built in its own
# folder (BUILD/asan). Any sanitizer report fails it; LeakSanitizer ignores only Mesa's own
# allocations (tests/sanitizers/lsan.supp). Usage (CTest): asan_suite.sh PATH/TO/vplview REPO_ROOT.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
asan=$build/asan
cmake -S "$repo" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVPLVIEW_SANITIZE=address,undefined >/dev/null || exit 1
cmake --build "$asan" --parallel "$(nproc)" >/dev/null || { echo "FAIL: the sanitizer build failed"; exit 1; }
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# print_suppressions=0: the summary of used suppressions would add lines to stderr, which the
# command-line tests hold to one line per error.
export LSAN_OPTIONS="suppressions=$repo/tests/sanitizers/lsan.supp:print_suppressions=0"
# The sanitizer runs of the sanitizer tests themselves (the fuzzer has ASan of its own), and the
# Node validator, are left out; so is the preview's slice-border statistic, which renders 200 preview
# passes of two fields at 160x120 (330 s under the sanitizers, a quarter of this suite) through code
# that the other preview tests run here too.
# In parallel (the plain suite runs so too): alone at the end of a CI run, it is the critical path.
cd "$asan" && ctest -j "$(nproc)" --output-on-failure --timeout 900 -E "asan_suite|tsan_session|fuzz_loader|gltf_validator|Preview.PassesLeaveNoStepsOrLinesFromSlices"
