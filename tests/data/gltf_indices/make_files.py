#!/usr/bin/env python3
"""Writes the glTF files of tests/unit/test_gltf_indices.cpp: valid.gltf, which uses every kind of
index glTF 2.0 has (scene, nodes, mesh, camera, children, skin, light, primitive indices, attributes,
morph target, material, every textureInfo, texture source and sampler, image bufferView, accessor and
sparse bufferViews, bufferView buffer, animation), is clean under the Khronos glTF-Validator; each
bad_*.gltf breaks one index of it. no_triangles.gltf is valid and instances nothing.
float_index.gltf writes mesh index 0 as 0.0: the JavaScript validator accepts it, vplview does not
(README.md, "Where vplview and the glTF validator disagree").
Usage: tests/data/gltf_indices/make_files.py [OUT_DIR]"""
import copy, json, os, struct, sys

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "..", "fuzz"))
from make_corpus import data_uri, glb, png  # noqa: E402

out = sys.argv[1] if len(sys.argv) > 1 else here
image = png(2, 2)

# One buffer, each view 4-byte aligned: (name, bytes).
views = [
    ("positions", struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)),
    ("uvs", struct.pack("<6f", 0, 0, 1, 0, 0, 1)),
    ("indices", struct.pack("<3H", 0, 1, 2)),
    ("joints", bytes(12)),
    ("weights", struct.pack("<12f", *([1, 0, 0, 0] * 3))),
    ("inverse_bind", struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1)),
    ("times", struct.pack("<2f", 0, 1)),
    ("translations", struct.pack("<6f", 0, 0, 0, 0, 0, 1)),
    ("sparse_indices", bytes([1])),
    ("sparse_values", struct.pack("<2f", 0.5, 0.5)),
    ("morph", struct.pack("<9f", 0, 0, 0, 0, 0, 0, 0, 0, 0.5)),
    ("image", image),
]
binary, buffer_views = b"", []
for name, data in views:
    buffer_views.append({"buffer": 0, "byteOffset": len(binary), "byteLength": len(data)})
    binary += data + b"\0" * (-len(data) % 4)
V = {name: i for i, (name, _) in enumerate(views)}


def accessor(view, component, type_, count, **extra):
    a = {"componentType": component, "type": type_, "count": count, **extra}
    if view is not None:
        a["bufferView"] = V[view]
    return a


FLOAT, UBYTE, USHORT = 5126, 5121, 5123
valid = {
    "asset": {"version": "2.0", "generator": "tests/data/gltf_indices/make_files.py"},
    "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_specular"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 10}]}},
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [
        {"camera": 0, "translation": [0.25, 0.25, 3], "children": [2]},
        {"mesh": 0, "skin": 0},
        {"extensions": {"KHR_lights_punctual": {"light": 0}}},
    ],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
    "meshes": [{"primitives": [{
        "attributes": {"POSITION": 0, "TEXCOORD_0": 1, "JOINTS_0": 3, "WEIGHTS_0": 4},
        "indices": 2, "material": 0, "targets": [{"POSITION": 8}]}], "weights": [0]}],
    "skins": [{"joints": [2], "skeleton": 2, "inverseBindMatrices": 5}],
    "animations": [{"channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}],
                    "samplers": [{"input": 6, "output": 7}]}],
    "materials": [{
        "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicRoughnessTexture": {"index": 0}},
        "normalTexture": {"index": 1}, "occlusionTexture": {"index": 0},
        "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1],
        "extensions": {"KHR_materials_specular": {"specularTexture": {"index": 0}, "specularColorTexture": {"index": 0}}}}],
    "textures": [{"source": 0, "sampler": 0}, {"source": 1}],
    "samplers": [{"magFilter": 9729}],
    "images": [{"uri": data_uri("image/png", image)}, {"bufferView": V["image"], "mimeType": "image/png"}],
    "accessors": [
        accessor("positions", FLOAT, "VEC3", 3, min=[0, 0, 0], max=[1, 1, 0]),
        accessor("uvs", FLOAT, "VEC2", 3, sparse={"count": 1, "indices": {"bufferView": V["sparse_indices"], "componentType": UBYTE},
                                                   "values": {"bufferView": V["sparse_values"]}}),
        accessor("indices", USHORT, "SCALAR", 3),
        accessor("joints", UBYTE, "VEC4", 3),
        accessor("weights", FLOAT, "VEC4", 3),
        accessor("inverse_bind", FLOAT, "MAT4", 1),
        accessor("times", FLOAT, "SCALAR", 2, min=[0], max=[1]),
        accessor("translations", FLOAT, "VEC3", 2),
        accessor("morph", FLOAT, "VEC3", 3, min=[0, 0, 0], max=[0, 0, 0.5]),
    ],
    "bufferViews": buffer_views,
    "buffers": [{"byteLength": len(binary), "uri": data_uri("application/octet-stream", binary)}],
}

# (file, JSON path as a list, value): each breaks one index; the test holds vplview to the message.
BROKEN = [
    ("bad_scene", ["scene"], 1),
    ("bad_scene_node", ["scenes", 0, "nodes", 1], 3),
    ("bad_node_mesh", ["nodes", 1, "mesh"], -5),
    ("bad_node_mesh_minus_one", ["nodes", 1, "mesh"], -1),           # tinygltf: "no mesh"
    ("bad_node_mesh_2pow32", ["nodes", 1, "mesh"], 4294967296),      # tinygltf: mesh 0
    ("bad_node_mesh_fraction", ["nodes", 1, "mesh"], 0.5),           # tinygltf: "no mesh"
    ("bad_node_camera", ["nodes", 0, "camera"], 1),
    ("bad_node_child", ["nodes", 0, "children", 0], 7),
    ("bad_node_skin", ["nodes", 1, "skin"], 1),
    ("bad_node_light", ["nodes", 2, "extensions", "KHR_lights_punctual", "light"], 1),
    ("bad_primitive_indices", ["meshes", 0, "primitives", 0, "indices"], 9),
    ("bad_primitive_attribute", ["meshes", 0, "primitives", 0, "attributes", "POSITION"], 9),
    ("bad_primitive_target", ["meshes", 0, "primitives", 0, "targets", 0, "POSITION"], -2),
    ("bad_primitive_material", ["meshes", 0, "primitives", 0, "material"], 1),
    ("bad_base_color_texture", ["materials", 0, "pbrMetallicRoughness", "baseColorTexture", "index"], 2),
    ("bad_metallic_roughness_texture", ["materials", 0, "pbrMetallicRoughness", "metallicRoughnessTexture", "index"], 2),
    ("bad_normal_texture", ["materials", 0, "normalTexture", "index"], 2),
    ("bad_occlusion_texture", ["materials", 0, "occlusionTexture", "index"], 2),
    ("bad_emissive_texture", ["materials", 0, "emissiveTexture", "index"], -1),
    ("bad_specular_texture", ["materials", 0, "extensions", "KHR_materials_specular", "specularTexture", "index"], 2),
    ("bad_specular_color_texture", ["materials", 0, "extensions", "KHR_materials_specular", "specularColorTexture", "index"], -1),
    ("bad_texture_source", ["textures", 0, "source"], 2),
    ("bad_texture_sampler", ["textures", 0, "sampler"], 1),
    ("bad_image_buffer_view", ["images", 1, "bufferView"], 12),
    ("bad_accessor_buffer_view", ["accessors", 0, "bufferView"], 12),
    ("bad_sparse_indices_buffer_view", ["accessors", 1, "sparse", "indices", "bufferView"], 12),
    ("bad_sparse_values_buffer_view", ["accessors", 1, "sparse", "values", "bufferView"], -3),
    ("bad_buffer_view_buffer", ["bufferViews", 0, "buffer"], 1),
    ("bad_skin_joint", ["skins", 0, "joints", 0], 3),
    ("bad_skin_skeleton", ["skins", 0, "skeleton"], -1),
    ("bad_skin_inverse_bind_matrices", ["skins", 0, "inverseBindMatrices"], 9),
    ("bad_animation_channel_sampler", ["animations", 0, "channels", 0, "sampler"], 1),
    ("bad_animation_target_node", ["animations", 0, "channels", 0, "target", "node"], 3),
    ("bad_animation_input", ["animations", 0, "samplers", 0, "input"], 9),
    ("bad_animation_output", ["animations", 0, "samplers", 0, "output"], -1),
]


def write(name, content):
    with open(os.path.join(out, name), "wb") as f:
        f.write(content if isinstance(content, bytes) else (json.dumps(content, separators=(",", ":")) + "\n").encode())


def broken(path, value):
    doc = copy.deepcopy(valid)
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return doc


write("valid.gltf", valid)
for name, path, value in BROKEN:
    write(name + ".gltf", broken(path, value))
# The same negative mesh index in a GLB's JSON chunk (the buffer becomes the BIN chunk).
doc = broken(["nodes", 1, "mesh"], -5)
del doc["buffers"][0]["uri"]
write("bad_node_mesh.glb", glb(doc, binary))
write("float_index.gltf", broken(["nodes", 1, "mesh"], 0.0))
write("no_triangles.gltf", {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
                            "nodes": [{"camera": 0}], "cameras": valid["cameras"]})
