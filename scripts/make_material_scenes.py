#!/usr/bin/env python3
"""Writes small glTF 2.0 scenes, one per material feature of issue 57 and one with all of them, for
qsgi and for scripts/material_reference.py (standard library only: the PNG textures are written
with zlib and struct).

Every scene is a room of subdivided quads (about 0.2 m cells, so that the vertices sample the
lighting; 1,300 to 2,400 vertices), metres, Y up, single-sided walls facing into the room, all
materials metallicFactor 0 and roughnessFactor 1, each with a camera. Node order: the room's
surfaces first (floor, ceiling, back z-, front z+, left x-, right x+), then the objects, so a scene
and its twin (below) share the room's vertex indices where their rooms are the same.

  textured_floor    closed 3 x 2.4 x 3 m room lit by a 0.8 m ceiling panel (L_e 10 through
                    KHR_materials_emissive_strength); the floor's baseColorTexture is a 2 x 1 PNG,
                    red on the x < 0 half and blue on the x > 0 half (sRGB (200, 40, 30) and
                    (30, 60, 200)), sampler NEAREST / CLAMP_TO_EDGE, baseColorFactor 0.9; walls and
                    ceiling white 0.8. Tests per-texel albedo (the colour each wall gets by bleeding
                    is its neighbouring half's, not the mean's) and sRGB decoding. The floor has 15
                    cells across, so no vertex lies on the texel boundary.
  vertex_colour     the same room and panel; the back wall's colour is COLOR_0 as float VEC3
                    (0.1, 0.2, 0.8) on a white 0.8 factor, the left wall's COLOR_0 an unsigned-byte
                    normalized VEC4 (230, 190, 60, 255) (linear, 0.9 x 0.745 x 0.235) on a
                    factor of 1; floor grey 0.5. Tests COLOR_0 x factor and both accessor kinds.
  alpha_mask        the same room and panel; a 1 x 1 m doubleSided card at y = 1.2 under the panel,
                    its front facing down, alphaMode MASK, alphaCutoff 0.5, baseColorFactor
                    (0.9, 0.8, 0.7, 1) x an 8 x 8 RGBA checker whose alpha is 255 and 0 in turn
                    (coverage 0.5; colour sRGB 235), NEAREST / CLAMP_TO_EDGE, 13 x 13 cells (no
                    vertex on a texel boundary). Tests the cut-out (the floor right under the card
                    gets about half of the panel's direct light, not none) and the back side of a
                    doubleSided sheet (the card's top, lit by the panel).
  alpha_blend       the same card without texture, alphaMode BLEND, baseColorFactor
                    (0.9, 0.8, 0.7, 0.5): half of the light passes whatever the direction.
  glass_window      a closed 3 x 2.4 x 3 m room lit only by a uniform sky (render with --sky 1,1,1)
                    through a 1 x 0.8 m window in the x+ wall (z in [-0.5, 0.5], y in [1, 1.8]),
                    closed by a single-sided pane facing into the room: KHR_materials_transmission
                    transmissionFactor 0.9, baseColorFactor (0.8, 0.9, 0.85) (the tint), metallic 0.
                    Tests thin transmission: direct light behind the pane is 0.9 x tint x the open
                    window's, entering through the back of a single-sided surface.
  emissive_texture  a closed 3 x 2.4 x 3 m room with no other light; a 0.6 x 0.5 x 0.6 m box on the
                    floor (five faces, no bottom; grey 0.5) whose emissiveTexture is an 8 x 8 PNG,
                    black but for 2 x 2 white texels that the box's +z face maps to a 0.3 x 0.25 m
                    "screen" in its middle (the other faces map to a black quadrant); emissiveFactor
                    1 x KHR_materials_emissive_strength 30, NEAREST / CLAMP_TO_EDGE. Tests that the
                    screen alone emits (power pi x 30 x 0.075 m^2 = 7.07 W), not the whole box.
  materials_room    everything at once in a 4 x 2.6 x 3.4 m room, lit by a 0.8 m ceiling panel (L_e 8)
                    and a uniform sky (--sky 1,1,1) through a 1.2 x 0.8 m glass window in the x+ wall
                    (transmission 0.9, tint (0.85, 0.9, 0.95)); the floor's red/blue texture read
                    through KHR_texture_transform (scale (2, 1), offset (0.25, 0)) with REPEAT:
                    stripes, no vertex on a stripe's edge; the back wall blue by COLOR_0; a
                    doubleSided MASK checker card under the panel; a single-sided vertical BLEND
                    card (alpha 0.5) before the left wall; the box with the screen on the floor,
                    its screen facing the room's front.

--twins also writes, for checks with scripts/reference.py (which reads factors only) or against
the feature scene, scenes whose difference from a feature scene is known:
  textured_floor_factors   the floor as two primitives, red and blue by baseColorFactor (the
                           texture's decoded colours x 0.9), 8 + 8 cells; the rest identical.
  vertex_colour_factors    the two walls coloured by baseColorFactor = factor x COLOR_0.
  card_room_nocard         the alpha_mask / alpha_blend room without the card.
  glass_window_open        glass_window without the pane (the window open).
  emissive_texture_factors the box's screen as a primitive of its own with emissiveFactor 1 x
                           strength 30, the rest of the box not emissive (the box's +z face split
                           into the screen and the four pieces around it).

Run: python3 scripts/make_material_scenes.py OUT_DIR [NAME ...] [--twins] [--list]
Writes OUT_DIR/NAME.gltf, NAME.bin and NAME_*.png for each scene (all of them without NAMEs).
Deterministic: the same arguments give the same bytes.
"""
import argparse
import math
import os
import struct
import sys
import zlib

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_cornell import GltfBuilder, grid  # noqa: E402
from make_test_scenes import look_at  # noqa: E402

NEAREST, LINEAR = 9728, 9729
REPEAT, CLAMP = 10497, 33071
WHITE = [0.8, 0.8, 0.8]
CELL = 0.2  # metres: the rooms' quads

SCENES = ["textured_floor", "vertex_colour", "alpha_mask", "alpha_blend", "glass_window", "emissive_texture",
          "materials_room"]
TWINS = ["textured_floor_factors", "vertex_colour_factors", "card_room_nocard", "glass_window_open",
         "emissive_texture_factors"]

# The floor texture's two texels (sRGB bytes) and the factor on them.
RED_SRGB, BLUE_SRGB, FLOOR_FACTOR = (200, 40, 30), (30, 60, 200), 0.9
BLUE_COLOR_0 = [0.1, 0.2, 0.8]            # float VEC3
YELLOW_COLOR_0 = [230, 190, 60, 255]      # unsigned-byte normalized VEC4
CARD_FACTOR = [0.9, 0.8, 0.7]
GLASS_TINT = [0.8, 0.9, 0.85]


# ---------------------------------------------------------------------------------------------
# PNG (8-bit, RGB or RGBA, no interlace), with zlib and struct only

def png_bytes(width, height, pixels, channels):
    """pixels: rows top to bottom, each a list of width tuples of `channels` bytes."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    colour_type = {3: 2, 4: 6}[channels]
    raw = b"".join(b"\x00" + bytes(c for px in row for c in px) for row in pixels)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def srgb_to_linear(byte):
    c = byte / 255.0
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


# ---------------------------------------------------------------------------------------------
# A builder with textures, UVs and COLOR_0 (on make_cornell's GltfBuilder: its buffer and accessors)

class SceneBuilder:
    def __init__(self, folder, name):
        self.folder, self.name = folder, name
        self.g = GltfBuilder()
        self.doc = self.g.doc
        self.doc["asset"]["generator"] = "qsgi scripts/make_material_scenes.py"
        self.doc["scenes"][0]["name"] = name
        self.doc["extensionsUsed"] = []
        for key in ("images", "samplers", "textures"):
            self.doc[key] = []
        self.pngs = {}

    def use(self, extension):
        if extension not in self.doc["extensionsUsed"]:
            self.doc["extensionsUsed"].append(extension)

    def texture(self, stem, width, height, pixels, channels, mag=NEAREST, wrap=CLAMP):
        """A PNG written beside the scene (NAME_stem.png) and a texture reading it; returns its index."""
        uri = f"{self.name}_{stem}.png"
        self.pngs[uri] = png_bytes(width, height, pixels, channels)
        self.doc["images"].append({"uri": uri})
        self.doc["samplers"].append({"magFilter": mag, "minFilter": mag, "wrapS": wrap, "wrapT": wrap})
        self.doc["textures"].append({"sampler": len(self.doc["samplers"]) - 1, "source": len(self.doc["images"]) - 1})
        return len(self.doc["textures"]) - 1

    def material(self, name, base, alpha=1.0, base_texture=None, texture_transform=None, emission=None, strength=None,
                 emissive_texture=None, alpha_mode=None, cutoff=None, double_sided=False, transmission=None):
        pbr = {"baseColorFactor": list(base) + [alpha], "metallicFactor": 0.0, "roughnessFactor": 1.0}
        if base_texture is not None:
            pbr["baseColorTexture"] = {"index": base_texture}
            if texture_transform:
                pbr["baseColorTexture"]["extensions"] = {"KHR_texture_transform": texture_transform}
                self.use("KHR_texture_transform")
        m = {"name": name, "pbrMetallicRoughness": pbr}
        if emission is not None:
            m["emissiveFactor"] = list(emission)
        if emissive_texture is not None:
            m["emissiveTexture"] = {"index": emissive_texture}
        extensions = {}
        if strength is not None:
            extensions["KHR_materials_emissive_strength"] = {"emissiveStrength": strength}
            self.use("KHR_materials_emissive_strength")
        if transmission is not None:
            extensions["KHR_materials_transmission"] = {"transmissionFactor": transmission}
            pbr["roughnessFactor"] = 0.0
            self.use("KHR_materials_transmission")
        if extensions:
            m["extensions"] = extensions
        if alpha_mode:
            m["alphaMode"] = alpha_mode
        if cutoff is not None:
            m["alphaCutoff"] = cutoff
        if double_sided:
            m["doubleSided"] = True
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, parts, material, color=None):
        """A node with one primitive from `parts`: [(positions, normals, indices, uvs)] concatenated.
        color: None, ("float", rgb) or ("ubyte", rgba): COLOR_0 constant over the primitive."""
        positions, normals, indices, uvs = [], [], [], []
        for p, n, i, uv in parts:
            base = len(positions)
            positions += p
            normals += n
            uvs += uv
            indices += [base + k for k in i]
        g = self.g
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        attributes = {
            "POSITION": g.add_accessor(b"".join(struct.pack("<3f", *p) for p in positions), 5126, len(positions), "VEC3",
                                       lo, hi, target=34962),
            "NORMAL": g.add_accessor(b"".join(struct.pack("<3f", *n) for n in normals), 5126, len(normals), "VEC3",
                                     target=34962),
            "TEXCOORD_0": g.add_accessor(b"".join(struct.pack("<2f", *uv) for uv in uvs), 5126, len(uvs), "VEC2",
                                         target=34962),
        }
        if color is not None:
            kind, value = color
            if kind == "float":
                attributes["COLOR_0"] = g.add_accessor(struct.pack("<3f", *value) * len(positions), 5126, len(positions),
                                                       "VEC3", target=34962)
            else:
                attributes["COLOR_0"] = g.add_accessor(struct.pack("<4B", *value) * len(positions), 5121, len(positions),
                                                       "VEC4", target=34962)
                self.doc["accessors"][attributes["COLOR_0"]]["normalized"] = True
        ia = g.add_accessor(struct.pack("<%dI" % len(indices), *indices), 5125, len(indices), "SCALAR", target=34963)
        self.doc["meshes"].append({"name": name, "primitives": [{"attributes": attributes, "indices": ia,
                                                                  "material": material}]})
        g.node({"name": name, "mesh": len(self.doc["meshes"]) - 1})
        return len(positions)

    def camera(self, eye, target):
        self.doc["cameras"].append({"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 4 / 3,
                                                                            "znear": 0.01}})
        self.g.node(dict(look_at(eye, target), camera=len(self.doc["cameras"]) - 1, name="Camera"))

    def write(self):
        if not self.doc["extensionsUsed"]:
            del self.doc["extensionsUsed"]
        for key in ("images", "samplers", "textures", "cameras"):
            if not self.doc[key]:
                del self.doc[key]
        for uri, data in self.pngs.items():
            with open(os.path.join(self.folder, uri), "wb") as f:
                f.write(data)
        self.g.write(self.folder, self.name)


def quad(corner, u, v, cells, cells_v=None, uv=lambda s, t: (s, t), skip=None):
    """make_cornell.grid's quads (front = u x v), with TEXCOORD_0 = uv(s, t) for the grid
    parameters s, t in [0, 1]; skip(i, j) drops cell (i, j) (a window), and the vertices only it used."""
    cells_v = cells if cells_v is None else cells_v
    p, n, idx = grid(corner, u, v, cells, cells_v)
    st = [uv(i / cells, j / cells_v) for j in range(cells_v + 1) for i in range(cells + 1)]
    if skip is not None:
        kept = []
        for c in range(cells * cells_v):
            i, j = c % cells, c // cells
            if not skip(i, j):
                kept += idx[6 * c:6 * c + 6]
        used = sorted(set(kept))
        remap = {old: new for new, old in enumerate(used)}
        p, n, st = [p[k] for k in used], [n[k] for k in used], [st[k] for k in used]
        idx = [remap[k] for k in kept]
    return p, n, idx, st


def cells_for(length):
    """About CELL metres per cell, an odd count (no vertex on the middle line, where the test textures
    change colour)."""
    c = max(1, int(round(length / CELL)))
    return c if c % 2 else c + 1


# ---------------------------------------------------------------------------------------------
# The pieces

def room(b, size, materials, floor_uv=None, floor_split=None, right_skip=None, colors=None):
    """The six inward-facing surfaces of the room x in [-W/2, W/2], y in [0, H], z in [-D/2, D/2].
    materials: dict surface -> material (floor, ceiling, back, front, left, right). floor_uv: the floor's
    uv(s, t) (s along +x, t along -z). floor_split: (left material, right material): the floor as two
    primitives split at x = 0. right_skip: cells (i, j) of the x+ wall left out (i along +z from z = -D/2,
    j up). colors: dict surface -> COLOR_0 spec."""
    w, h, d = size
    x0, x1, z0, z1 = -w / 2, w / 2, -d / 2, d / 2
    colors = colors or {}
    cw, ch, cd = cells_for(w), int(round(h / CELL)), cells_for(d)
    if floor_split:
        half = cw // 2 + 1
        for k, (mat, start) in enumerate(zip(floor_split, (x0, 0.0))):
            b.mesh("Floor" + "LR"[k], [quad([start, 0, z1], [w / 2, 0, 0], [0, 0, -d], half, cd)], mat)
    else:
        b.mesh("Floor", [quad([x0, 0, z1], [w, 0, 0], [0, 0, -d], cw, cd, uv=floor_uv or (lambda s, t: (s, t)))],
               materials["floor"])
    b.mesh("Ceiling", [quad([x0, h, z0], [w, 0, 0], [0, 0, d], cw, cd)], materials["ceiling"])
    b.mesh("BackWall", [quad([x0, 0, z0], [w, 0, 0], [0, h, 0], cw, ch)], materials["back"], colors.get("back"))
    b.mesh("FrontWall", [quad([x1, 0, z1], [-w, 0, 0], [0, h, 0], cw, ch)], materials["front"], colors.get("front"))
    b.mesh("LeftWall", [quad([x0, 0, z1], [0, 0, -d], [0, h, 0], cd, ch)], materials["left"], colors.get("left"))
    b.mesh("RightWall", [quad([x1, 0, z0], [0, 0, d], [0, h, 0], cd, ch, skip=right_skip)], materials["right"],
           colors.get("right"))
    return cd, ch


def panel(b, height, size, material, centre=(0.0, 0.0)):
    """A square emitter 1 mm under the ceiling, facing down, 4 x 4 cells."""
    cx, cz = centre
    b.mesh("Panel", [quad([cx - size / 2, height - 0.001, cz - size / 2], [size, 0, 0], [0, 0, size], 4)], material)


def checker_card(b, name, material, centre, y, size=1.0, cells=13):
    """A horizontal square card facing down (its back, up, faces the panel), UV 0..1 over it."""
    cx, cz = centre
    b.mesh(name, [quad([cx - size / 2, y, cz - size / 2], [size, 0, 0], [0, 0, size], cells)], material)


def checker_texture(b, stem):
    px = [[(235, 235, 235, 255 if (i + j) % 2 == 0 else 0) for i in range(8)] for j in range(8)]
    return b.texture(stem, 8, 8, px, 4)


def screen_texture(b, stem):
    """8 x 8, black but for texels (1..2, 1..2): the screen, in the top-left quadrant."""
    px = [[(255, 255, 255) if i in (1, 2) and j in (1, 2) else (0, 0, 0) for i in range(8)] for j in range(8)]
    return b.texture(stem, 8, 8, px, 3)


def screen_box(b, material, centre, size=(0.6, 0.5, 0.6), facing=+1, split_material=None):
    """A box standing on the floor, five faces (no bottom), 0.6 x 0.5 x 0.6 m. Its screen face (+z, or -z
    with facing -1) maps to the texture's top-left quadrant [0, 0.5]^2 (5 x 5 cells: vertices at u = 0.1 i, none
    on a texel edge), the other faces to the black quadrant [0.5, 1]^2. split_material: the twin's
    layout: the screen face cut at the screen's edges, the screen (3 x 2 cells) a primitive of its own
    with split_material, the rest of the box not emissive."""
    sx, sy, sz = size
    cx, cz = centre
    x0, x1, z0, z1 = cx - sx / 2, cx + sx / 2, cz - sz / 2, cz + sz / 2
    black = lambda s, t: (0.5 + 0.5 * s, 0.5 + 0.5 * t)  # noqa: E731
    screen_uv = lambda s, t: (0.5 * s, 0.5 * (1 - t))     # noqa: E731  (the image's top at the face's top)
    if facing > 0:
        face = ([x0, 0, z1], [sx, 0, 0], [0, sy, 0])
        others = [([x1, 0, z0], [-sx, 0, 0], [0, sy, 0]), ([x1, 0, z1], [0, 0, -sz], [0, sy, 0]),
                  ([x0, 0, z0], [0, 0, sz], [0, sy, 0])]
    else:
        face = ([x1, 0, z0], [-sx, 0, 0], [0, sy, 0])
        others = [([x0, 0, z1], [sx, 0, 0], [0, sy, 0]), ([x1, 0, z1], [0, 0, -sz], [0, sy, 0]),
                  ([x0, 0, z0], [0, 0, sz], [0, sy, 0])]
    others.append(([x0, sy, z1], [sx, 0, 0], [0, 0, -sz]))  # top, +y
    parts = [quad(c, u, v, 3, uv=black) for c, u, v in others]
    corner, u, v = face
    if split_material is None:
        parts.insert(0, quad(corner, u, v, 5, uv=screen_uv))
        return b.mesh("ScreenBox", parts, material)
    # The screen: s in [0.25, 0.75], t in [0.25, 0.75] of the face; four pieces around it.
    def piece(s0, s1, t0, t1, cu, cv):
        c = [corner[k] + s0 * u[k] + t0 * v[k] for k in range(3)]
        return quad(c, [(s1 - s0) * x for x in u], [(t1 - t0) * x for x in v], cu, cv)
    parts += [piece(0, 1, 0, 0.25, 4, 1), piece(0, 1, 0.75, 1, 4, 1), piece(0, 0.25, 0.25, 0.75, 1, 2),
              piece(0.75, 1, 0.25, 0.75, 1, 2)]
    b.mesh("ScreenBox", parts, material)
    b.mesh("Screen", [piece(0.25, 0.75, 0.25, 0.75, 3, 2)], split_material)


def standard_room_materials(b):
    white = b.material("White", WHITE)
    return {k: white for k in ("floor", "ceiling", "back", "front", "left", "right")}


def panel_material(b, strength):
    return b.material("Panel", WHITE, emission=[1.0, 1.0, 1.0], strength=strength)


# ---------------------------------------------------------------------------------------------
# The scenes

ROOM = (3.0, 2.4, 3.0)


def textured_floor(b, twin=False):
    # The floor's albedo is per texel: red on x < 0, blue on x > 0 (the texture's mean would be purple).
    mats = standard_room_materials(b)
    if twin:
        red = [FLOOR_FACTOR * srgb_to_linear(c) for c in RED_SRGB]
        blue = [FLOOR_FACTOR * srgb_to_linear(c) for c in BLUE_SRGB]
        room(b, ROOM, mats, floor_split=(b.material("FloorRed", red), b.material("FloorBlue", blue)))
    else:
        tex = b.texture("floor", 2, 1, [[RED_SRGB, BLUE_SRGB]], 3)
        mats["floor"] = b.material("Floor", [FLOOR_FACTOR] * 3, base_texture=tex)
        room(b, ROOM, mats)
    panel(b, ROOM[1], 0.8, panel_material(b, 10.0))
    b.camera([0, 1.6, 1.4], [0, 0.4, -0.6])


def vertex_colour(b, twin=False):
    # COLOR_0 multiplies the factor: the back wall blue (float VEC3), the left wall yellow (ubyte RGBA).
    mats = standard_room_materials(b)
    mats["floor"] = b.material("Grey", [0.5, 0.5, 0.5])
    if twin:
        mats["back"] = b.material("BackBlue", [0.8 * c for c in BLUE_COLOR_0])
        mats["left"] = b.material("LeftYellow", [c / 255 for c in YELLOW_COLOR_0[:3]])
        room(b, ROOM, mats)
    else:
        mats["left"] = b.material("WhiteOne", [1.0, 1.0, 1.0])
        room(b, ROOM, mats, colors={"back": ("float", BLUE_COLOR_0), "left": ("ubyte", YELLOW_COLOR_0)})
    panel(b, ROOM[1], 0.8, panel_material(b, 10.0))
    b.camera([0.8, 1.6, 1.4], [-0.3, 0.8, -1.0])


def alpha_mask(b, mode="MASK"):
    # A cut-out card of coverage 0.5 (MASK) or a card of alpha 0.5 (BLEND) between the panel and the floor;
    # doubleSided: its upper side, facing the panel, is its back. mode None: the room alone.
    room(b, ROOM, standard_room_materials(b))
    panel(b, ROOM[1], 0.8, panel_material(b, 10.0))
    if mode == "MASK":
        tex = checker_texture(b, "checker")
        card = b.material("MaskCard", CARD_FACTOR, base_texture=tex, alpha_mode="MASK", cutoff=0.5, double_sided=True)
        checker_card(b, "Card", card, (0.0, 0.0), 1.2)
    elif mode == "BLEND":
        card = b.material("BlendCard", CARD_FACTOR, alpha=0.5, alpha_mode="BLEND", double_sided=True)
        checker_card(b, "Card", card, (0.0, 0.0), 1.2)
    b.camera([1.2, 1.9, 1.4], [0, 0.6, 0])


def glass_window(b, pane=True):
    # Sky through a window closed by a thin pane: 0.9 of the light passes, tinted by the base colour.
    w, h, d = ROOM
    mats = standard_room_materials(b)
    # x+ wall: 15 cells along z (0.2 m), 12 up; the window: z in [-0.5, 0.5] (cells 5..9), y in [1.0, 1.8] (5..8).
    room(b, ROOM, mats, right_skip=lambda i, j: 5 <= i <= 9 and 5 <= j <= 8)
    if pane:
        glass = b.material("Glass", GLASS_TINT, transmission=0.9)
        b.mesh("Pane", [quad([w / 2, 1.0, -0.5], [0, 0, 1.0], [0, 0.8, 0], 5, 4)], glass)
    b.camera([-1.2, 1.5, 1.2], [1.5, 1.0, -0.3])


def emissive_texture(b, twin=False):
    # The box's emissive texture is black but for a small screen: only the screen emits.
    room(b, ROOM, standard_room_materials(b))
    if twin:
        box = b.material("Box", [0.5, 0.5, 0.5])
        screen = b.material("Screen", [0.5, 0.5, 0.5], emission=[1.0, 1.0, 1.0], strength=30.0)
        screen_box(b, box, (0.0, -0.3), split_material=screen)
    else:
        tex = screen_texture(b, "screen")
        box = b.material("ScreenBox", [0.5, 0.5, 0.5], emission=[1.0, 1.0, 1.0], strength=30.0, emissive_texture=tex)
        screen_box(b, box, (0.0, -0.3))
    b.camera([0.3, 1.5, 1.4], [0, 0.3, -0.3])


def materials_room(b):
    # Every feature together, lit by a panel and by the sky through the glass window.
    size = (4.0, 2.6, 3.4)
    w, h, d = size
    mats = standard_room_materials(b)
    floor_tex = b.texture("floor", 2, 1, [[RED_SRGB, BLUE_SRGB]], 3, wrap=REPEAT)
    # u' = 2 s + 0.25 along x: four stripes, edges at s = 1/8, 3/8, 5/8, 7/8 (21 cells: no vertex on them).
    mats["floor"] = b.material("Floor", [FLOOR_FACTOR] * 3, base_texture=floor_tex,
                               texture_transform={"scale": [2.0, 1.0], "offset": [0.25, 0.0]})
    mats["back"] = b.material("BackWall", WHITE)
    # x+ wall: 17 cells along z (0.2 m), 13 up; the window: cells 6..11 (z in [-0.5, 0.7]), rows 5..8 (y in [1, 1.8]).
    room(b, size, mats, colors={"back": ("float", BLUE_COLOR_0)},
         right_skip=lambda i, j: 6 <= i <= 11 and 5 <= j <= 8)
    glass = b.material("Glass", [0.85, 0.9, 0.95], transmission=0.9)
    b.mesh("Pane", [quad([w / 2, 1.0, -0.5], [0, 0, 1.2], [0, 0.8, 0], 6, 4)], glass)
    panel(b, h, 0.8, panel_material(b, 8.0), centre=(-0.6, 0.0))
    mask_tex = checker_texture(b, "checker")
    card = b.material("MaskCard", CARD_FACTOR, base_texture=mask_tex, alpha_mode="MASK", cutoff=0.5, double_sided=True)
    checker_card(b, "MaskCard", card, (-0.6, 0.0), 1.3)
    blend = b.material("BlendCard", [0.3, 0.7, 0.4], alpha=0.5, alpha_mode="BLEND")
    # A vertical card 0.3 m before the left wall, facing +x, 1.0 x 1.2 m, 7 x 9 cells.
    b.mesh("BlendCard", [quad([-w / 2 + 0.3, 0.3, 1.0], [0, 0, -1.0], [0, 1.2, 0], 7, 9)], blend)
    tex = screen_texture(b, "screen")
    box = b.material("ScreenBox", [0.5, 0.5, 0.5], emission=[1.0, 1.0, 1.0], strength=30.0, emissive_texture=tex)
    screen_box(b, box, (0.9, -0.6), facing=+1)
    b.camera([-1.5, 1.8, 1.5], [0.6, 0.5, -0.8])


def foliage(b, cards=3000, seed=7):
    """The benchmark's foliage (issue 57): `cards` double-sided alpha-MASK leaf cards (a 0.2 m quad
    whose 16 x 16 texture is an opaque disc, 0.79 of it; the rest cut out), scattered with random
    orientations over a 4 x 4 m ground at 0.3..2.3 m, under `--sky 1,1,1`. Written only when named
    (it is not one of the checks)."""
    import random
    rng = random.Random(seed)
    leaf = [[(60, 140, 50, 255 if (i - 7.5) ** 2 + (j - 7.5) ** 2 <= 64 else 0) for i in range(16)] for j in range(16)]
    texture = b.texture("leaf", 16, 16, leaf, 4)
    material = b.material("Leaf", [1.0, 1.0, 1.0], base_texture=texture, alpha_mode="MASK", cutoff=0.5, double_sided=True)
    ground = b.material("Ground", [0.5, 0.5, 0.5])
    b.mesh("Ground", [quad([-2, 0, 2], [4, 0, 0], [0, 0, -4], 20)], ground)
    parts = []
    for _ in range(cards):
        centre = [rng.uniform(-1.8, 1.8), rng.uniform(0.3, 2.3), rng.uniform(-1.8, 1.8)]
        # Two random perpendicular edges of 0.2 m.
        while True:
            a = [rng.gauss(0, 1) for _ in range(3)]
            norm = math.sqrt(sum(x * x for x in a))
            if norm > 1e-3:
                break
        a = [x / norm for x in a]
        helper = [0.0, 1.0, 0.0] if abs(a[1]) < 0.9 else [1.0, 0.0, 0.0]
        c = [a[1] * helper[2] - a[2] * helper[1], a[2] * helper[0] - a[0] * helper[2], a[0] * helper[1] - a[1] * helper[0]]
        norm = math.sqrt(sum(x * x for x in c))
        c = [x / norm for x in c]
        u = [0.2 * x for x in a]
        v = [0.2 * x for x in c]
        corner = [centre[k] - (u[k] + v[k]) / 2 for k in range(3)]
        parts.append(quad(corner, u, v, 1))
    b.mesh("Leaves", parts, material)
    b.camera([3.0, 2.0, 3.0], [0.0, 1.0, 0.0])


BENCHES = ["foliage"]

BUILDERS = {
    "textured_floor": textured_floor,
    "vertex_colour": vertex_colour,
    "alpha_mask": lambda b: alpha_mask(b, "MASK"),
    "alpha_blend": lambda b: alpha_mask(b, "BLEND"),
    "glass_window": glass_window,
    "emissive_texture": emissive_texture,
    "materials_room": materials_room,
    "textured_floor_factors": lambda b: textured_floor(b, twin=True),
    "vertex_colour_factors": lambda b: vertex_colour(b, twin=True),
    "card_room_nocard": lambda b: alpha_mask(b, None),
    "glass_window_open": lambda b: glass_window(b, pane=False),
    "emissive_texture_factors": lambda b: emissive_texture(b, twin=True),
    "foliage": foliage,
}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir", nargs="?")
    ap.add_argument("names", nargs="*", help="scenes to write (default: all; see --list)")
    ap.add_argument("--twins", action="store_true", help="also write the check twins (see above)")
    ap.add_argument("--list", action="store_true", help="print the scene names (and the twins') and exit")
    args = ap.parse_args()
    if args.list:
        print("\n".join(SCENES))
        print("\n".join("%s (--twins)" % t for t in TWINS))
        print("\n".join("%s (when named: a benchmark)" % t for t in BENCHES))
        return
    if not args.out_dir:
        ap.error("OUT_DIR is required")
    names = args.names or SCENES + (TWINS if args.twins else [])
    for name in names:
        if name not in BUILDERS:
            ap.error("unknown scene %r (--list names them)" % name)
    os.makedirs(args.out_dir, exist_ok=True)
    for name in names:
        b = SceneBuilder(args.out_dir, name)
        BUILDERS[name](b)
        b.write()
        vertices = sum(a["count"] for m in b.doc["meshes"] for p in m["primitives"]
                       for a in [b.doc["accessors"][p["attributes"]["POSITION"]]])
        print("%s: %d vertices" % (os.path.join(args.out_dir, name + ".gltf"), vertices))


if __name__ == "__main__":
    main()
