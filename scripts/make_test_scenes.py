#!/usr/bin/env python3
"""Generates the analytic test scenes in tests/scenes/ (standard library only):

- sphere_point_light.gltf: a closed sphere of radius 1 m (icosphere, inward normals, albedo 0.5)
  with a 1 W/sr KHR_lights_punctual point light at its centre: E = 2 W/m^2 everywhere.
- plane_point_light.gltf: a 3.2 m square plane (albedo 0.5) under a 1 W/sr point light 1 m
  above its centre: E = I h / d^3.
- corner_point_light.gltf: an inside corner (albedo 0.6): a 2 m square floor at y = 0 over x, z in
  [0, 2] and two 2 m high walls on the planes x = 0 and z = 0, all facing into the corner, each a
  24 x 24 grid of its own vertices and normals; a 1 W/sr point light at (0.7, 1.2, 0.7). Direct
  E = I cos / d^2 (1/1.2^2 W/m^2 below the light); interreflection adds to it (Mitsuba reference).
- open_box_sky.gltf: no light of its own (lit with --sky 1,1,1; Mitsuba reference): an open box
  (albedo 0.6), a 2 m square floor at y = 0 and four 1 m walls, floor and walls 5 cm thick (inner
  and outer faces, rims, a bottom facing down at y = -0.05: closed but for its top, no two faces in
  one plane), with a 0.4 m block on the floor off centre.
Each has a camera. Run: python3 scripts/make_test_scenes.py [OUT_DIR]
"""
import base64
import json
import math
import os
import struct
import sys


def icosphere(subdivisions):
    t = (1 + math.sqrt(5)) / 2
    p = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    p = [normalize(v) for v in p]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
         (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5),
         (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                p.append(normalize([(p[a][k] + p[b][k]) / 2 for k in range(3)]))
                cache[key] = len(p) - 1
            return cache[key]
        nf = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return p, f


def normalize(v):
    n = math.sqrt(sum(c * c for c in v))
    return [c / n for c in v]


def gltf(positions, normals, faces, albedo, light_pos, camera_node, name):
    """light_pos None: a scene without lights."""
    pos = b"".join(struct.pack("<3f", *v) for v in positions)
    nrm = b"".join(struct.pack("<3f", *v) for v in normals)
    idx = b"".join(struct.pack("<3I", *f) for f in faces)
    data = pos + nrm + idx
    lo = [min(v[k] for v in positions) for k in range(3)]
    hi = [max(v[k] for v in positions) for k in range(3)]
    lit = {
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "color": [1, 1, 1], "intensity": 1.0}]}},
    } if light_pos is not None else {}
    nodes = [{"name": name, "mesh": 0}]
    if light_pos is not None:
        nodes.append({"name": "Light", "translation": light_pos, "extensions": {"KHR_lights_punctual": {"light": 0}}})
    nodes.append(dict(camera_node, camera=0, name="Camera"))
    return {
        "asset": {"version": "2.0", "generator": "qsgi scripts/make_test_scenes.py"},
        **lit,
        "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 4 / 3, "znear": 0.01}}],
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": albedo + [1], "metallicFactor": 0}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "buffers": [{"byteLength": len(data),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(nrm)},
                        {"buffer": 0, "byteOffset": len(pos) + len(nrm), "byteLength": len(idx)}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3", "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5126, "count": len(normals), "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5125, "count": 3 * len(faces), "type": "SCALAR"}],
    }


def grid(origin, u, v, cells, pos, nrm, faces, cells_v=None):
    """Appends a cells x cells_v (default cells) grid of quads (two triangles each) spanning
    origin + [0,1] u + [0,1] v, with vertices of its own and normal u x v (counter-clockwise seen
    from that side)."""
    cells_v = cells if cells_v is None else cells_v
    n = normalize([u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]])
    base, row = len(pos), cells + 1
    for j in range(cells_v + 1):
        for i in range(row):
            pos.append([origin[k] + u[k] * i / cells + v[k] * j / cells_v for k in range(3)])
            nrm.append(n)
    for j in range(cells_v):
        for i in range(cells):
            a = base + j * row + i
            faces += [(a, a + 1, a + row + 1), (a, a + row + 1, a + row)]


def look_at(eye, target):
    """A camera node at eye looking at target (yaw about y, then pitch about the camera's x)."""
    d = [target[k] - eye[k] for k in range(3)]
    yaw = math.atan2(-d[0], -d[2])
    pitch = math.atan2(d[1], math.hypot(d[0], d[2]))
    sy, cy, sp, cp = math.sin(yaw / 2), math.cos(yaw / 2), math.sin(pitch / 2), math.cos(pitch / 2)
    return {"translation": eye, "rotation": [cy * sp, sy * cp, -sy * sp, cy * cp]}


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "scenes")
    os.makedirs(folder, exist_ok=True)
    p, f = icosphere(5)
    inward = [(a, c, b) for a, b, c in f]  # reversed winding: the front side faces the centre
    sphere = gltf(p, [[-c for c in v] for v in p], inward, [0.5, 0.5, 0.5], [0, 0, 0],
                  {"translation": [0, 0, 0.3]}, "Sphere")
    cells, half = 96, 1.6
    pos, faces = [], []
    for j in range(cells + 1):
        for i in range(cells + 1):
            pos.append([-half + 2 * half * i / cells, 0, half - 2 * half * j / cells])
    row = cells + 1
    for j in range(cells):
        for i in range(cells):
            a = j * row + i
            faces += [(a, a + 1, a + row + 1), (a, a + row + 1, a + row)]
    # Camera 3 m out and 2 m up, pitched down to look at the plane's centre.
    pitch = -math.atan2(2.0, 3.0)
    plane = gltf(pos, [[0, 1, 0]] * len(pos), faces, [0.5, 0.5, 0.5], [0, 1, 0],
                 {"translation": [0, 2, 3], "rotation": [math.sin(pitch / 2), 0, 0, math.cos(pitch / 2)]}, "Plane")
    pos, nrm, faces = [], [], []
    grid([0, 0, 0], [0, 0, 2], [2, 0, 0], 24, pos, nrm, faces)  # floor, +y
    grid([0, 0, 0], [0, 2, 0], [0, 0, 2], 24, pos, nrm, faces)  # wall x = 0, +x
    grid([0, 0, 0], [2, 0, 0], [0, 2, 0], 24, pos, nrm, faces)  # wall z = 0, +z
    corner = gltf(pos, nrm, faces, [0.6, 0.6, 0.6], [0.7, 1.2, 0.7],
                  look_at([3.2, 2.4, 3.2], [0.6, 0.6, 0.6]), "Corner")
    pos, nrm, faces = [], [], []
    t = 1.05  # the walls' outer faces
    grid([-1, 0, -1], [0, 0, 2], [2, 0, 0], 24, pos, nrm, faces)                 # floor, +y
    grid([-1, 0, -1], [0, 1, 0], [0, 0, 2], 12, pos, nrm, faces, 24)             # inner wall x = -1, +x
    grid([1, 0, -1], [0, 0, 2], [0, 1, 0], 24, pos, nrm, faces, 12)              # inner wall x = 1, -x
    grid([-1, 0, -1], [2, 0, 0], [0, 1, 0], 24, pos, nrm, faces, 12)             # inner wall z = -1, +z
    grid([-1, 0, 1], [0, 1, 0], [2, 0, 0], 12, pos, nrm, faces, 24)              # inner wall z = 1, -z
    d = t - 1  # the floor's thickness too: the bottom lies at y = -d, never on the floor's plane
    h = 1 + d  # the outer walls' height
    grid([t, -d, -t], [0, h, 0], [0, 0, 2 * t], 12, pos, nrm, faces, 24)         # outer wall x = t, +x
    grid([-t, -d, -t], [0, 0, 2 * t], [0, h, 0], 24, pos, nrm, faces, 12)        # outer wall x = -t, -x
    grid([-t, -d, t], [2 * t, 0, 0], [0, h, 0], 24, pos, nrm, faces, 12)         # outer wall z = t, +z
    grid([-t, -d, -t], [0, h, 0], [2 * t, 0, 0], 12, pos, nrm, faces, 24)        # outer wall z = -t, -z
    grid([1, 1, -t], [0, 0, 2 * t], [t - 1, 0, 0], 24, pos, nrm, faces, 1)       # rims, +y
    grid([-t, 1, -t], [0, 0, 2 * t], [t - 1, 0, 0], 24, pos, nrm, faces, 1)
    grid([-1, 1, 1], [0, 0, t - 1], [2, 0, 0], 1, pos, nrm, faces, 24)
    grid([-1, 1, -t], [0, 0, t - 1], [2, 0, 0], 1, pos, nrm, faces, 24)
    grid([-t, -d, -t], [2 * t, 0, 0], [0, 0, 2 * t], 24, pos, nrm, faces)        # bottom, -y
    x0, z0, b = 0.3, -0.2, 0.4                                                   # the block
    grid([x0, b, z0], [0, 0, b], [b, 0, 0], 6, pos, nrm, faces)                  # top, +y
    grid([x0, 0, z0], [0, 0, b], [0, b, 0], 6, pos, nrm, faces)                  # -x
    grid([x0 + b, 0, z0], [0, b, 0], [0, 0, b], 6, pos, nrm, faces)              # +x
    grid([x0, 0, z0], [0, b, 0], [b, 0, 0], 6, pos, nrm, faces)                  # -z
    grid([x0, 0, z0 + b], [b, 0, 0], [0, b, 0], 6, pos, nrm, faces)              # +z
    open_box = gltf(pos, nrm, faces, [0.6, 0.6, 0.6], None, look_at([2.4, 2.6, 2.8], [0, 0.3, 0]), "OpenBox")
    for name, doc in (("sphere_point_light", sphere), ("plane_point_light", plane), ("corner_point_light", corner),
                      ("open_box_sky", open_box)):
        with open(os.path.join(folder, name + ".gltf"), "w") as out:
            json.dump(doc, out)
            out.write("\n")


if __name__ == "__main__":
    main()
