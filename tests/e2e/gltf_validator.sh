#!/usr/bin/env bash
# The Khronos glTF-Validator as the judge of vplview's loader:
# 1. every built-in scene (committed and generated) is valid;
# 2. over every .gltf/.glb in ../shared/scenes, fuzz/corpus, fuzz/regressions and tests/data/gltf_indices,
#    vplview refuses (exit 2, one line on stderr) each file the validator reports an error in and
#    renders each file it reports none in, except the files README.md lists under "Where vplview and
#    the glTF validator disagree" (there the two must still disagree, or the list is stale).
# Usage (CTest): gltf_validator.sh PATH/TO/vplview REPO_ROOT. Exit 77 (skip) without node or the
# validator, and after checking the rest when ../shared/scenes is absent.
set -u
exe=$1; build=$(cd "$(dirname "$1")" && pwd); repo=$(cd "$2" && pwd)
validator=$build/tools/node_modules/gltf-validator
if ! command -v node >/dev/null || [ ! -d "$validator" ]; then
  echo "SKIP: node or $validator is missing (scripts/setup.sh installs it when npm can reach its registry)"
  exit 77
fi
validate() { GLTF_VALIDATOR=$validator node "$repo/tests/e2e/gltf_validator.mjs" "$@"; }
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
status=0

validate "$repo"/scenes/*.gltf "$build"/scenes/*.glb || { echo "FAIL: a built-in scene is invalid"; status=1; }

folders=("$repo/fuzz/corpus" "$repo/fuzz/regressions" "$repo/tests/data/gltf_indices")
shared=$(cd "$repo/.." && pwd)/shared/scenes
[ -d "$shared" ] && folders+=("$shared")
mapfile -t files < <(find "${folders[@]}" -type f \( -name '*.gltf' -o -name '*.glb' \) | sort)
# The documented limits: table rows "| `PATH` | ..." of that README section, PATH relative to the repo.
limits=$(sed -n '/^### Where vplview and the glTF validator disagree/,/^#/p' "$repo/README.md" |
         sed -n 's/^| `\([^`]*\.gl[tb]f*\)` |.*/\1/p')
[ -n "$limits" ] || { echo "FAIL: README.md lists no limits (section missing or renamed?)"; status=1; }

validate --counts "${files[@]}" > "$tmp/counts" 2> "$tmp/report" || { cat "$tmp/report"; echo "FAIL: the validator did not run"; exit 1; }
[ "$(wc -l < "$tmp/counts")" = "${#files[@]}" ] || { cat "$tmp/report"; echo "FAIL: the validator skipped files"; exit 1; }
agree=0; documented=0
while IFS=$'\t' read -r errors file; do
  rel=$(realpath --relative-to="$repo" "$file")
  timeout 300 "$exe" render "$file" --mode brdf --spp 1 --width 4 --height 4 --threads 1 --out "$tmp/out.exr" \
    > /dev/null 2> "$tmp/err" < /dev/null; rc=$?
  if [ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ]; then verdict=refuses
  elif [ $rc = 0 ]; then verdict=renders
  else echo "FAIL: $rel: exit $rc: $(head -c 2000 "$tmp/err")"; status=1; continue
  fi
  if [ "$errors" -gt 0 ]; then expected=refuses; else expected=renders; fi
  if grep -qxF "$rel" <<< "$limits"; then
    [ $verdict != $expected ] || { echo "FAIL: $rel: README.md lists it as a limit, but vplview now $verdict it like the validator ($errors errors): remove it from the list"; status=1; }
    echo "limit: $rel: validator $errors errors, vplview $verdict it (README.md says why)"
    documented=$((documented + 1))
  elif [ $verdict = $expected ]; then
    echo "ok: $rel: validator $errors errors, vplview $verdict it$([ $verdict = refuses ] && echo ": $(cat "$tmp/err")")"
    agree=$((agree + 1))
  else
    echo "FAIL: $rel: the validator reports $errors errors, but vplview $verdict it: $(head -c 2000 "$tmp/err")"
    awk -v f="$file:" 'index($0, f) == 1 { p = 1; print; next } /^[^ ]/ { p = 0 } p' "$tmp/report"  # its issues
    status=1
  fi
done < "$tmp/counts"
echo "$agree files judged alike, $documented documented limits, of ${#files[@]}"
[ $status = 0 ] || exit 1
[ -d "$shared" ] || { echo "SKIP: $shared is absent: its scenes were not checked (the rest passed)"; exit 77; }
exit 0
