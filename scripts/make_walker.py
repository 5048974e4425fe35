#!/usr/bin/env python3
"""Generates data/walker: a skinned figure walking past static furniture in a room under a lamp,
animated in the glTF file itself (no transform file): what an artist's export looks like.

- Room: 8 x 6 x 3 m, white, open at the front (z = 3) where the camera stands; a table, a chair
  and a bench (wood).
- Lamp: a KHR_lights_punctual point light, 60 W/sr, 2.8 m above the floor's centre.
- Figure: one skinned mesh (torso, head, two legs; 4 joints: Walker > Hips > LeftLeg, RightLeg),
  its legs blended into the hips over their top 15 cm.
- Animation "Walk", 4 s: Walker slides along +x from -2.5 to 2.5 m (LINEAR); the legs swing
  +-25 degrees about z every half second, the left one LINEAR (spherical), the right one
  CUBICSPLINE with zero tangents (eased). Constant channels on the hips, as exporters write them.
- A perspective camera in front of the room.

Render it with configs/walker.json (`qsgi render --config configs/walker.json`).
Standard library only; deterministic bytes. Run from anywhere: python3 scripts/make_walker.py [OUT_DIR]
"""
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(__file__))
from make_cornell import GltfBuilder, box_faces, grid  # noqa: E402

WHITE = [0.75, 0.74, 0.72]
WOOD = [0.55, 0.36, 0.2]
CLOTH = [0.2, 0.3, 0.6]
DURATION = 4.0
STEP = 0.5  # seconds between leg keys
SWING = math.radians(25)
HIP_HEIGHT = 0.9
LEG_OFFSET = 0.12
BLEND = 0.15  # the top of a leg blends into the hips over this height


def merged(parts):
    """Concatenates (positions, normals, indices) parts into one."""
    positions, normals, indices = [], [], []
    for p, n, i in parts:
        base = len(positions)
        positions += p
        normals += n
        indices += [base + k for k in i]
    return positions, normals, indices


def box(centre_xz, base_y, half, cells):
    """box_faces moved to stand at (x, base_y, z)."""
    p, n, i = box_faces(half, cells)
    return [[q[0] + centre_xz[0], q[1] + base_y, q[2] + centre_xz[1]] for q in p], n, i


def quaternion_about_z(angle):
    return [0.0, 0.0, round(math.sin(angle / 2), 9), round(math.cos(angle / 2), 9)]


def figure():
    """The figure's mesh in its bind pose (Walker at the origin, facing +x), with JOINTS_0 and
    WEIGHTS_0: joint 0 Walker (unused), 1 Hips, 2 LeftLeg, 3 RightLeg."""
    parts, weights = [], []
    torso = box((0, 0), HIP_HEIGHT, [0.13, 0.33, 0.22], 3)
    head = box((0, 0), HIP_HEIGHT + 0.66, [0.1, 0.12, 0.1], 2)
    for part in (torso, head):
        parts.append(part)
        weights += [((1, 0), (1.0, 0.0))] * len(part[0])
    for joint, z in ((2, -LEG_OFFSET), (3, LEG_OFFSET)):
        leg = box((0, z), 0.0, [0.07, HIP_HEIGHT / 2, 0.07], 6)
        parts.append(leg)
        for q in leg[0]:
            # Below the blend zone the leg alone; above it a linear hand-over to the hips.
            s = min(1.0, max(0.0, (HIP_HEIGHT - q[1]) / BLEND))
            weights.append(((joint, 1), (round(s, 6), round(1 - s, 6))))
    positions, normals, indices = merged(parts)
    return positions, normals, indices, weights


def main():
    here = os.path.dirname(__file__)
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "data", "walker")
    os.makedirs(folder, exist_ok=True)
    g = GltfBuilder()
    g.doc["asset"]["generator"] = "qsgi scripts/make_walker.py"
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    g.doc["scenes"][0]["name"] = "Walker"
    white = g.material("White", WHITE)
    wood = g.material("Wood", WOOD)
    skin_material = g.material("Figure", CLOTH)

    # The room.
    p, n, i = grid([-4, 0, 3], [8, 0, 0], [0, 0, -6], 48)
    g.node({"name": "Floor", "mesh": g.mesh("Floor", p, n, i, white)})
    walls = [("BackWall", [-4, 0, -3], [8, 0, 0], [0, 3, 0], 32, 12),
             ("Ceiling", [-4, 3, -3], [8, 0, 0], [0, 0, 6], 32, 24),
             ("LeftWall", [-4, 0, 3], [0, 0, -6], [0, 3, 0], 24, 12),
             ("RightWall", [4, 0, -3], [0, 0, 6], [0, 3, 0], 24, 12)]
    for name, corner, u, v, cu, cv in walls:  # inward-facing; the front (z = 3) is open
        p, n, i = grid(corner, u, v, cu, cv)
        g.node({"name": name, "mesh": g.mesh(name, p, n, i, white)})
    # Furniture: table (top and four legs), chair (seat, back, legs), bench.
    table = [box((0.8, -1.6), 0.72, [0.6, 0.02, 0.35], 6)]
    table += [box((0.8 + dx, -1.6 + dz), 0.0, [0.03, 0.36, 0.03], 1) for dx in (-0.55, 0.55) for dz in (-0.3, 0.3)]
    g.node({"name": "Table", "mesh": g.mesh("Table", *merged(table), wood)})
    chair = [box((-1.3, -1.7), 0.45, [0.22, 0.02, 0.22], 4), box((-1.3, -1.9), 0.47, [0.22, 0.25, 0.02], 4)]
    chair += [box((-1.3 + dx, -1.7 + dz), 0.0, [0.02, 0.225, 0.02], 1) for dx in (-0.19, 0.19) for dz in (-0.19, 0.19)]
    g.node({"name": "Chair", "mesh": g.mesh("Chair", *merged(chair), wood)})
    g.node({"name": "Bench", "mesh": g.mesh("Bench", *box((-0.2, 1.4), 0.0, [0.9, 0.22, 0.2], 6), wood)})

    # The lamp and the camera.
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "Lamp", "type": "point", "intensity": 60.0}]}}
    g.node({"name": "Lamp", "translation": [0, 2.8, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g.doc["cameras"].append({"name": "Front", "type": "perspective",
                             "perspective": {"yfov": 0.75, "aspectRatio": 16 / 9, "znear": 0.05}})
    tilt = math.radians(-12)
    g.node({"name": "Camera", "camera": 0, "translation": [0, 1.9, 6.2],
            "rotation": [round(math.sin(tilt / 2), 9), 0, 0, round(math.cos(tilt / 2), 9)]})

    # The figure: joints first (Walker is a scene root; Hips and the legs hang below it).
    nodes = g.doc["nodes"]
    walker = len(nodes)
    nodes.append({"name": "Walker", "translation": [-2.5, 0, 0.2], "children": [walker + 1]})
    nodes.append({"name": "Hips", "translation": [0, HIP_HEIGHT, 0], "children": [walker + 2, walker + 3]})
    nodes.append({"name": "LeftLeg", "translation": [0, 0, -LEG_OFFSET]})
    nodes.append({"name": "RightLeg", "translation": [0, 0, LEG_OFFSET]})
    g.doc["scenes"][0]["nodes"].append(walker)
    positions, normals, indices, weights = figure()
    mesh = g.mesh("Figure", positions, normals, indices, skin_material)
    primitive = g.doc["meshes"][mesh]["primitives"][0]
    primitive["attributes"]["JOINTS_0"] = g.add_accessor(
        b"".join(struct.pack("<4B", j[0], j[1], 0, 0) for j, _ in weights), 5121, len(weights), "VEC4", target=34962)
    primitive["attributes"]["WEIGHTS_0"] = g.add_accessor(
        b"".join(struct.pack("<4f", w[0], w[1], 0, 0) for _, w in weights), 5126, len(weights), "VEC4", target=34962)
    # Inverse bind matrices: the joints' world transforms in the bind pose are translations.
    bind = [(0, 0, 0), (0, HIP_HEIGHT, 0), (0, HIP_HEIGHT, -LEG_OFFSET), (0, HIP_HEIGHT, LEG_OFFSET)]
    inverse = b"".join(struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -x, -y, -z, 1) for x, y, z in bind)
    g.doc["skins"] = [{"name": "Body", "joints": [walker, walker + 1, walker + 2, walker + 3],
                       "skeleton": walker, "inverseBindMatrices": g.add_accessor(inverse, 5126, 4, "MAT4")}]
    figure_node = len(nodes)
    nodes.append({"name": "Figure", "mesh": mesh, "skin": 0})
    g.doc["scenes"][0]["nodes"].append(figure_node)

    # The animation.
    def scalars(values):
        return g.add_accessor(struct.pack("<%df" % len(values), *values), 5126, len(values), "SCALAR",
                              [min(values)], [max(values)])

    def vectors(values, kind):
        flat = [c for v in values for c in v]
        return g.add_accessor(struct.pack("<%df" % len(flat), *flat), 5126, len(values), kind)

    keys = [k * STEP for k in range(int(DURATION / STEP) + 1)]
    swing = [quaternion_about_z(SWING if k % 2 else -SWING) for k in range(len(keys))]
    eased = []  # CUBICSPLINE: in-tangent, value, out-tangent per key (zero tangents)
    for q in swing:
        eased += [[0, 0, 0, 0], [-q[0], -q[1], -q[2], q[3]], [0, 0, 0, 0]]  # the other leg: opposite swing
    samplers = [
        {"input": scalars([0.0, DURATION]), "output": vectors([[-2.5, 0, 0.2], [2.5, 0, 0.2]], "VEC3")},
        {"input": scalars(keys), "output": vectors(swing, "VEC4")},
        {"input": scalars(keys), "output": vectors(eased, "VEC4"), "interpolation": "CUBICSPLINE"},
        {"input": scalars([0.0, DURATION]), "output": vectors([[0, HIP_HEIGHT, 0], [0, HIP_HEIGHT, 0]], "VEC3")},
    ]
    channels = [
        {"sampler": 0, "target": {"node": walker, "path": "translation"}},
        {"sampler": 1, "target": {"node": walker + 2, "path": "rotation"}},
        {"sampler": 2, "target": {"node": walker + 3, "path": "rotation"}},
        {"sampler": 3, "target": {"node": walker + 1, "path": "translation"}},
    ]
    g.doc["animations"] = [{"name": "Walk", "samplers": samplers, "channels": channels}]
    g.write(folder, "walker")


if __name__ == "__main__":
    main()
