#!/usr/bin/env bash
# The whole test suite again under AddressSanitizer + UndefinedBehaviorSanitizer, built in its own
# folder (BUILD/asan). Any sanitizer report fails it; LeakSanitizer ignores only Mesa's own
# allocations (tests/sanitizers/lsan.supp). Usage (CTest): asan_suite.sh PATH/TO/vplview REPO_ROOT.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
asan=$build/asan
# -O1 -g1: half the compile time of -O2 -g under UBSan (CLI11's headers dominate the app's files), with
# the line tables that the sanitizers' stack traces need.
flags="-O1 -g1 -DNDEBUG"
cmake -S "$repo" -B "$asan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVPLVIEW_SANITIZE=address,undefined -DVPLVIEW_BENCH=OFF \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="$flags" -DCMAKE_C_FLAGS_RELWITHDEBINFO="$flags" >/dev/null || exit 1
cmake --build "$asan" --parallel "$(nproc)" >/dev/null || { echo "FAIL: the sanitizer build failed"; exit 1; }
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
# print_suppressions=0: the summary of used suppressions would add lines to stderr, which the
# command-line tests hold to one line per error.
export LSAN_OPTIONS="suppressions=$repo/tests/sanitizers/lsan.supp:print_suppressions=0"
# The sanitizer runs of the sanitizer tests themselves (the fuzzer has ASan of its own), and the
# Node validator, are left out; so are the preview's statistical tests over every built-in scene
# (hundreds of passes each, half of this suite's test time under the sanitizers): the preview's shader,
# its VPL field and the coarse first preview run here in the other preview tests and the session's.
# The agreement cases that only repeat another case's code on a second scene are left out too: the
# Cycles anchor (the modes of GuidedModes on the same scenes) and the two_rooms and door_ajar cases
# that have a cornell_box or cornell_glossy twin (together 40 % of this suite's test time).
skip="asan_suite|tsan_session|fuzz_loader|gltf_validator"
skip+="|Preview\\.(PassesLeaveNoSteps|CoarseFirstPreview|SumsThePaths|PixelChoice|FirstPassesConverge)"
skip+="|ScalingTheSceneLeavesThePreviewsDistributionUnchanged"
# Likewise the cases whose every feature another case left in runs (a mode on another scene, or a
# subset of a combination's flags): a sanitizer needs each code path once, the plain suite keeps each
# case's statistical verdict. Beside each, the case that runs its code here (the last eight together
# 300 of the 1440 core-seconds of this suite's tests in the fresh-clone run of 188ac59):
covered=(
  two_rooms_mis two_rooms_metropolis two_rooms_mixture  # cornell_glossy_mis, _metropolis, _mixture
  two_rooms_mis_chain two_rooms_mis_fixed_probability   # cornell_glossy_mis_chain, _mis_every_vertex_fixed_probability
  two_rooms_mis_every_vertex                            # cornell_glossy_mis_every_vertex_fixed_probability
  door_ajar_brdf_connections                            # cornell_glossy_brdf_vpl_roulette_connections: brdf's joins
  cornell_box_mis cornell_box_metropolis cornell_box_mixture  # cornell_glossy_mis, _metropolis, _mixture
  door_ajar_mixture                                     # cornell_glossy_mixture
  cornell_box_brdf_vpl_roulette                         # cornell_glossy_brdf_vpl_roulette_connections
  cornell_glossy_metropolis_every_vertex                # its _vpl_roulette twin
  two_rooms_mixture_every_vertex                        # cornell_glossy_mixture, _metropolis_every_vertex_vpl_roulette
  two_rooms_mis_vpl_roulette                            # the same two vpl_roulette cases
)
skip+="|CyclesAnchor|PixelByPixel/($(IFS='|'; echo "${covered[*]}"))( |\$)"
# Learned light sampling's agreement under the sky and in mis (2 x 12 x 512 spp each, 3 min under the
# sanitizers): their code runs here in brdf's agreement and in the per-sample tests of EmitterGuide.
skip+="|EmitterGuide\\.(MisConvergesToBrdfWithLearning|BrdfUnderTheSkyConvergesToTheSameImageWithLearning)"
# The random sampler's convergence (2 x 1024 spp): its code runs here in PixelSampler's own tests.
skip+="|RenderJob\\.RandomSamplerConvergesToTheStratifiedImage"
# In parallel (the plain suite runs so too): alone at the end of a CI run, it is the critical path.
cd "$asan" && ctest -j "$(nproc)" --output-on-failure --timeout 900 -E "$skip"
