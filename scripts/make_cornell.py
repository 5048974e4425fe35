#!/usr/bin/env python3
"""Generates data/cornell: a 2x2x2 m Cornell-like box (red left wall, green right wall, white
elsewhere, a 0.5x0.5 m emissive ceiling light), finely tessellated walls, a block named "Block",
a camera looking into the open front, and animation.json moving the block across the floor.

With --ceiling-panel it writes tests/scenes/ceiling_panel instead: the same box with coarser walls
(32 cells), lit by a 0.6x0.6 m slab 2 mm thick hanging 4 mm under the ceiling and emitting from its
underside, and no animation. It is the scene where estimators leak light through a thin occluder
(the ceiling above the slab sees only what comes through the gap), checked against the reference
in tests/reference/.

Standard library only. Run from anywhere: python3 scripts/make_cornell.py [--ceiling-panel] [OUT_DIR]
"""
import json
import math
import os
import struct
import sys

WALL_CELLS = 64      # per wall side: 5 walls x 65^2 vertices = 21125 vertices
BLOCK_CELLS = 8
FRAMES = 60

RED = [0.63, 0.065, 0.05]
GREEN = [0.14, 0.45, 0.091]
WHITE = [0.725, 0.71, 0.68]
LIGHT_RADIANCE = 12.0  # W m^-2 sr^-1 (emissive strength on a white emissiveFactor)


def grid(corner, u, v, cells, cells_v=None):
    """A quad grid from corner spanning u and v (cells along u, cells_v along v, default the
    same); front side (CCW) faces cross(u, v)."""
    cells_v = cells if cells_v is None else cells_v
    n = cross(u, v)
    length = math.sqrt(sum(c * c for c in n))
    n = [c / length for c in n]
    positions, normals, indices = [], [], []
    for j in range(cells_v + 1):
        for i in range(cells + 1):
            s, t = i / cells, j / cells_v
            positions.append([corner[k] + s * u[k] + t * v[k] for k in range(3)])
            normals.append(n)
    row = cells + 1
    for j in range(cells_v):
        for i in range(cells):
            a = j * row + i
            indices += [a, a + 1, a + row + 1, a, a + row + 1, a + row]
    return positions, normals, indices


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def box_walls(white, red, green):
    """Inward-facing walls of the box x in [-1,1], y in [0,2], z in [-1,1]; the front (z=+1) is
    open: (name, corner, u, v, material) for grid()."""
    return [
        ("Floor", [-1, 0, 1], [2, 0, 0], [0, 0, -2], white),
        ("Ceiling", [-1, 2, -1], [2, 0, 0], [0, 0, 2], white),
        ("BackWall", [-1, 0, -1], [2, 0, 0], [0, 2, 0], white),
        ("LeftWall", [-1, 0, 1], [0, 0, -2], [0, 2, 0], red),
        ("RightWall", [1, 0, -1], [0, 0, 2], [0, 2, 0], green),
    ]


def box_faces(half, cells):
    """Outward-facing faces of an axis-aligned box centred at the origin, base at y=0."""
    hx, hy, hz = half
    faces = [
        ([-hx, 0, hz], [2 * hx, 0, 0], [0, 2 * hy, 0]),    # +z
        ([hx, 0, -hz], [-2 * hx, 0, 0], [0, 2 * hy, 0]),   # -z
        ([hx, 0, hz], [0, 0, -2 * hz], [0, 2 * hy, 0]),    # +x
        ([-hx, 0, -hz], [0, 0, 2 * hz], [0, 2 * hy, 0]),   # -x
        ([-hx, 2 * hy, hz], [2 * hx, 0, 0], [0, 0, -2 * hz]),  # +y (top)
        ([-hx, 0, -hz], [2 * hx, 0, 0], [0, 0, 2 * hz]),   # -y (bottom)
    ]
    positions, normals, indices = [], [], []
    for corner, u, v in faces:
        p, n, i = grid(corner, u, v, cells)
        base = len(positions)
        positions += p
        normals += n
        indices += [base + k for k in i]
    return positions, normals, indices


class GltfBuilder:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "qsgi scripts/make_cornell.py"},
            "extensionsUsed": ["KHR_materials_emissive_strength"],
            "scene": 0, "scenes": [{"name": "Cornell", "nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "buffers": [], "cameras": [],
        }

    def material(self, name, albedo, emission=None, strength=None):
        m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": albedo + [1.0],
                                                    "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        if emission:
            m["emissiveFactor"] = emission
            m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        offset = len(self.bin)
        self.bin += data
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(data), "target": target})
        return len(self.doc["bufferViews"]) - 1

    def _accessor(self, view, component, count, kind, lo=None, hi=None):
        a = {"bufferView": view, "componentType": component, "count": count, "type": kind}
        if lo is not None:
            a["min"], a["max"] = lo, hi
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def add_accessor(self, data, component, count, kind, lo=None, hi=None, target=None):
        """An accessor over raw little-endian bytes (its own buffer view); returns its index."""
        view = self._view(data, target) if target else self._view_untargeted(data)
        return self._accessor(view, component, count, kind, lo, hi)

    def _view_untargeted(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        offset = len(self.bin)
        self.bin += data
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": offset, "byteLength": len(data)})
        return len(self.doc["bufferViews"]) - 1

    def mesh(self, name, positions, normals, indices, material):
        pv = self._view(b"".join(struct.pack("<3f", *p) for p in positions), 34962)
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        pa = self._accessor(pv, 5126, len(positions), "VEC3", lo, hi)
        nv = self._view(b"".join(struct.pack("<3f", *n) for n in normals), 34962)
        na = self._accessor(nv, 5126, len(normals), "VEC3")
        iv = self._view(struct.pack("<%dI" % len(indices), *indices), 34963)
        ia = self._accessor(iv, 5125, len(indices), "SCALAR")
        self.doc["meshes"].append({"name": name, "primitives": [
            {"attributes": {"POSITION": pa, "NORMAL": na}, "indices": ia, "material": material}]})
        return len(self.doc["meshes"]) - 1

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)

    def write(self, folder, stem):
        self.doc["buffers"] = [{"uri": stem + ".bin", "byteLength": len(self.bin)}]
        with open(os.path.join(folder, stem + ".bin"), "wb") as f:
            f.write(self.bin)
        with open(os.path.join(folder, stem + ".gltf"), "w") as f:
            json.dump(self.doc, f, indent=1)
            f.write("\n")


def main():
    args = [a for a in sys.argv[1:] if a != "--ceiling-panel"]
    panel = len(args) != len(sys.argv) - 1
    here = os.path.dirname(__file__)
    default = os.path.join(here, "..", "tests", "scenes", "ceiling_panel") if panel else os.path.join(here, "..", "data", "cornell")
    folder = args[0] if args else default
    os.makedirs(folder, exist_ok=True)
    if panel:
        build(folder, "ceiling_panel", wall_cells=32, light="slab", animate=False)
    else:
        build(folder, "cornell", wall_cells=WALL_CELLS, light="panel", animate=True)


def build(folder, stem, wall_cells, light, animate, add_nodes=None):
    """The box; add_nodes(builder, white), if given, adds nodes of its own before the camera
    (scripts/make_bench_scenes.py adds its movers so)."""
    g = GltfBuilder()
    white = g.material("White", WHITE)
    red = g.material("Red", RED)
    green = g.material("Green", GREEN)
    light_material = g.material("Light", [0.78, 0.78, 0.78], [1.0, 1.0, 1.0], LIGHT_RADIANCE)
    block = g.material("Block", WHITE)

    for name, corner, u, v, mat in box_walls(white, red, green):
        p, n, i = grid(corner, u, v, wall_cells)
        g.node({"name": name, "mesh": g.mesh(name, p, n, i, mat)})
    if light == "panel":
        # The light hangs 1 mm below the ceiling, emitting downwards.
        p, n, i = grid([-0.25, 1.999, -0.25], [0.5, 0, 0], [0, 0, 0.5], 4)
        g.node({"name": "Light", "mesh": g.mesh("Light", p, n, i, light_material)})
    else:
        # A slab 2 mm thick, its top 4 mm under the ceiling: emissive underside, white elsewhere.
        h = 0.3
        p, n, i = grid([-h, 1.994, -h], [2 * h, 0, 0], [0, 0, 2 * h], 6)
        g.node({"name": "Light", "mesh": g.mesh("Light", p, n, i, light_material)})
        top, sides = [], [([-h, 1.996, h], [2 * h, 0, 0], [0, 0, -2 * h])]
        sides += [([-h, 1.994, h], [2 * h, 0, 0], [0, 0.002, 0]), ([h, 1.994, -h], [-2 * h, 0, 0], [0, 0.002, 0]),
                  ([h, 1.994, h], [0, 0, -2 * h], [0, 0.002, 0]), ([-h, 1.994, -h], [0, 0, 2 * h], [0, 0.002, 0])]
        positions, normals, indices = [], [], []
        for corner, u, v in sides:
            p, n, i = grid(corner, u, v, 6)
            base = len(positions)
            positions += p
            normals += n
            indices += [base + k for k in i]
        g.node({"name": "LightHousing", "mesh": g.mesh("LightHousing", positions, normals, indices, white)})
    p, n, i = box_faces([0.25, 0.3, 0.25], BLOCK_CELLS)
    g.node({"name": "Block", "mesh": g.mesh("Block", p, n, i, block), "translation": [-0.5, 0, 0.1]})
    if add_nodes:
        add_nodes(g, white)
    g.doc["cameras"].append({"name": "Front", "type": "perspective",
                             "perspective": {"yfov": 0.7, "aspectRatio": 4 / 3, "znear": 0.05}})
    g.node({"name": "Camera", "camera": 0, "translation": [0, 1, 4.0]})
    g.write(folder, stem)
    if not animate:
        return

    # The block slides from x=-0.5 to x=+0.5 while turning a quarter turn.
    frames = []
    for f in range(FRAMES):
        s = f / (FRAMES - 1)
        angle = 0.5 * math.pi * s
        frames.append({"frame": f, "nodes": {"Block": {
            "translation": [round(-0.5 + s, 6), 0, 0.1],
            "rotation": [0, round(math.sin(angle / 2), 9), 0, round(math.cos(angle / 2), 9)]}}})
    with open(os.path.join(folder, "animation.json"), "w") as f:
        json.dump({"format": "qsgi-animation", "version": 1, "fps": 24, "frames": frames}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
