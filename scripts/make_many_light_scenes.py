#!/usr/bin/env python3
"""Writes glTF 2.0 scenes lit by many lights, the groundwork for a light tree (many lights at the
cost of a few): a corridor under 120 small emissive lamps, and a box lit by 10 to 10,000 point
lights of the same total intensity (standard library only).

Every scene is metres, Y up, made of subdivided quads of CELL = 0.2 m (so that the vertices sample
the lighting; the corridor's 7,378 vertices, the boxes' 2,351), single-sided surfaces facing into
the room, all materials metallicFactor 0 and roughnessFactor 1, each with a camera. Node order: the
room's surfaces first (floor, ceiling, back z-, front z+, left x-, right x+), then the objects, then
the lights, so the scenes of one family share their vertex indices.

  corridor        a closed corridor 24 m long (z in [-12, 12]), 2.4 m wide (x in [-1.2, 1.2]) and
                  2.6 m high, walls and ceiling grey 0.6, floor grey 0.4 (120 x 12 cells on the floor
                  and ceiling, 120 x 13 on the long walls, 12 x 13 on the end walls). It is lit ONLY
                  by 120 small emissive ceiling lamps: 0.2 x 0.2 m quads of 2 triangles each (one mesh,
                  "Lamps", 240 emissive triangles), 1 cm under the ceiling (y = 2.59), facing down,
                  in two rows at x = -0.6 and x = +0.6, 60 to a row, 0.4 m apart (centres z = -11.8,
                  -11.4, ..., 11.8); emissiveFactor 1 x KHR_materials_emissive_strength 200
                  (L_e = 200 W m^-2 sr^-1: each lamp pi x 200 x 0.04 = 25.1 W, 3016 W in all; the
                  lamps' albedo 0.8). Floor irradiance: about 20 W/m^2 direct (40 % of the lamps'
                  power lands on the floor; an estimate), 32 W/m^2 on average with the
                  interreflections (18 in the end corners to 36; a qsgi reference). A camera at the
                  z+ end looks down the corridor.
  box_lights_N    for N in 10, 100, 1000, 10000: a closed 4 x 3 x 4 m box (x, z in [-2, 2], y in
                  [0, 3]; 20 x 20 cells on floor and ceiling, 20 x 15 on each wall), albedo 0.6, with
                  a 0.8 m cube standing on the floor at (0.5, 0, -0.4) (five faces, no bottom, 4 x 4
                  cells each; albedo 0.5), lit by N KHR_lights_punctual point lights (each its own
                  light, white, one node each, children of the node "Lamps") on the plane y = 2.7
                  (0.3 m under the ceiling): a jittered grid of nx x nz cells over x, z in
                  [-1.8, 1.8] (nx x nz = N: 5 x 2, 10 x 10, 40 x 25, 100 x 100), one light uniformly
                  at random in each cell (random.Random(N): the same positions every run). Each has
                  intensity I_TOTAL / N, I_TOTAL = 100 W/sr (4 pi x 100 = 1257 W in all, for every N).
                  Floor irradiance: about 9 W/m^2 direct (an estimate), 28 W/m^2 on average with
                  the interreflections (a qsgi reference of box_lights_1000). The lights differ
                  between the N, so their solutions differ (most on the ceiling, above the lights);
                  compare a box only with itself.

Run: python3 scripts/make_many_light_scenes.py OUT_DIR [NAME ...] [--list]
Writes OUT_DIR/NAME.gltf and NAME.bin for each scene (all of them without NAMEs).
Deterministic: the same arguments give the same bytes.
"""
import argparse
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_cornell import grid  # noqa: E402
from make_material_scenes import SceneBuilder as MaterialSceneBuilder  # noqa: E402
from make_walker import merged  # noqa: E402

CELL = 0.2  # metres: the quads of every surface but the lamps

# corridor
CORRIDOR = (2.4, 2.6, 24.0)          # width (x), height (y), length (z)
CORRIDOR_GREY, CORRIDOR_FLOOR = 0.6, 0.4
LAMP_SIZE, LAMP_DROP = 0.2, 0.01     # a lamp's side; how far under the ceiling it hangs
LAMP_ROWS_X = (-0.6, 0.6)
LAMPS_PER_ROW = 60                   # 120 lamps
LAMP_RADIANCE = 200.0                # W m^-2 sr^-1
LAMP_ALBEDO = 0.8

# box_lights_N
BOX = (4.0, 3.0, 4.0)                # x, y, z
BOX_GREY, CUBE_GREY = 0.6, 0.5
CUBE_SIZE, CUBE_CENTRE = 0.8, (0.5, -0.4)
LIGHT_HEIGHT = 2.7                   # 0.3 m under the ceiling
LIGHT_HALF_EXTENT = 1.8              # the lights' plane: x, z in [-1.8, 1.8]
I_TOTAL = 100.0                      # W/sr over all N lights
LIGHT_GRIDS = {10: (5, 2), 100: (10, 10), 1000: (40, 25), 10000: (100, 100)}

SCENES = ["corridor"] + ["box_lights_%d" % n for n in sorted(LIGHT_GRIDS)]


# ---------------------------------------------------------------------------------------------
# A builder: make_material_scenes' (buffer, materials, camera, writing), with point lights, and
# meshes without texture coordinates

class SceneBuilder(MaterialSceneBuilder):
    def __init__(self, folder, name):
        super().__init__(folder, name)
        self.doc["asset"]["generator"] = "qsgi scripts/make_many_light_scenes.py"
        self.lights = 0   # point lights
        self.lamps = 0    # emissive quads

    def material(self, name, grey, strength=None):
        emission = [1.0, 1.0, 1.0] if strength is not None else None
        return super().material(name, [grey] * 3, emission=emission, strength=strength)

    def mesh(self, name, parts, material):
        """A node with one primitive from `parts`: [(positions, normals, indices)] concatenated."""
        positions, normals, indices = merged(parts)
        mesh = self.g.mesh(name, positions, normals, indices, material)
        self.g.node({"name": name, "mesh": mesh})
        return len(positions)

    def point_lights(self, group, positions, intensity):
        """One KHR_lights_punctual point light per position, each its own light and node, the nodes
        children of one node named `group`."""
        self.use("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        children = []
        for k, p in enumerate(positions):
            lights.append({"name": "%s_%d" % (group, k), "type": "point", "color": [1.0, 1.0, 1.0],
                           "intensity": intensity})
            self.doc["nodes"].append({"name": "%s_%d" % (group, k), "translation": list(p),
                                      "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}})
            children.append(len(self.doc["nodes"]) - 1)
        self.g.node({"name": group, "children": children})
        self.lights += len(positions)

    def vertices(self):
        return sum(self.doc["accessors"][p["attributes"]["POSITION"]]["count"]
                   for m in self.doc["meshes"] for p in m["primitives"])


def cells_for(length):
    return max(1, int(round(length / CELL)))


def room(b, size, materials):
    """The six inward-facing surfaces of the room x in [-W/2, W/2], y in [0, H], z in [-D/2, D/2]
    (materials: dict surface -> material: floor, ceiling, back, front, left, right)."""
    w, h, d = size
    x0, x1, z0, z1 = -w / 2, w / 2, -d / 2, d / 2
    cw, ch, cd = cells_for(w), cells_for(h), cells_for(d)
    b.mesh("Floor", [grid([x0, 0, z1], [w, 0, 0], [0, 0, -d], cw, cd)], materials["floor"])
    b.mesh("Ceiling", [grid([x0, h, z0], [w, 0, 0], [0, 0, d], cw, cd)], materials["ceiling"])
    b.mesh("BackWall", [grid([x0, 0, z0], [w, 0, 0], [0, h, 0], cw, ch)], materials["back"])
    b.mesh("FrontWall", [grid([x1, 0, z1], [-w, 0, 0], [0, h, 0], cw, ch)], materials["front"])
    b.mesh("LeftWall", [grid([x0, 0, z1], [0, 0, -d], [0, h, 0], cd, ch)], materials["left"])
    b.mesh("RightWall", [grid([x1, 0, z0], [0, 0, d], [0, h, 0], cd, ch)], materials["right"])


def cube(b, name, material, centre, size):
    """An outward-facing cube standing on the floor: five faces (no bottom), about CELL per cell."""
    cx, cz = centre
    s = size
    x0, x1, z0, z1 = cx - s / 2, cx + s / 2, cz - s / 2, cz + s / 2
    c = cells_for(s)
    faces = [([x0, 0, z1], [s, 0, 0], [0, s, 0]),     # +z
             ([x1, 0, z0], [-s, 0, 0], [0, s, 0]),    # -z
             ([x1, 0, z1], [0, 0, -s], [0, s, 0]),    # +x
             ([x0, 0, z0], [0, 0, s], [0, s, 0]),     # -x
             ([x0, s, z1], [s, 0, 0], [0, 0, -s])]    # top, +y
    b.mesh(name, [grid(corner, u, v, c) for corner, u, v in faces], material)


# ---------------------------------------------------------------------------------------------
# The scenes

def corridor(b):
    w, h, d = CORRIDOR
    grey = b.material("Grey", CORRIDOR_GREY)
    floor = b.material("Floor", CORRIDOR_FLOOR)
    room(b, (w, h, d), {"floor": floor, "ceiling": grey, "back": grey, "front": grey, "left": grey,
                        "right": grey})
    lamp = b.material("Lamp", LAMP_ALBEDO, strength=LAMP_RADIANCE)
    spacing = d / LAMPS_PER_ROW
    y, s = h - LAMP_DROP, LAMP_SIZE
    parts = []
    for x in LAMP_ROWS_X:
        for i in range(LAMPS_PER_ROW):
            z = -d / 2 + spacing * (i + 0.5)
            parts.append(grid([x - s / 2, y, z - s / 2], [s, 0, 0], [0, 0, s], 1))  # faces down
    b.mesh("Lamps", parts, lamp)
    b.lamps += len(parts)
    b.camera([0.0, 1.6, d / 2 - 0.6], [0.0, 1.1, -d / 2])


def light_positions(n):
    """N positions on the plane y = LIGHT_HEIGHT: one uniformly at random in each cell of an nx x nz
    grid over x, z in [-LIGHT_HALF_EXTENT, LIGHT_HALF_EXTENT], in row order (z outer, x inner)."""
    nx, nz = LIGHT_GRIDS[n]
    rng = random.Random(n)
    e = LIGHT_HALF_EXTENT
    dx, dz = 2 * e / nx, 2 * e / nz
    out = []
    for j in range(nz):
        for i in range(nx):
            x = -e + dx * (i + rng.random())
            z = -e + dz * (j + rng.random())
            out.append((round(x, 6), LIGHT_HEIGHT, round(z, 6)))
    return out


def box_lights(b, n):
    wall = b.material("Grey", BOX_GREY)
    room(b, BOX, {k: wall for k in ("floor", "ceiling", "back", "front", "left", "right")})
    cube(b, "Cube", b.material("CubeGrey", CUBE_GREY), CUBE_CENTRE, CUBE_SIZE)
    b.point_lights("Lamps", light_positions(n), I_TOTAL / n)
    b.camera([1.7, 2.3, 1.9], [-0.4, 0.7, -0.6])


BUILDERS = {"corridor": corridor}
for _n in LIGHT_GRIDS:
    BUILDERS["box_lights_%d" % _n] = (lambda n: lambda b: box_lights(b, n))(_n)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir", nargs="?")
    ap.add_argument("names", nargs="*", help="scenes to write (default: all; see --list)")
    ap.add_argument("--list", action="store_true", help="print the scene names and exit")
    args = ap.parse_args()
    if args.list:
        print("\n".join(SCENES))
        return
    if not args.out_dir:
        ap.error("OUT_DIR is required")
    names = args.names or SCENES
    for name in names:
        if name not in BUILDERS:
            ap.error("unknown scene %r (--list names them)" % name)
    os.makedirs(args.out_dir, exist_ok=True)
    for name in names:
        b = SceneBuilder(args.out_dir, name)
        BUILDERS[name](b)
        b.write()
        print("%s: %d vertices, %d point lights, %d emissive lamps"
              % (os.path.join(args.out_dir, name + ".gltf"), b.vertices(), b.lights, b.lamps))


if __name__ == "__main__":
    main()
