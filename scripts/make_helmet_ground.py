#!/usr/bin/env python3
"""Writes the FlightHelmet on a ground: Khronos' FlightHelmet (from ../shared beside the repository)
standing on a 1 m x 1 m grey ground, Y up, no lights: the scene of issue 56's benchmark, lit by
qsgi's `--sky 1,1,1` (a uniform sky of radiance 1).

- The helmet is unchanged (no transform): its six nodes under one "Helmet" node, so they flatten
  in the asset's own node order (Hose, RubberWood, GlassPlastic, MetalParts, LeatherParts, Lenses).
- The ground, node "Ground" after it, is a 10 x 10-cell grid (0.1 m cells, 121 vertices) centred
  under the helmet, facing +Y, albedo 0.5 grey, at the height of the helmet's lowest vertex (read
  from its .bin: -2.14e-5 m, the stand's flat bottom), so the helmet stands on it.
- A camera ("Front") looks at the helmet from the front, for the EXR view only.
- `--black`: every material, the helmet's too, black (baseColorFactor 0, no textures): qsgi's
  irradiance is then direct light alone (no interreflections), the sky-share check of issue 56.
- `--far-plane DIST`: adds "FarPlane", a 0.1 m x 0.1 m grey quad lying on the ground's level
  (facing +Y) centred DIST metres along +X (DIST > 0.6). It widens the scene's diagonal to about
  DIST while adding no light the helmet can see (it lies edge-on to every point above the ground):
  the "the answer does not move when the scene around an asset grows" check.

The helmet's glTF, its .bin and its textures are not copied: the written glTF names them by a
path relative to OUT_DIR, so the folder works as long as ../shared stays where it is. The ground's
geometry is in OUT_DIR/scene.bin; the scene is OUT_DIR/scene.gltf. Deterministic: the same
arguments give the same bytes.

Exits 2, saying so, when ../shared's FlightHelmet is absent (it is not part of the repository).
Standard library only; shares the glTF writer with make_cornell.py (as make_helmet_room.py does).
Run: python3 scripts/make_helmet_ground.py OUT_DIR [--shared SHARED_DIR] [--black] [--far-plane DIST]
"""
import argparse
import json
import math
import os
import struct
import sys
import urllib.parse

sys.path.insert(0, os.path.dirname(__file__))
from make_cornell import GltfBuilder, grid  # noqa: E402
from make_helmet_room import HELMET, default_shared, embed_helmet, write_with_helmet  # noqa: E402

GROUND_SIZE = 1.0
GROUND_CELLS = 10
GROUND_ALBEDO = [0.5, 0.5, 0.5]
FAR_PLANE_SIZE = 0.1


def lowest_y(helmet, helmet_dir):
    """The lowest Y of the helmet's vertices as float32, from its .bin (the asset has no node
    transforms; refused otherwise)."""
    for node in helmet["nodes"]:
        if any(k in node for k in ("matrix", "translation", "rotation", "scale")):
            sys.exit("make_helmet_ground.py: the helmet has a node transform; this script assumes none")
    (buffer,) = helmet["buffers"]
    with open(os.path.join(helmet_dir, urllib.parse.unquote(buffer["uri"])), "rb") as f:
        data = f.read()
    low = math.inf
    for mesh in helmet["meshes"]:
        for prim in mesh["primitives"]:
            accessor = helmet["accessors"][prim["attributes"]["POSITION"]]
            view = helmet["bufferViews"][accessor["bufferView"]]
            if accessor["componentType"] != 5126 or accessor["type"] != "VEC3":
                sys.exit("make_helmet_ground.py: positions that are not float VEC3")
            stride = view.get("byteStride", 12)
            start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
            for i in range(accessor["count"]):
                low = min(low, struct.unpack_from("<f", data, start + i * stride + 4)[0])
    return low


def build(folder, helmet_path, black, far_plane):
    with open(helmet_path, encoding="utf-8") as f:
        helmet = json.load(f)
    helmet_dir = os.path.dirname(helmet_path)
    ground_y = lowest_y(helmet, helmet_dir)
    g = GltfBuilder()
    doc = g.doc
    doc["asset"]["generator"] = "qsgi scripts/make_helmet_ground.py"
    doc["scenes"][0]["name"] = "HelmetGround" + ("Black" if black else "")
    # The helmet's arrays first (make_helmet_room.embed_helmet); the ground's are appended after.
    helmet_bin, helmet_buffer, children = embed_helmet(doc, helmet, helmet_dir, folder, textures=not black)
    if black:
        # Black, opaque, no textures: qsgi's irradiance is then direct light only.
        doc["materials"] = [{"name": m.get("name", "Material%d" % i),
                             "pbrMetallicRoughness": {"baseColorFactor": [0.0, 0.0, 0.0, 1.0],
                                                      "metallicFactor": 0.0, "roughnessFactor": 1.0}}
                            for i, m in enumerate(doc["materials"])]
    g.node({"name": "Helmet", "children": children})

    ground = g.material("Ground", [0.0] * 3 if black else GROUND_ALBEDO)
    half = GROUND_SIZE / 2
    # Corner at (-half, y, +half), u along +X, v along -Z: the front (CCW) side faces +Y.
    p, n, i = grid([-half, ground_y, half], [GROUND_SIZE, 0, 0], [0, 0, -GROUND_SIZE], GROUND_CELLS)
    g.node({"name": "Ground", "mesh": g.mesh("Ground", p, n, i, ground)})
    if far_plane is not None:
        far = g.material("FarPlane", [0.0] * 3 if black else GROUND_ALBEDO)
        h = FAR_PLANE_SIZE / 2
        p, n, i = grid([far_plane - h, ground_y, h], [FAR_PLANE_SIZE, 0, 0], [0, 0, -FAR_PLANE_SIZE], 1)
        g.node({"name": "FarPlane", "mesh": g.mesh("FarPlane", p, n, i, far)})

    doc["cameras"].append({"name": "Front", "type": "perspective",
                           "perspective": {"yfov": 0.6, "aspectRatio": 4 / 3, "znear": 0.05}})
    # At (0, 0.9, 1.7), turned down by atan(0.55 / 1.7) to look at (0, 0.35, 0).
    tilt = math.atan2(0.55, 1.7)
    g.node({"name": "Camera", "camera": 0, "translation": [0, 0.9, 1.7],
            "rotation": [-math.sin(tilt / 2), 0.0, 0.0, math.cos(tilt / 2)]})

    write_with_helmet(folder, "scene", g, helmet_bin, helmet_buffer)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--shared", default=default_shared(), help="the shared folder (default ../shared beside the repository)")
    ap.add_argument("--black", action="store_true", help="every material black, no textures (direct light only)")
    ap.add_argument("--far-plane", type=float, metavar="DIST",
                    help="add a 0.1 m quad on the ground's level DIST metres along +X (DIST > 0.6)")
    args = ap.parse_args()
    if args.far_plane is not None and not args.far_plane > GROUND_SIZE / 2 + FAR_PLANE_SIZE:
        ap.error("--far-plane must be more than %g m (outside the ground)" % (GROUND_SIZE / 2 + FAR_PLANE_SIZE))
    helmet_path = os.path.join(args.shared, HELMET)
    if not os.path.isfile(helmet_path):
        print("make_helmet_ground.py: %s is absent: the FlightHelmet scene needs ../shared beside the repository "
              "(or --shared SHARED_DIR); nothing written" % helmet_path, file=sys.stderr)
        sys.exit(2)
    os.makedirs(args.out_dir, exist_ok=True)
    build(args.out_dir, helmet_path, args.black, args.far_plane)


if __name__ == "__main__":
    main()
