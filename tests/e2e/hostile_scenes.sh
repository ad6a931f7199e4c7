#!/usr/bin/env bash
# vplview render on hostile scenes: accessors claiming gigabytes, an image header claiming
# 16384^2 pixels, URIs leaving the scene's folder (../, absolute, %2e%2e), and every input the
# fuzzer once crashed on (fuzz/regressions/). Each must end in exit status 2 with one line on
# stderr, quickly. Usage (CTest): hostile_scenes.sh PATH/TO/vplview REPO_ROOT.
set -u
exe=$1; repo=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/scene"
fail() { echo "FAIL: $*"; exit 1; }

python3 - "$tmp" <<'PY' || fail "writing the scenes"
import base64, json, os, struct, sys
tmp = sys.argv[1]
tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
open(os.path.join(tmp, "outside.bin"), "wb").write(tri)
inline = "data:application/octet-stream;base64," + base64.b64encode(tri).decode()
def scene(name, uri=inline, count=3, extra=None):
    doc = {"asset": {"version": "2.0"}, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
           "accessors": [{"bufferView": 0, "componentType": 5126, "count": count, "type": "VEC3"}],
           "bufferViews": [{"buffer": 0, "byteLength": 36}], "buffers": [{"byteLength": 36, "uri": uri}]}
    doc.update(extra or {})
    json.dump(doc, open(os.path.join(tmp, "scene", name), "w"))
png = b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" + struct.pack(">IIBBBBB", 16384, 16384, 8, 6, 0, 0, 0) + b"CRC!"
png += struct.pack(">I", 2) + b"IDATx\x9c" + b"CRC!"  # stb_image reads the header up to the first IDAT
scene("accessor_24GB.gltf", count=2_000_000_000)
scene("accessor_1.5GB_in_36_bytes.gltf", count=125_000_000)
scene("image_16384x16384.gltf", extra={"images": [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}]})
scene("uri_dotdot.gltf", uri="../outside.bin")
scene("uri_absolute.gltf", uri=os.path.join(tmp, "outside.bin"))
scene("uri_percent_encoded.gltf", uri="%2e%2e%2Foutside.bin")
PY
cp "$repo"/fuzz/regressions/* "$tmp/scene/" 2>/dev/null

n=0
for f in "$tmp"/scene/*; do
  start=$EPOCHREALTIME
  timeout 60 "$exe" render "$f" --mode brdf --spp 1 --width 8 --height 8 --threads 1 --out "$tmp/out.exr" \
    > /dev/null 2> "$tmp/err"; rc=$?
  secs=$(awk "BEGIN { printf \"%.2f\", $EPOCHREALTIME - $start }")
  [ $rc = 2 ] && [ "$(grep -c . "$tmp/err")" = 1 ] || fail "$(basename "$f"): exit $rc: $(head -c 2000 "$tmp/err")"
  echo "ok: $(basename "$f") (${secs} s): $(cat "$tmp/err")"
  n=$((n + 1))
done
echo "ok: $n hostile scenes refused with one line and exit 2"
