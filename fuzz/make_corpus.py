#!/usr/bin/env python3
"""Writes the fuzzer's seed corpus (fuzz/corpus/): small hand-made glTF files that reach every
part of the loader (data-URI buffers and images, indices, normals, texture coordinates, sparse
accessors, strips and fans, node transforms, lights, a camera, external URIs the fuzz target
provides as b.bin and i.png, GLB with a BIN chunk), and the built-in scenes with their buffer
inlined as a data URI (as .gltf and .glb). Usage: fuzz/make_corpus.py [OUT_DIR]"""
import base64, json, os, struct, sys, zlib

here = os.path.dirname(os.path.abspath(__file__))
out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "corpus")
scenes = os.path.join(here, "..", "scenes")


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


def png(w, h):
    """An RGBA PNG with a small gradient (zlib, no filter)."""
    rows = b"".join(b"\0" + b"".join(bytes((x * 60 % 256, y * 60 % 256, 128, 255)) for x in range(w)) for y in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b""))


def glb(doc, binary):
    """A GLB container: JSON chunk, then the BIN chunk, each padded to 4 bytes."""
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    body = struct.pack("<II", len(js), 0x4E4F534A) + js + struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def write(name, content):
    with open(os.path.join(out, name), "wb") as f:
        f.write(content if isinstance(content, bytes) else json.dumps(content, separators=(",", ":")).encode())


TRIANGLE = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)


def triangle_doc(uri):
    return {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                           "min": [0, 0, 0], "max": [1, 1, 0]}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}],
            "buffers": [{"byteLength": 36, **({"uri": uri} if uri else {})}]}


def textured_quad():
    """Indexed quad with normals, UVs, a sparse accessor, a textured emissive material, lights, camera."""
    pos = struct.pack("<12f", -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0)
    nrm = struct.pack("<12f", *([0, 0, 1] * 4))
    uv = struct.pack("<8H", 0, 0, 65535, 0, 65535, 65535, 0, 65535)  # normalized unsigned short
    idx = struct.pack("<6B", 0, 1, 2, 0, 2, 3) + b"\0\0"
    sparse_idx = struct.pack("<H", 2) + b"\0\0"
    sparse_val = struct.pack("<3f", 1, 1, 0.5)
    data = pos + nrm + uv + idx + sparse_idx + sparse_val
    views, off = [], 0
    for chunk in (pos, nrm, uv, idx, sparse_idx, sparse_val):
        views.append({"buffer": 0, "byteOffset": off, "byteLength": len(chunk)})
        off += len(chunk)
    views[0]["byteStride"] = 12
    return {
        "asset": {"version": "2.0"}, "scene": 0,
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_ior",
                           "KHR_materials_specular"],
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [{"children": [1], "translation": [0, 0, -2], "rotation": [0, 0.3826834, 0, 0.9238795], "scale": [1, 2, 1]},
                  {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1]},
                  {"camera": 0, "translation": [0, 0, 3], "children": [3]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}}, ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "aspectRatio": 1.5, "znear": 0.01}}],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "spot", "color": [1, 0.9, 0.8], "intensity": 20, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
            {"type": "directional", "intensity": 2}]}},
        "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
                                                    "indices": 3, "material": 0}]}],
        "materials": [{"name": "lamp", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1],
                                                                "baseColorTexture": {"index": 0},
                                                                "metallicRoughnessTexture": {"index": 0},
                                                                "metallicFactor": 0.2, "roughnessFactor": 0.4},
                       "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}, "alphaMode": "MASK",
                       "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
                                      "KHR_materials_ior": {"ior": 1.45},
                                      "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 0.5]}}}],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33648}],
        "images": [{"uri": data_uri("image/png", png(4, 4))}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0.5],
             "sparse": {"count": 1, "indices": {"bufferView": 4, "componentType": 5123},
                        "values": {"bufferView": 5}}},
            {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "normalized": True, "count": 4, "type": "VEC2"},
            {"bufferView": 3, "componentType": 5121, "count": 6, "type": "SCALAR"}],
        "bufferViews": views,
        "buffers": [{"byteLength": len(data), "uri": data_uri("application/octet-stream", data)}]}


def strip_and_fan():
    pos = struct.pack("<15f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 0, 0)
    doc = triangle_doc(data_uri("application/gltf-buffer", pos))
    doc["accessors"][0]["count"] = 5
    doc["bufferViews"][0]["byteLength"] = doc["buffers"][0]["byteLength"] = len(pos)
    doc["meshes"][0]["primitives"] = [{"attributes": {"POSITION": 0}, "mode": 5}, {"attributes": {"POSITION": 0}, "mode": 6},
                                      {"attributes": {"POSITION": 0}, "mode": 1}]
    return doc


def external():
    doc = triangle_doc("b.bin")
    doc["images"] = [{"uri": "i.png"}]
    doc["textures"] = [{"source": 0}]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    return doc


def glb_triangle():
    image = png(2, 2)
    binary = TRIANGLE + image
    doc = triangle_doc(None)
    doc["buffers"][0]["byteLength"] = len(binary)
    doc["bufferViews"].append({"buffer": 0, "byteOffset": 36, "byteLength": len(image)})
    doc["images"] = [{"bufferView": 1, "mimeType": "image/png"}]
    doc["textures"] = [{"source": 0}]
    doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["meshes"][0]["primitives"][0]["material"] = 0
    return glb(doc, binary)


def inlined(name):
    """A built-in scene with its external buffer as a data URI, and the same as a GLB."""
    with open(os.path.join(scenes, name + ".gltf")) as f:
        doc = json.load(f)
    with open(os.path.join(scenes, doc["buffers"][0]["uri"]), "rb") as f:
        binary = f.read()
    doc["buffers"][0]["uri"] = data_uri("application/octet-stream", binary)
    write(name + "_inline.gltf", doc)
    del doc["buffers"][0]["uri"]
    write(name + ".glb", glb(doc, binary))


if __name__ == "__main__":  # tests/data/gltf_indices/make_files.py imports the helpers above
    os.makedirs(out, exist_ok=True)
    write("triangle.gltf", triangle_doc(data_uri("application/octet-stream", TRIANGLE)))
    write("textured_quad.gltf", textured_quad())
    write("strip_fan.gltf", strip_and_fan())
    write("external.gltf", external())
    write("triangle.glb", glb_triangle())
    for scene in ("cornell_box", "cornell_glossy", "two_rooms"):
        inlined(scene)
