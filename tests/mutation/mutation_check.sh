#!/usr/bin/env bash
# The mutation check (not part of CI: it rebuilds once per mutant, 10-20 minutes in all on 2 cores).
# For every mutant of tests/mutation/mutants.py: a clean copy of HEAD in a scratch folder, the one
# change applied, an incremental Release build, and the unit tests (every GoogleTest; not the e2e
# scripts). Prints, per mutant, the tests that failed: a mutant that fails none SURVIVED, and the
# script then exits 1.
# Usage: tests/mutation/mutation_check.sh [SCRATCH_DIR] [MUTANT ...]
set -u
repo=$(cd "$(dirname "$0")/../.." && pwd)
scratch=${1:-/tmp/vplview-mutants}
shift || true
mutants=${*:-$(python3 "$repo/tests/mutation/mutants.py" names)}
rm -rf "$scratch"
git -C "$repo" worktree prune
git -C "$repo" worktree add --detach "$scratch" HEAD >/dev/null 2>&1 || { echo "cannot make a worktree in $scratch"; exit 2; }
trap 'git -C "$repo" worktree remove --force "$scratch" >/dev/null 2>&1' EXIT
# ../shared must sit beside the copy as it does beside the repo.
[ -e "$scratch/../shared" ] || [ ! -d "$repo/../shared" ] || ln -s "$repo/../shared" "$scratch/../shared" 2>/dev/null
build=$scratch/build
cmake -S "$scratch" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null || exit 2
cmake --build "$build" --parallel "$(nproc)" >/dev/null || { echo "the unmutated build failed"; exit 2; }
survivors=0
printf '%-28s %s\n' mutant "failing tests"
for m in $mutants; do
  python3 "$repo/tests/mutation/mutants.py" apply "$m" "$scratch" || exit 2
  if ! cmake --build "$build" --parallel "$(nproc)" >/dev/null 2>&1; then
    printf '%-28s %s\n' "$m" "(does not compile: update the mutant)"; survivors=$((survivors + 1))
  else
    failed=$(cd "$build" && ctest --parallel "$(nproc)" --timeout 600 -E '^(e2e_|cli_contract)' 2>&1 |
             sed -n 's/^[[:space:]]*[0-9]* - \(.*\) (\(Failed\|Timeout\|Subprocess aborted\|Exception\)).*/\1/p' |
             sed 's/  # GetParam.*//' | tr '\n' ' ')
    if [ -z "$failed" ]; then
      printf '%-28s %s\n' "$m" "SURVIVED"; survivors=$((survivors + 1))
    else
      printf '%-28s %s\n' "$m" "$failed"
    fi
  fi
  git -C "$scratch" checkout -- . >/dev/null
done
[ $survivors = 0 ] || { echo "$survivors mutant(s) survived"; exit 1; }
echo "every mutant was caught"
