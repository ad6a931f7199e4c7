#!/usr/bin/env bash
# Makes the Cycles references of tests/unit/test_cycles_anchor.cpp: the built-in scenes that
# Blender's Cycles maps exactly (../shared/tools/cycles/README.md: Lambertians, front-side
# emitters), each as 8 independent renders (seeds 1..8) of 16384 samples per pixel, 32x24 pixels,
# --max-bounces 7 (= vplview --max-depth 8: Cycles counts bounces after the camera hit, vplview
# counts path segments from the camera). The test averages the 8 and takes Cycles' own standard
# error from their spread. Refused (exit 2, no exact counterpart): cornell_glossy (dielectric
# glossy layers, metallic 0 with specularFactor 1) and the generated interior (the same).
# Usage, from the repository root: tests/data/cycles/make_references.sh [BUILD_DIR] [SCENE...]
# (default: build, every scene below; BUILD_DIR holds the generated scenes/skylit_hall.glb and
# lamp_rooms.glb). 1-2 min for cornell_box, about 6 for two_rooms, 5 for skylit_hall, 2 for lamp_rooms and 2 for door_ajar, on 2 idle cores; needs
# `apt-get install blender python3-numpy`.
set -euo pipefail
repo=$(cd "$(dirname "$0")/../../.." && pwd)
build=${1:-$repo/build}
shift || true
tool=$repo/../shared/tools/cycles/cycles-render
out=$repo/tests/data/cycles
. "$repo/bench/lib.sh"
for scene in ${*:-cornell_box two_rooms skylit_hall lamp_rooms door_ajar}; do
  file=$(scene_file "$repo" "$build" "$scene" make_references)
  for seed in 1 2 3 4 5 6 7 8; do
    "$tool" "$file" "$out/${scene}_seed$seed.exr" \
      --width 32 --height 24 --spp 16384 --seed "$seed" --max-bounces 7 --threads 2
  done
done
