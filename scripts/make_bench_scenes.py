#!/usr/bin/env python3
"""Generates the scenes scripts/bench_update.py measures besides data/ (standard library only,
deterministic bytes):

- sheet/sheet.gltf: a 4 m sheet of 80 x 80 cells under a point lamp, with one morph target that
  waves all of it (every vertex moves every frame), animated 0 -> 1 over 2 s: the case where
  updating costs more than recomputing, so frames fall back to scratch.
- flying-block.json: a transform file for data/cornell in which the block flies across the box,
  turns, lifts and pauses (a large mover: about a quarter of the paths change per frame), where
  updating must win.
- sweeping-panel/: data/cornell's box with a wall-sized panel (1.8 x 1.8 m, 2 cm thick) that sweeps
  from the back wall to the open front, 8 cm a frame: nearly every path meets it, so every frame
  should be computed from scratch (the fallback's case, issue 34).
- dense-floor/dense-floor.gltf: a floor of 22 x 22 instanced tiles (one mesh of 32 x 32 cells,
  2,048 triangles, 4 mm between vertices) under a point lamp, with a block standing on it: about
  10^6 triangles and 5.3 * 10^5 vertices, the dense asset of issue 45 (instanced, as artists'
  floors are). `--tiles N` makes an N x N crop of it.

Run: python3 scripts/make_bench_scenes.py OUT_DIR [--tiles N]
"""
import json
import math
import os
import struct
import sys

sys.path.insert(0, os.path.dirname(__file__))
from make_cornell import GltfBuilder, box_faces, build, grid  # noqa: E402

CELLS = 80


def sheet(folder):
    g = GltfBuilder()
    g.doc["asset"]["generator"] = "qsgi scripts/make_bench_scenes.py"
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    white = g.material("White", [0.7, 0.7, 0.7])
    positions, normals, indices = grid([-2, 0, 2], [4, 0, 0], [0, 0, -4], CELLS)
    mesh = g.mesh("Sheet", positions, normals, indices, white)
    # The morph target: a wave over the whole sheet (displacements only; normals left alone).
    wave = [(0.0, 0.25 * math.sin(2.1 * p[0]) * math.cos(1.7 * p[2]), 0.0) for p in positions]
    lo = [min(d[k] for d in wave) for k in range(3)]
    hi = [max(d[k] for d in wave) for k in range(3)]
    target = g.add_accessor(b"".join(struct.pack("<3f", *d) for d in wave), 5126, len(wave), "VEC3", lo, hi, 34962)
    g.doc["meshes"][mesh]["primitives"][0]["targets"] = [{"POSITION": target}]
    g.doc["meshes"][mesh]["weights"] = [0.0]
    g.node({"name": "Sheet", "mesh": mesh})
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "Lamp", "type": "point", "intensity": 30.0}]}}
    g.node({"name": "Lamp", "translation": [0.3, 2.0, 0.2], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g.doc["cameras"].append({"name": "Above", "type": "perspective",
                             "perspective": {"yfov": 0.9, "aspectRatio": 4 / 3, "znear": 0.05}})
    tilt = math.radians(-40)
    g.node({"name": "Camera", "camera": 0, "translation": [0, 3.0, 4.0],
            "rotation": [round(math.sin(tilt / 2), 9), 0, 0, round(math.cos(tilt / 2), 9)]})
    times = [0.0, 2.0]
    weights = [0.0, 1.0]
    t_acc = g.add_accessor(struct.pack("<2f", *times), 5126, 2, "SCALAR", [0.0], [2.0])
    w_acc = g.add_accessor(struct.pack("<2f", *weights), 5126, 2, "SCALAR")
    node = len(g.doc["nodes"]) - 3  # the sheet
    g.doc["animations"] = [{"name": "Wave", "samplers": [{"input": t_acc, "output": w_acc, "interpolation": "LINEAR"}],
                            "channels": [{"sampler": 0, "target": {"node": node, "path": "weights"}}]}]
    os.makedirs(os.path.join(folder, "sheet"), exist_ok=True)
    g.write(os.path.join(folder, "sheet"), "sheet")


# The block grown to 0.8 x 0.96 x 0.8 m: about a quarter of the paths change per frame, as in the
# animation issue 34 measured (data/cornell's own block changes a tenth).
BLOCK_SCALE = 1.6


def flying_block(folder):
    frames = []
    for f in range(48):
        if 16 <= f < 24:  # a pause
            t = 16
        else:
            t = f if f < 16 else f - 8
        x = -0.6 + 1.2 * t / 39
        y = 0.35 * math.sin(math.pi * t / 39)
        z = 0.1 + 0.3 * math.sin(0.21 * t)
        angle = 0.09 * t
        frames.append({"frame": f, "nodes": {"Block": {
            "translation": [round(x, 6), round(y, 6), round(z, 6)],
            "rotation": [0, round(math.sin(angle / 2), 9), 0, round(math.cos(angle / 2), 9)],
            "scale": [BLOCK_SCALE] * 3}}})
    with open(os.path.join(folder, "flying-block.json"), "w") as out:
        json.dump({"format": "qsgi-animation", "version": 1, "fps": 24, "frames": frames}, out, indent=1)
        out.write("\n")


PANEL_FRAMES = 24


def sweeping_panel(folder):
    def add_panel(g, white):
        p, n, i = box_faces([0.9, 0.9, 0.01], 24)
        g.node({"name": "Panel", "mesh": g.mesh("Panel", p, n, i, white), "translation": [0, 0.05, -0.9]})

    out = os.path.join(folder, "sweeping-panel")
    os.makedirs(out, exist_ok=True)
    build(out, "panel", wall_cells=64, light="panel", animate=False, add_nodes=add_panel)
    frames = [{"frame": f, "nodes": {"Panel": {"translation": [0, 0.05, round(-0.9 + 1.8 * f / (PANEL_FRAMES - 1), 6)]}}}
              for f in range(PANEL_FRAMES)]
    with open(os.path.join(out, "animation.json"), "w") as f:
        json.dump({"format": "qsgi-animation", "version": 1, "fps": 24, "frames": frames}, f, indent=1)
        f.write("\n")


TILE_CELLS = 32
TILE_SIZE = 0.128  # 4 mm cells


def dense_floor(folder, tiles=22, stem="dense-floor"):
    g = GltfBuilder()
    g.doc["asset"]["generator"] = "qsgi scripts/make_bench_scenes.py"
    g.doc["extensionsUsed"] = ["KHR_lights_punctual"]
    white = g.material("White", [0.7, 0.7, 0.7])
    grey = g.material("Grey", [0.5, 0.5, 0.5])
    positions, normals, indices = grid([0, 0, TILE_SIZE], [TILE_SIZE, 0, 0], [0, 0, -TILE_SIZE], TILE_CELLS)
    tile = g.mesh("Tile", positions, normals, indices, white)
    half = tiles * TILE_SIZE / 2
    for j in range(tiles):
        for i in range(tiles):
            g.node({"name": "Tile_%d_%d" % (i, j), "mesh": tile,
                    "translation": [round(-half + i * TILE_SIZE, 6), 0, round(-half + j * TILE_SIZE, 6)]})
    # A block standing on the floor: contacts and a shadow, as an artist's scene has.
    side = min(0.3, half / 3)
    p, n, i = box_faces([side, side, side], 8)
    g.node({"name": "Block", "mesh": g.mesh("Block", p, n, i, grey), "translation": [round(-half / 4, 6), 0, 0]})
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [{"name": "Lamp", "type": "point",
                                                               "intensity": round(12.0 * half * half, 6)}]}}
    g.node({"name": "Lamp", "translation": [round(half / 3, 6), round(1.2 * half, 6), round(half / 5, 6)],
            "extensions": {"KHR_lights_punctual": {"light": 0}}})
    g.doc["cameras"].append({"name": "Above", "type": "perspective",
                             "perspective": {"yfov": 0.9, "aspectRatio": 4 / 3, "znear": 0.05}})
    tilt = math.radians(-45)
    g.node({"name": "Camera", "camera": 0, "translation": [0, round(1.6 * half, 6), round(1.6 * half, 6)],
            "rotation": [round(math.sin(tilt / 2), 9), 0, 0, round(math.cos(tilt / 2), 9)]})
    out = os.path.join(folder, stem)
    os.makedirs(out, exist_ok=True)
    g.write(out, stem)


def main():
    args = sys.argv[1:]
    if any(a in ("-h", "--help") for a in args):
        print(__doc__)
        return
    if any(a.startswith("-") and a != "--tiles" for a in args):
        sys.exit("make_bench_scenes.py: unknown option; usage: make_bench_scenes.py [FOLDER] [--tiles N]")
    tiles = None
    if "--tiles" in args:
        k = args.index("--tiles")
        tiles = int(args[k + 1])
        del args[k:k + 2]
    folder = args[0] if args else "out/bench/scenes"
    os.makedirs(folder, exist_ok=True)
    if tiles is not None:  # the dense floor alone, cropped
        dense_floor(folder, tiles, "dense-floor-%d" % tiles)
        return
    sheet(folder)
    flying_block(folder)
    sweeping_panel(folder)
    dense_floor(folder)


if __name__ == "__main__":
    main()
