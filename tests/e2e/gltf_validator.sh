#!/usr/bin/env bash
# Runs the Khronos glTF-Validator on every built-in scene (committed and generated).
# Usage (CTest): gltf_validator.sh PATH/TO/vplview REPO_ROOT. Exit 77 (skip) without node or the validator.
set -u
build=$(cd "$(dirname "$1")" && pwd); repo=$2
validator=$build/tools/node_modules/gltf-validator
if ! command -v node >/dev/null || [ ! -d "$validator" ]; then
  echo "SKIP: node or $validator is missing (scripts/setup.sh installs it when npm can reach its registry)"
  exit 77
fi
GLTF_VALIDATOR=$validator node "$repo/tests/e2e/gltf_validator.mjs" "$repo"/scenes/*.gltf "$build"/scenes/*.glb
