#!/usr/bin/env python3
"""Writes the FlightHelmet room: Khronos' FlightHelmet (95k triangles, from ../shared beside the
repository) standing on the floor of a 2x2x2 m room whose five walls are 20x20-cell grids (the
front is open), lit by a point light under the ceiling, and a 0.2 m block sliding across the floor
in front of the helmet (animation.json). The scene where per-vertex stages meet a dense mesh: disc
regions and DETP on 57,597 vertices, of which 55,392 are the helmet's.

The helmet's glTF, its .bin and its textures are not copied: the written glTF names them by a
path relative to OUT_DIR, so the folder works as long as ../shared stays where it is. The room's
own geometry is in helmet_room.bin. Deterministic: the same OUT_DIR gives the same bytes.

Exits 2, saying so, when ../shared's FlightHelmet is absent (it is not part of the repository).
Standard library only; shares the glTF writer with make_cornell.py.
Run: python3 scripts/make_helmet_room.py OUT_DIR [--shared SHARED_DIR]
"""
import json
import math
import os
import sys
import urllib.parse

sys.path.insert(0, os.path.dirname(__file__))
from make_cornell import GltfBuilder, box_faces, box_walls, grid  # noqa: E402

HELMET = os.path.join("data", "gltf-samples", "models", "FlightHelmet", "glTF", "FlightHelmet.gltf")
WALL_CELLS = 20      # 5 walls x 21^2 = 2205 vertices
BLOCK_HALF = 0.1
BLOCK_CELLS = 4
FRAMES = 24

RED = [0.63, 0.065, 0.05]
GREEN = [0.14, 0.45, 0.091]
WHITE = [0.725, 0.71, 0.68]


def default_shared():
    return os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared"))


def uri_to(target, folder):
    """A relative URI from `folder` to the file `target` (percent-encoded, '/' separated)."""
    relative = os.path.relpath(os.path.abspath(target), os.path.abspath(folder))
    return urllib.parse.quote(relative.replace(os.sep, "/"), safe="/")


def embed_helmet(doc, helmet, helmet_dir, folder, textures=True):
    """Copies the helmet's glTF into `doc` (GltfBuilder's) ahead of the scene's own arrays, unchanged,
    so that its indices stay valid (GltfBuilder appends the rest); its views read buffer 1, its own
    .bin, and its images and .bin are named by URIs relative to `folder`. textures=False leaves its
    textures, images and samplers out. Returns the .bin's URI, the helmet's buffer and the indices
    of its nodes in `doc`, for the caller to hang under a node of its own."""
    keys = ["meshes", "materials", "accessors", "bufferViews"] + (["textures", "images", "samplers"] if textures else [])
    for key in keys:
        doc[key] = [dict(item) for item in helmet.get(key, [])]
    for view in doc["bufferViews"]:
        view["buffer"] = 1
    for image in doc.get("images", []) if textures else []:
        if "uri" in image:
            image["uri"] = uri_to(os.path.join(helmet_dir, urllib.parse.unquote(image["uri"])), folder)
    (helmet_buffer,) = helmet["buffers"]
    helmet_bin = uri_to(os.path.join(helmet_dir, urllib.parse.unquote(helmet_buffer["uri"])), folder)
    children = []
    for node in helmet["nodes"]:
        doc["nodes"].append(dict(node))
        children.append(len(doc["nodes"]) - 1)
    return helmet_bin, helmet_buffer, children


def write_with_helmet(folder, name, g, helmet_bin, helmet_buffer):
    """Writes NAME.gltf and NAME.bin (the builder's own buffer, 0) into `folder`, buffer 1 being
    the helmet's .bin that embed_helmet named."""
    g.doc["buffers"] = [{"uri": name + ".bin", "byteLength": len(g.bin)},
                        {"uri": helmet_bin, "byteLength": helmet_buffer["byteLength"]}]
    with open(os.path.join(folder, name + ".bin"), "wb") as f:
        f.write(g.bin)
    with open(os.path.join(folder, name + ".gltf"), "w", encoding="utf-8") as f:
        json.dump(g.doc, f, indent=1)
        f.write("\n")


def build(folder, helmet_path):
    with open(helmet_path, encoding="utf-8") as f:
        helmet = json.load(f)
    helmet_dir = os.path.dirname(helmet_path)
    g = GltfBuilder()
    doc = g.doc
    doc["asset"]["generator"] = "qsgi scripts/make_helmet_room.py"
    doc["scenes"][0]["name"] = "HelmetRoom"
    doc["extensionsUsed"] = ["KHR_lights_punctual"]
    helmet_bin, helmet_buffer, children = embed_helmet(doc, helmet, helmet_dir, folder)
    # The helmet's nodes under one "Helmet" node, standing on the floor (its base is at y = 0).
    g.node({"name": "Helmet", "children": children, "translation": [0, 0, -0.2]})

    white, red, green, block = (g.material("White", WHITE), g.material("Red", RED), g.material("Green", GREEN),
                                g.material("Block", WHITE))
    for name, corner, u, v, material in box_walls(white, red, green):
        p, n, i = grid(corner, u, v, WALL_CELLS)
        g.node({"name": name, "mesh": g.mesh(name, p, n, i, material)})
    p, n, i = box_faces([BLOCK_HALF, BLOCK_HALF, BLOCK_HALF], BLOCK_CELLS)
    g.node({"name": "Block", "mesh": g.mesh("Block", p, n, i, block), "translation": [-0.7, 0, 0.15]})
    doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "Bulb", "type": "point", "color": [1.0, 0.97, 0.9], "intensity": 20.0}]}}
    g.node({"name": "Bulb", "translation": [0.3, 1.8, 0.4], "extensions": {"KHR_lights_punctual": {"light": 0}}})
    doc["cameras"].append({"name": "Front", "type": "perspective",
                           "perspective": {"yfov": 0.7, "aspectRatio": 4 / 3, "znear": 0.05}})
    g.node({"name": "Camera", "camera": 0, "translation": [0, 1, 4.0]})

    write_with_helmet(folder, "helmet_room", g, helmet_bin, helmet_buffer)

    # The block slides along the floor in front of the helmet, 5 cm from its front at the closest.
    frames = []
    for f in range(FRAMES):
        s = f / (FRAMES - 1)
        frames.append({"frame": f, "nodes": {"Block": {"translation": [round(-0.7 + 1.4 * s, 6), 0, 0.15]}}})
    with open(os.path.join(folder, "animation.json"), "w", encoding="utf-8") as f:
        json.dump({"format": "qsgi-animation", "version": 1, "fps": 24, "frames": frames}, f, indent=1)
        f.write("\n")


def main():
    args = sys.argv[1:]
    shared = default_shared()
    if "--shared" in args:
        at = args.index("--shared")
        if at + 1 >= len(args):
            sys.exit("make_helmet_room.py: --shared needs a folder")
        shared = args[at + 1]
        del args[at:at + 2]
    if len(args) != 1 or args[0].startswith("-"):
        sys.exit("usage: make_helmet_room.py OUT_DIR [--shared SHARED_DIR]")
    helmet_path = os.path.join(shared, HELMET)
    if not os.path.isfile(helmet_path):
        print("make_helmet_room.py: %s is absent: the FlightHelmet room needs ../shared beside the repository "
              "(or --shared SHARED_DIR); nothing written" % helmet_path, file=sys.stderr)
        sys.exit(2)
    folder = args[0]
    os.makedirs(folder, exist_ok=True)
    build(folder, helmet_path)


if __name__ == "__main__":
    main()
