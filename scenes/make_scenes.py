#!/usr/bin/env python3
"""Writes vplview's built-in glTF 2.0 scenes (standard library only, deterministic output).

  python3 make_scenes.py                  # the committed small scenes, into this folder
  python3 make_scenes.py --out DIR        # every scene, into DIR
  python3 make_scenes.py --interior-only --out DIR   # the generated ones: interior, skylit hall, lamp rooms (CMake)

Scenes: cornell_box (the viewer's default), cornell_glossy, two_rooms (light in one room, camera in
the other), door_ajar (light only behind a door open 15 degrees, camera in the other room),
interior.glb (a sun-lit hall of more than 100K triangles, a Sponza stand-in), skylit_hall.glb (the
same hall, matte, lit through its skylights by an emitting panel: a large scene Cycles maps exactly),
lamp_rooms.glb (six rooms in a row, each lit by its own tessellated globe lamp: 1920 emitting
triangles, most of them hidden from any one point).
Units are metres, +Y up. Punctual intensities: candela / lux; emission: nits (emissive strength).
"""
import argparse
import json
import math
import os
import struct

# ---------------------------------------------------------------------------------------------
# geometry


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def add(a, b): return (a[0] + b[0], a[1] + b[1], a[2] + b[2])
def mul(a, s): return (a[0] * s, a[1] * s, a[2] * s)
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    l = math.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    return (a[0] / l, a[1] / l, a[2] / l)


def rot_y(p, degrees, centre):
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    x, z = p[0] - centre[0], p[2] - centre[2]
    return (centre[0] + c * x + s * z, p[1], centre[2] - s * x + c * z)


class Mesh:
    """Triangles of one material. Flat faces get their own vertices; smooth surfaces share them."""

    def __init__(self, name, material):
        self.name, self.material = name, material
        self.positions, self.normals, self.indices = [], [], []

    def vertex(self, p, n):
        self.positions.append(p)
        self.normals.append(n)
        return len(self.positions) - 1

    def quad(self, p0, p1, p2, p3):
        """Counter-clockwise seen from the side the normal points to."""
        n = norm(cross(sub(p1, p0), sub(p2, p0)))
        i = [self.vertex(p, n) for p in (p0, p1, p2, p3)]
        self.indices += [i[0], i[1], i[2], i[0], i[2], i[3]]

    def box(self, lo, hi, rotate=0.0, inward=False):
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        c = ((x0 + x1) / 2, 0, (z0 + z1) / 2)
        v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
        v = [rot_y(p, rotate, c) for p in v]
        faces = [(4, 5, 6, 7), (1, 0, 3, 2), (0, 4, 7, 3), (5, 1, 2, 6), (3, 7, 6, 2), (0, 1, 5, 4)]
        for f in faces:
            q = [v[k] for k in f]
            if inward:
                q = q[::-1]
            self.quad(*q)

    def sphere(self, centre, radius, subdivisions):
        """An icosphere: the icosahedron's faces split in four `subdivisions` times, wound outwards."""
        t = (1.0 + math.sqrt(5.0)) / 2.0
        points = [norm(p) for p in ((-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                                    (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1))]
        faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
                 (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
                 (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
        for _ in range(subdivisions):
            midpoints, split = {}, []

            def midpoint(a, b):
                key = (min(a, b), max(a, b))
                if key not in midpoints:
                    points.append(norm(mul(add(points[a], points[b]), 0.5)))
                    midpoints[key] = len(points) - 1
                return midpoints[key]
            for a, b, c in faces:
                ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
                split += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
            faces = split
        first = len(self.positions)
        for n in points:
            self.vertex(add(centre, mul(n, radius)), n)
        for f in faces:
            self.indices += [first + k for k in f]

    def slab(self, corner, a, b, c):
        """A parallelepiped from corner along edges a, b, c, each face wound to face outwards."""
        centre = add(corner, mul(add(add(a, b), c), 0.5))
        for (o, e1, e2) in ((corner, a, b), (corner, b, c), (corner, c, a)):
            for far in (False, True):
                if far:
                    third = c if e1 is a else (a if e1 is b else b)
                    o2 = add(o, third)
                else:
                    o2 = o
                q = [o2, add(o2, e1), add(add(o2, e1), e2), add(o2, e2)]
                n = cross(e1, e2)
                mid = add(o2, mul(add(e1, e2), 0.5))
                if sum(n[k] * (mid[k] - centre[k]) for k in range(3)) < 0:
                    q = q[::-1]
                self.quad(*q)

    def cylinder(self, base, radius, height, segments, rings):
        """Smooth-shaded open cylinder along +Y."""
        first = len(self.positions)
        for r in range(rings + 1):
            y = base[1] + height * r / rings
            for s in range(segments):
                a = 2 * math.pi * s / segments
                n = (math.cos(a), 0.0, math.sin(a))
                self.vertex((base[0] + radius * n[0], y, base[2] + radius * n[2]), n)
        for r in range(rings):
            for s in range(segments):
                a = first + r * segments + s
                b = first + r * segments + (s + 1) % segments
                c, d = a + segments, b + segments
                self.indices += [a, c, b, b, c, d]

    def arch(self, centre, radius, thickness, depth, segments, axis_x=True):
        """A semicircular arch (a half annulus extruded along z or x), smooth inner and outer faces."""
        def point(angle, r, w):
            u = r * math.cos(angle)
            y = centre[1] + r * math.sin(angle)
            return (centre[0] + u, y, centre[2] + w) if axis_x else (centre[0] + w, y, centre[2] + u)
        for s in range(segments):
            a0, a1 = math.pi * s / segments, math.pi * (s + 1) / segments
            for (r, sign) in ((radius, -1), (radius + thickness, 1)):
                p = [point(a0, r, -depth / 2), point(a1, r, -depth / 2), point(a1, r, depth / 2), point(a0, r, depth / 2)]
                self.quad(*(p if sign < 0 else p[::-1]))
            for w in (-depth / 2, depth / 2):
                p = [point(a0, radius, w), point(a0, radius + thickness, w), point(a1, radius + thickness, w), point(a1, radius, w)]
                self.quad(*(p if w > 0 else p[::-1]))


# ---------------------------------------------------------------------------------------------
# glTF writing


def material(name, base, metallic=0.0, roughness=1.0, emissive=None, strength=1.0, lambert=False, double_sided=True):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": [base[0], base[1], base[2], 1.0],
                                                 "metallicFactor": metallic, "roughnessFactor": roughness},
         "doubleSided": double_sided}
    ext = {}
    if emissive:
        m["emissiveFactor"] = list(emissive)
        if strength != 1.0:
            ext["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
    if lambert:
        ext["KHR_materials_specular"] = {"specularFactor": 0.0}
    if ext:
        m["extensions"] = ext
    return m


def build_gltf(meshes, materials, camera, lights=(), bin_uri=None):
    """Returns (json dict, binary buffer). camera = (eye, target, yfov radians)."""
    blob = bytearray()
    views, accessors, gl_meshes, nodes = [], [], [], []

    def push(data, target):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        return len(views) - 1

    for mesh in meshes:
        pos = struct.pack("<%df" % (3 * len(mesh.positions)), *[c for p in mesh.positions for c in p])
        nrm = struct.pack("<%df" % (3 * len(mesh.normals)), *[c for n in mesh.normals for c in n])
        idx = struct.pack("<%dI" % len(mesh.indices), *mesh.indices)
        lo = [min(p[k] for p in mesh.positions) for k in range(3)]
        hi = [max(p[k] for p in mesh.positions) for k in range(3)]
        accessors.append({"bufferView": push(pos, 34962), "componentType": 5126, "count": len(mesh.positions),
                          "type": "VEC3", "min": lo, "max": hi})
        accessors.append({"bufferView": push(nrm, 34962), "componentType": 5126, "count": len(mesh.normals), "type": "VEC3"})
        accessors.append({"bufferView": push(idx, 34963), "componentType": 5125, "count": len(mesh.indices), "type": "SCALAR"})
        a = len(accessors) - 3
        gl_meshes.append({"name": mesh.name, "primitives": [{"attributes": {"POSITION": a, "NORMAL": a + 1},
                                                              "indices": a + 2, "material": mesh.material}]})
        nodes.append({"name": mesh.name, "mesh": len(gl_meshes) - 1})

    # Camera node: glTF cameras look down their local -Z with +Y up.
    eye, target, yfov = camera
    f = norm(sub(target, eye))
    r = norm(cross(f, (0.0, 1.0, 0.0)))
    u = cross(r, f)
    matrix = [r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, -f[0], -f[1], -f[2], 0, eye[0], eye[1], eye[2], 1]
    nodes.append({"name": "camera", "camera": 0, "matrix": [round(x, 9) for x in matrix]})

    ext_used = sorted({k for m in materials for k in m.get("extensions", {})})
    doc = {"asset": {"version": "2.0", "generator": "vplview scenes/make_scenes.py"},
           "scene": 0, "scenes": [{"nodes": list(range(len(nodes) + len(lights)))}],
           "nodes": nodes, "meshes": gl_meshes, "materials": materials, "accessors": accessors,
           "bufferViews": views, "buffers": [{"byteLength": len(blob)}],
           "cameras": [{"type": "perspective", "perspective": {"yfov": yfov, "znear": 0.01}}]}
    if bin_uri:
        doc["buffers"][0]["uri"] = bin_uri
    if lights:
        doc["extensions"] = {"KHR_lights_punctual": {"lights": [l for l, _ in lights]}}
        ext_used.append("KHR_lights_punctual")
        for i, (_, node) in enumerate(lights):
            node = dict(node)
            node["extensions"] = {"KHR_lights_punctual": {"light": i}}
            nodes.append(node)
    if ext_used:
        doc["extensionsUsed"] = sorted(ext_used)
    return doc, bytes(blob)


def write_gltf(folder, name, doc_and_blob):
    doc, blob = doc_and_blob
    doc["buffers"][0]["uri"] = name + ".bin"
    with open(os.path.join(folder, name + ".gltf"), "w") as f:
        json.dump(doc, f, indent=1, sort_keys=True)
        f.write("\n")
    with open(os.path.join(folder, name + ".bin"), "wb") as f:
        f.write(blob)


def write_glb(path, doc_and_blob):
    doc, blob = doc_and_blob
    text = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    blob = blob + b"\0" * (-len(blob) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    with open(path, "wb") as f:
        f.write(struct.pack("<4sII", b"glTF", 2, total))
        f.write(struct.pack("<I4s", len(text), b"JSON") + text)
        f.write(struct.pack("<I4s", len(blob), b"BIN\0") + blob)


# ---------------------------------------------------------------------------------------------
# scenes

WHITE, RED, GREEN = (0.725, 0.71, 0.68), (0.63, 0.065, 0.05), (0.14, 0.45, 0.091)
SKY_PANEL_STRENGTH = 12.0  # nits: the skylit hall's panel


def cornell(glossy):
    """McGuire's CornellBox-Original proportions: 2 m wide, open towards +Z, light under the ceiling."""
    mats = [material("white", WHITE, lambert=True), material("red", RED, lambert=True),
            material("green", GREEN, lambert=True),
            material("light", (0.78, 0.78, 0.78), emissive=(1.0, 12 / 17, 4 / 17), strength=17.0, lambert=True,
                     double_sided=False)]
    tall_mat = short_mat = back_mat = 0
    if glossy:
        mats += [material("copper", (0.95, 0.64, 0.54), metallic=1.0, roughness=0.25),
                 material("glossy_white", WHITE, roughness=0.15),
                 material("glossy_back", WHITE, roughness=0.35)]
        tall_mat, short_mat, back_mat = 4, 5, 6
    x0, x1, y0, y1, z0, z1 = -1.02, 1.0, 0.0, 1.99, -1.04, 0.99
    room = Mesh("walls", 0)
    room.quad((x0, y0, z1), (x1, y0, z1), (x1, y0, z0), (x0, y0, z0))  # floor, normal +Y
    room.quad((x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1))  # ceiling, normal -Y
    back = Mesh("back", back_mat)
    back.quad((x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0))  # back wall, normal +Z
    left = Mesh("left_red", 1)
    left.quad((x0, y0, z1), (x0, y0, z0), (x0, y1, z0), (x0, y1, z1))
    right = Mesh("right_green", 2)
    right.quad((x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0))
    light = Mesh("light", 3)
    light.quad((-0.24, 1.98, -0.22), (0.23, 1.98, -0.22), (0.23, 1.98, 0.16), (-0.24, 1.98, 0.16))  # faces -Y
    short = Mesh("short_box", short_mat)
    short.box((0.05, 0.0, 0.06), (0.65, 0.6, 0.66), rotate=-17.0)
    tall = Mesh("tall_box", tall_mat)
    tall.box((-0.69, 0.0, -0.66), (-0.09, 1.2, -0.06), rotate=17.0)
    meshes = [room, back, left, right, light, short, tall]
    return build_gltf(meshes, mats, ((0.0, 1.0, 3.9), (0.0, 1.0, 0.0), math.radians(39.3)))


def two_rooms():
    """Room A (x < 0) holds the light; the camera stands in room B and sees A only through a doorway."""
    mats = [material("white", (0.8, 0.8, 0.78), lambert=True), material("floor", (0.6, 0.45, 0.3), lambert=True),
            material("blue", (0.2, 0.3, 0.7), lambert=True), material("terracotta", (0.7, 0.3, 0.2), lambert=True),
            material("lamp", (0.8, 0.8, 0.8), emissive=(1.0, 0.9, 0.75), strength=40.0, lambert=True, double_sided=False)]
    W, H, D, door_w, door_h = 4.0, 3.0, 2.0, 0.5, 2.1
    walls, floor, blue, boxes, lamp = Mesh("walls", 0), Mesh("floor", 1), Mesh("blue_wall", 2), Mesh("furniture", 3), Mesh("lamp", 4)
    floor.quad((-W, 0, D), (W, 0, D), (W, 0, -D), (-W, 0, -D))
    walls.quad((-W, H, -D), (W, H, -D), (W, H, D), (-W, H, D))
    walls.quad((-W, 0, -D), (W, 0, -D), (W, H, -D), (-W, H, -D))   # back (z = -D)
    walls.quad((W, 0, D), (-W, 0, D), (-W, H, D), (W, H, D))       # front (z = +D)
    walls.quad((-W, 0, D), (-W, 0, -D), (-W, H, -D), (-W, H, D))   # far end of room A
    blue.quad((W, 0, -D), (W, 0, D), (W, H, D), (W, H, -D))        # far end of room B
    # The dividing wall at x = 0 with a doorway (|z| < door_w, y < door_h); two-sided.
    walls.quad((0, 0, -D), (0, 0, -door_w), (0, H, -door_w), (0, H, -D))
    walls.quad((0, 0, door_w), (0, 0, D), (0, H, D), (0, H, door_w))
    walls.quad((0, door_h, -door_w), (0, door_h, door_w), (0, H, door_w), (0, H, -door_w))
    lamp.quad((-2.5, H - 0.01, -0.5), (-1.5, H - 0.01, -0.5), (-1.5, H - 0.01, 0.5), (-2.5, H - 0.01, 0.5))
    boxes.box((1.6, 0.0, -1.6), (2.6, 0.8, -0.9), rotate=20.0)
    boxes.box((0.6, 0.0, 1.2), (1.2, 1.6, 1.8), rotate=-10.0)
    boxes.box((-3.4, 0.0, -1.5), (-2.6, 0.5, -0.7), rotate=5.0)
    return build_gltf([floor, walls, blue, boxes, lamp], mats, ((3.7, 1.4, 1.7), (0.0, 1.0, -0.1), math.radians(60.0)))


def door_ajar(strength=None):
    """Light only behind a door ajar: room A (x < -T/2) holds the lamp, room B (x > T/2) the camera.

    Plan (metres, +Y up; the dividing wall is T = 0.2 thick, x in [-0.1, 0.1], floor to ceiling):
      * A floor-to-ceiling doorway, z in [-0.43, 0.43], in the dividing wall. Its door (0.04 thick)
        hangs on the -z jamb, on room A's face of the wall, and is open 15 degrees into room A, so the
        only way from A to B is the vertical slit between its free edge and the +z jamb corner
        (x, z) = (-0.1, 0.43): 0.225 m at its narrowest (2.5 m tall). The door runs 5 cm past its
        hinge line into the wall and 1 cm into floor and ceiling, and the wall's faces run 1 cm past
        the room's, so no crack between touching surfaces leaks light.
      * The lamp is a 0.7 x 0.6 m panel on room A's face of the dividing wall, on the hinge side
        (z in [-1.7, -1.0]), 5 mm off the wall, emitting from its front (-X) side only. Every ray it
        emits therefore has direction.x < 0 and stays at x < -0.105, so no straight line from the
        lamp reaches room B (x >= 0.1): room B is lit only by light that has bounced in room A and
        come through the slit, and the lamp itself is never seen from B (B looks at its back).
        A render at --max-depth 1 (direct light only) is black except where the camera sees room A
        through the slit (checked at +12 stops); room B itself first shows light at --max-depth 2.
      * The camera stands in room B's -z corner and looks across the doorway, through the slit, to
        the lit far corner of room A.
    Materials map exactly to Cycles (tools/cycles/README.md): Lambertian (metallic 0, specular 0);
    the lamp has a black base colour.
    """
    lamp_strength = 1000.0 if strength is None else strength
    mats = [material("white", (0.8, 0.8, 0.78), lambert=True), material("floor", (0.6, 0.45, 0.3), lambert=True),
            material("terracotta", (0.7, 0.3, 0.2), lambert=True), material("blue", (0.2, 0.3, 0.7), lambert=True),
            material("door", (0.75, 0.7, 0.6), lambert=True),
            material("lamp", (0.0, 0.0, 0.0), emissive=(1.0, 0.9, 0.75), strength=lamp_strength, lambert=True,
                     double_sided=False)]
    XA, XB, D, H = -4.0, 4.5, 2.0, 2.5           # room A's far end, room B's far end, half depth, height
    T, half_door, E = 0.2, 0.43, 0.01            # wall thickness, half the doorway, overlap of touching parts
    angle, door_t = math.radians(15.0), 0.04
    walls, floor, warm, blue, door, furniture, lamp = (Mesh("walls", 0), Mesh("floor", 1), Mesh("room_a_end", 2),
                                                        Mesh("room_b_end", 3), Mesh("door", 4), Mesh("furniture", 0),
                                                        Mesh("lamp", 5))
    floor.quad((XA, 0, D), (XB, 0, D), (XB, 0, -D), (XA, 0, -D))
    walls.quad((XA, H, -D), (XB, H, -D), (XB, H, D), (XA, H, D))      # ceiling
    walls.quad((XA, 0, -D), (XB, 0, -D), (XB, H, -D), (XA, H, -D))    # side z = -D
    walls.quad((XB, 0, D), (XA, 0, D), (XA, H, D), (XB, H, D))        # side z = +D
    warm.quad((XA, 0, D), (XA, 0, -D), (XA, H, -D), (XA, H, D))       # room A's far end
    blue.quad((XB, 0, -D), (XB, 0, D), (XB, H, D), (XB, H, -D))       # room B's far end
    # The dividing wall: a solid from x = -T/2 to T/2 with the doorway cut through it (two-sided faces).
    xa, xb, y0, y1 = -T / 2, T / 2, -E, H + E
    for z0, z1 in ((-D - E, -half_door), (half_door, D + E)):
        walls.quad((xa, y0, z0), (xa, y0, z1), (xa, y1, z1), (xa, y1, z0))  # room A's face, normal -X
        walls.quad((xb, y0, z1), (xb, y0, z0), (xb, y1, z0), (xb, y1, z1))  # room B's face, normal +X
    walls.quad((xa, y0, -half_door), (xb, y0, -half_door), (xb, y1, -half_door), (xa, y1, -half_door))  # jamb, +Z
    walls.quad((xb, y0, half_door), (xa, y0, half_door), (xa, y1, half_door), (xb, y1, half_door))      # jamb, -Z
    # The door: its wall-side face runs from the hinge line (on room A's face, 1 cm past the -z jamb)
    # towards +z, turned by `angle` into room A; 5 cm of it continue into the wall behind the hinge.
    u = (-math.sin(angle), 0.0, math.cos(angle))        # along the door, hinge to free edge
    n = (-math.cos(angle), 0.0, -math.sin(angle))       # its thickness, into room A
    hinge = (xa, y0, -half_door - E)
    length = 2 * half_door + E                          # free edge: 0.225 m from the +z jamb corner
    door.slab(add(hinge, mul(u, -0.05)), mul(u, length + 0.05), (0.0, y1 - y0, 0.0), mul(n, door_t))
    # The lamp: on room A's face of the wall, hinge side, facing -X.
    lx = xa - 0.005
    lamp.quad((lx, 1.5, -1.7), (lx, 1.5, -1.0), (lx, 2.1, -1.0), (lx, 2.1, -1.7))
    furniture.box((-3.2, 0.0, 0.6), (-2.2, 0.75, 1.5), rotate=10.0)     # room A: a table-sized block
    furniture.box((2.4, 0.0, 1.3), (3.6, 0.9, 1.9))                     # room B: a sideboard
    furniture.box((1.0, 0.0, -1.9), (1.8, 0.45, -0.9), rotate=15.0)     # room B: a low bench
    return build_gltf([floor, walls, warm, blue, door, furniture, lamp], mats,
                      ((4.0, 1.5, -1.7), (0.0, 1.0, 0.3), math.radians(60.0)))


HALL_SIZE = (10.0, 5.0, 8.0)  # half length (x), half width (z), height (y)
HALL_CAMERA = ((-9.0, 1.7, -3.8), (4.0, 3.0, 1.5), math.radians(65.0))


def hall_meshes():
    """The hall of the interior: colonnades, arches, a gallery and furniture under a roof with skylights."""
    stone, floor, wood, cloth, plaster = (Mesh("columns", 0), Mesh("floor", 1), Mesh("furniture", 2), Mesh("banners", 3),
                                          Mesh("walls", 4))
    X, Z, H = HALL_SIZE
    floor.quad((-X, 0, Z), (X, 0, Z), (X, 0, -Z), (-X, 0, -Z))
    plaster.quad((-X, 0, -Z), (X, 0, -Z), (X, H, -Z), (-X, H, -Z))
    plaster.quad((X, 0, Z), (-X, 0, Z), (-X, H, Z), (X, H, Z))
    plaster.quad((-X, 0, Z), (-X, 0, -Z), (-X, H, -Z), (-X, H, Z))
    plaster.quad((X, 0, -Z), (X, 0, Z), (X, H, Z), (X, H, -Z))
    # Roof on a 20 x 10 grid of 1 m cells, with a strip of skylights along the nave.
    for i in range(20):
        for k in range(10):
            x, z = -X + i, -Z + k
            skylight = 2 <= i <= 17 and k in (4, 5) and i % 3 != 1
            if not skylight:
                plaster.quad((x, H, z), (x + 1, H, z), (x + 1, H, z + 1), (x, H, z + 1))
    # Two colonnades (finely tessellated columns) carrying arches, and a gallery above the aisles.
    for side in (-1, 1):
        zc = side * 2.5
        for i in range(8):
            xc = -8.75 + 2.5 * i
            stone.cylinder((xc, 0.0, zc), 0.28, 4.0, 96, 48)
            stone.box((xc - 0.4, 0.0, zc - 0.4), (xc + 0.4, 0.3, zc + 0.4))
            stone.box((xc - 0.4, 3.9, zc - 0.4), (xc + 0.4, 4.1, zc + 0.4))
            if i < 7:
                stone.arch((xc + 1.25, 4.1, zc), 0.85, 0.3, 0.6, 64, axis_x=True)
        gallery_z0, gallery_z1 = (zc, side * Z) if side > 0 else (side * Z, zc)
        stone.box((-X, 5.0, min(gallery_z0, gallery_z1)), (X, 5.25, max(gallery_z0, gallery_z1)))
        stone.box((-X, 5.25, zc - 0.06), (X, 6.1, zc + 0.06))  # balustrade
        for i in range(8):
            cloth.quad((-8.0 + 2.5 * i, 3.0, zc - side * 0.31), (-7.4 + 2.5 * i, 3.0, zc - side * 0.31),
                       (-7.4 + 2.5 * i, 4.6, zc - side * 0.31), (-8.0 + 2.5 * i, 4.6, zc - side * 0.31))
    # Tables with chairs along the nave.
    for i in range(6):
        xc = -7.5 + 3.0 * i
        wood.box((xc - 0.8, 0.72, -0.45), (xc + 0.8, 0.78, 0.45))
        for dx in (-0.7, 0.7):
            for dz in (-0.35, 0.35):
                wood.box((xc + dx - 0.04, 0.0, dz - 0.04), (xc + dx + 0.04, 0.72, dz + 0.04))
        for dz, back in ((-0.8, -1.0), (0.8, 1.0)):
            for dx in (-0.45, 0.45):
                wood.box((xc + dx - 0.22, 0.42, dz - 0.22), (xc + dx + 0.22, 0.46, dz + 0.22))
                wood.box((xc + dx - 0.22, 0.46, dz + back * 0.2 - 0.02), (xc + dx + 0.22, 1.0, dz + back * 0.2 + 0.02))
                for lx in (-0.18, 0.18):
                    for lz in (-0.18, 0.18):
                        wood.box((xc + dx + lx - 0.02, 0.0, dz + lz - 0.02), (xc + dx + lx + 0.02, 0.42, dz + lz + 0.02))
    return [floor, plaster, stone, wood, cloth]


def hall_materials(matte):
    """The materials of hall_meshes(), in its order; matte: the floor and furniture Lambertian, not glossy."""
    def glossy(roughness):
        return {"lambert": True} if matte else {"roughness": roughness}
    return [material("stone", (0.62, 0.58, 0.52), lambert=True), material("floor", (0.55, 0.5, 0.45), **glossy(0.6)),
            material("wood", (0.45, 0.28, 0.15), **glossy(0.5)), material("red_cloth", (0.6, 0.12, 0.1), lambert=True),
            material("plaster", (0.85, 0.83, 0.78), lambert=True)]


def interior():
    """The hall lit by a sun through its roof openings, with a glossy floor and furniture."""
    mats = hall_materials(matte=False)
    sun_dir = norm((-0.2, -1.0, -0.35))
    # A directional light's node points its -Z along the direction of travel.
    f = sun_dir
    r = norm(cross(f, (0.0, 0.0, 1.0)))
    u = cross(r, f)
    sun_node = {"name": "sun", "matrix": [r[0], r[1], r[2], 0, u[0], u[1], u[2], 0, -f[0], -f[1], -f[2], 0, 0, 20, 0, 1]}
    sun = ({"type": "directional", "name": "sun", "color": [1.0, 0.95, 0.85], "intensity": 12.0}, sun_node)
    return build_gltf(hall_meshes(), mats, HALL_CAMERA, lights=[sun])


def skylit_hall():
    """The interior's hall in materials and light that Cycles maps exactly (tools/cycles/README.md): every
    surface Lambertian (the interior's glossy floor and furniture turn matte), and instead of the sun an
    emitting panel 1 m above the roof that shines down (one-sided, black base colour), into the hall only
    through the skylights. Most of the hall sees light that has bounced off the floor below them: the
    large-scene row of the comparison with Cycles (bench/vs_cycles.sh)."""
    panel_material = material("sky_panel", (0.0, 0.0, 0.0), emissive=(1.0, 0.97, 0.92), strength=SKY_PANEL_STRENGTH,
                              lambert=True, double_sided=False)
    mats = hall_materials(matte=True) + [panel_material]
    X, _, H = HALL_SIZE
    panel = Mesh("sky_panel", 5)
    y = H + 1.0
    panel.quad((-X + 1.0, y, -2.0), (X - 1.0, y, -2.0), (X - 1.0, y, 2.0), (-X + 1.0, y, 2.0))  # its normal points down
    return build_gltf(hall_meshes() + [panel], mats, HALL_CAMERA)


LAMP_ROOMS = 6


def lamp_rooms():
    """Six rooms in a row along +X, each 4 x 4 m and 2.8 m high, joined by doorways that alternate
    between the two sides (z = -1 and z = +1), so no line of sight runs through more than two of them.
    Each room is lit by its own globe lamp (an icosphere of 320 triangles, 0.15 m in radius, hanging
    at 2.2 m): 1920 emitting triangles, of which a point sees at most its own room's and, through a
    doorway, a neighbour's. Sampling the lamps by power sends five of six shadow rays into walls; this
    is the scene where learned light samples must group triangles (render/guide/emitter_guide.h).
    The camera stands in the first room and looks through its doorway into the second. Materials map
    exactly to Cycles: Lambertian, the lamps one-sided with a black base colour."""
    mats = [material("white", (0.8, 0.8, 0.78), lambert=True), material("floor", (0.6, 0.45, 0.3), lambert=True),
            material("blue", (0.2, 0.3, 0.7), lambert=True), material("terracotta", (0.7, 0.3, 0.2), lambert=True),
            material("lamp", (0.0, 0.0, 0.0), emissive=(1.0, 0.9, 0.75), strength=20.0, lambert=True,
                     double_sided=False)]
    W, D, H, door_w, door_h = 4.0, 2.0, 2.8, 0.45, 2.1
    X = W * LAMP_ROOMS
    walls, floor, ends, furniture, lamps = Mesh("walls", 0), Mesh("floor", 1), Mesh("end_walls", 2), Mesh("furniture", 3), Mesh("lamps", 4)
    floor.quad((0, 0, D), (X, 0, D), (X, 0, -D), (0, 0, -D))
    walls.quad((0, H, -D), (X, H, -D), (X, H, D), (0, H, D))      # ceiling
    walls.quad((0, 0, -D), (X, 0, -D), (X, H, -D), (0, H, -D))    # side z = -D
    walls.quad((X, 0, D), (0, 0, D), (0, H, D), (X, H, D))        # side z = +D
    ends.quad((0, 0, D), (0, 0, -D), (0, H, -D), (0, H, D))       # the first room's end
    ends.quad((X, 0, -D), (X, 0, D), (X, H, D), (X, H, -D))       # the last room's end
    for k in range(1, LAMP_ROOMS):
        x, zc = W * k, (-1.0 if k % 2 else 1.0)                    # a two-sided wall with its doorway at zc
        walls.quad((x, 0, -D), (x, 0, zc - door_w), (x, H, zc - door_w), (x, H, -D))
        walls.quad((x, 0, zc + door_w), (x, 0, D), (x, H, D), (x, H, zc + door_w))
        walls.quad((x, door_h, zc - door_w), (x, door_h, zc + door_w), (x, H, zc + door_w), (x, H, zc - door_w))
    for k in range(LAMP_ROOMS):
        x0 = W * k
        lamps.sphere((x0 + W / 2, 2.2, 0.3 if k % 2 else -0.3), 0.15, 2)
        furniture.box((x0 + 0.4, 0.0, 0.9 if k % 2 else -1.8), (x0 + 1.6, 0.8, 1.8 if k % 2 else -0.9), rotate=8.0 * (k % 3))
        furniture.box((x0 + 2.6, 0.0, -1.8 if k % 2 else 1.2), (x0 + 3.3, 1.4, -1.2 if k % 2 else 1.8), rotate=-12.0)
    return build_gltf([floor, walls, ends, furniture, lamps], mats,
                      ((0.5, 1.5, 1.5), (4.0, 1.1, -0.9), math.radians(65.0)))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, help="output folder (default: this folder, small scenes only)")
    ap.add_argument("--interior-only", action="store_true")
    args = ap.parse_args()
    out = args.out or here
    os.makedirs(out, exist_ok=True)
    if not args.interior_only:
        write_gltf(out, "cornell_box", cornell(glossy=False))
        write_gltf(out, "cornell_glossy", cornell(glossy=True))
        write_gltf(out, "two_rooms", two_rooms())
        write_gltf(out, "door_ajar", door_ajar())
    if args.interior_only or args.out:
        write_glb(os.path.join(out, "interior.glb"), interior())
        write_glb(os.path.join(out, "skylit_hall.glb"), skylit_hall())
        write_glb(os.path.join(out, "lamp_rooms.glb"), lamp_rooms())


if __name__ == "__main__":
    main()
