#!/usr/bin/env bash
# The viewer's session under ThreadSanitizer: builds the session tests with -fsanitize=thread in
# their own folder (BUILD/tsan) and runs them with TBB kept to the calling thread, since Debian's
# libtbb is not instrumented and TSan would report its internal hand-overs (see test_session.cpp);
# then the test that shares one BSDF between plain threads (what TBB's parallel loops do with it).
# Any report fails the test. Usage (CTest): tsan_session.sh PATH/TO/vplview REPO_ROOT.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
tsan=$build/tsan
cmake -S "$repo" -B "$tsan" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVPLVIEW_SANITIZE=thread >/dev/null || exit 1
cmake --build "$tsan" --target test_session test_bsdf >/dev/null || { echo "FAIL: the TSan build failed"; exit 1; }
# Left out: the two tests of the decisions kept across camera moves (35 s here with TBB serial): their
# threads and hand-overs are every other session test's; what they add is controller-only state.
kept="Session.ACameraMoveKeepsWhatTheScenesPassesDecided:Session.AKeptJoinDepthOneNeedsAViewAsEvenlyLit"
VPLVIEW_SERIAL_TBB=1 TSAN_OPTIONS="halt_on_error=1 exitcode=66" "$tsan/tests/test_session" --gtest_filter="-$kept" || exit 1
TSAN_OPTIONS="halt_on_error=1 exitcode=66" "$tsan/tests/test_bsdf" --gtest_filter='*SeveralThreads*'
