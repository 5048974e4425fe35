#!/usr/bin/env python3
"""Generates data/tree: the paper's kind of scene (../shared/seed/paper-slides.txt) — a tree (a
trunk and many leaf quads) on a tessellated ground under a point light, and a small ball (about
3 % of the scene's size) rolling past and under the tree for 120 frames. Most of the scene is
static and a small object moves: the case the incremental update is for.

Writes tree.gltf, tree.bin and animation.json. Deterministic (fixed random seed). Standard library
only; shares the glTF writer with make_cornell.py. Run: python3 scripts/make_tree.py [OUT_DIR]
"""
import json
import math
import os
import random
import sys

sys.path.insert(0, os.path.dirname(__file__))
from make_cornell import GltfBuilder, grid  # noqa: E402

GROUND_HALF = 5.0      # the ground is 10 x 10 m
GROUND_CELLS = 100     # 101^2 = 10201 vertices
LEAVES = 1500          # 4 vertices each
LEAF_HALF = 0.13
TRUNK_HEIGHT = 2.6
BALL_RADIUS = 0.2      # 0.4 m across: ~3 % of the scene's ~14.6 m diagonal
FRAMES = 120

GROUND = [0.55, 0.5, 0.4]
BARK = [0.35, 0.25, 0.15]
LEAF = [0.25, 0.55, 0.2]
BALL = [0.8, 0.1, 0.1]


def trunk(radius, height, sides=16, rings=12):
    positions, normals, indices = [], [], []
    for j in range(rings + 1):
        for i in range(sides + 1):
            a = 2 * math.pi * i / sides
            positions.append([radius * math.cos(a), height * j / rings, radius * math.sin(a)])
            normals.append([math.cos(a), 0.0, math.sin(a)])
    row = sides + 1
    for j in range(rings):
        for i in range(sides):
            a = j * row + i
            # Counter-clockwise seen from outside.
            indices += [a, a + row, a + 1, a + 1, a + row, a + row + 1]
    return positions, normals, indices


def leaves(rng):
    positions, normals, indices = [], [], []
    centre = [0.0, 3.4, 0.0]
    for _ in range(LEAVES):
        # A point in an ellipsoidal crown, a random orientation tilted towards the sky.
        while True:
            p = [rng.uniform(-1, 1) for _ in range(3)]
            if sum(c * c for c in p) <= 1:
                break
        c = [centre[0] + 1.7 * p[0], centre[1] + 1.1 * p[1], centre[2] + 1.7 * p[2]]
        theta, phi = rng.uniform(0, 0.45 * math.pi), rng.uniform(0, 2 * math.pi)
        n = [math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi)]
        helper = [1.0, 0.0, 0.0] if abs(n[0]) < 0.9 else [0.0, 0.0, 1.0]
        u = [n[1] * helper[2] - n[2] * helper[1], n[2] * helper[0] - n[0] * helper[2], n[0] * helper[1] - n[1] * helper[0]]
        lu = math.sqrt(sum(x * x for x in u))
        u = [x / lu for x in u]
        v = [n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]]
        base = len(positions)
        for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
            positions.append([c[k] + LEAF_HALF * (su * u[k] + sv * v[k]) for k in range(3)])
            normals.append(n)
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return positions, normals, indices


def icosphere(radius, subdivisions):
    t = (1 + math.sqrt(5)) / 2
    verts = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
             [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    faces = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6],
             [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
             [8, 6, 7], [9, 8, 1]]
    verts = [[c / math.sqrt(sum(x * x for x in v)) for c in v] for v in verts]
    for _ in range(subdivisions):
        cache, out = {}, []

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in cache:
                m = [(verts[a][k] + verts[b][k]) / 2 for k in range(3)]
                length = math.sqrt(sum(x * x for x in m))
                verts.append([x / length for x in m])
                cache[key] = len(verts) - 1
            return cache[key]
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        faces = out
    positions = [[radius * x for x in v] for v in verts]
    return positions, verts, [i for f in faces for i in f]


def main():
    folder = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "data", "tree")
    os.makedirs(folder, exist_ok=True)
    rng = random.Random(1)
    g = GltfBuilder()
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "Sun", "type": "point", "color": [1.0, 0.97, 0.9], "intensity": 2000.0}]}}
    ground, bark, leaf, ball = (g.material("Ground", GROUND), g.material("Bark", BARK), g.material("Leaf", LEAF),
                                g.material("Ball", BALL))
    p, n, i = grid([-GROUND_HALF, 0, GROUND_HALF], [2 * GROUND_HALF, 0, 0], [0, 0, -2 * GROUND_HALF], GROUND_CELLS)
    g.node({"name": "Ground", "mesh": g.mesh("Ground", p, n, i, ground)})
    p, n, i = trunk(0.15, TRUNK_HEIGHT)
    g.node({"name": "Trunk", "mesh": g.mesh("Trunk", p, n, i, bark)})
    p, n, i = leaves(rng)
    g.node({"name": "Leaves", "mesh": g.mesh("Leaves", p, n, i, leaf)})
    p, n, i = icosphere(BALL_RADIUS, 2)
    g.node({"name": "Ball", "mesh": g.mesh("Ball", p, n, i, ball), "translation": [-4.0, BALL_RADIUS, 2.5]})
    g.node({"name": "Sun", "translation": [2.0, 9.0, 3.0], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g.doc["cameras"].append({"name": "View", "type": "perspective",
                             "perspective": {"yfov": 0.8, "aspectRatio": 4 / 3, "znear": 0.1}})
    # Looking at the tree from the front, slightly above (a rotation about x of −15°).
    a = -15 * math.pi / 180
    g.node({"name": "Camera", "camera": 0, "translation": [0, 3.5, 10.0],
            "rotation": [math.sin(a / 2), 0, 0, math.cos(a / 2)]})
    g.write(folder, "tree")

    # The ball rolls from the front left, under the crown, to the back right.
    frames = []
    for f in range(FRAMES):
        s = f / (FRAMES - 1)
        x, z = -4.0 + 7.5 * s, 2.5 - 4.0 * s
        angle = 7.5 * s * math.sqrt(1 + (4.0 / 7.5) ** 2) / BALL_RADIUS  # rolling without slipping
        frames.append({"frame": f, "nodes": {"Ball": {
            "translation": [round(x, 6), BALL_RADIUS, round(z, 6)],
            "rotation": [round(0.4706 * math.sin(angle / 2), 9), 0, round(0.8824 * math.sin(angle / 2), 9),
                         round(math.cos(angle / 2), 9)]}}})
    with open(os.path.join(folder, "animation.json"), "w") as f:
        json.dump({"format": "qsgi-animation", "version": 1, "fps": 24, "frames": frames}, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
