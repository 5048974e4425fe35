#!/usr/bin/env python3
"""Writes the hand-made test inputs of tests/data: hostile files that qsgi must refuse
(bad/gltf, bad/animation, bad/config, bad/ply) and valid edge cases that it must load (good/).

Each bad file breaks one rule; bad/generated.tsv lists it with the words its error message must
contain. Files found by fuzzing are added by hand to bad/<kind>/ and listed in bad/found.tsv.
Run from anywhere: python3 tests/data/make_inputs.py (the output is deterministic)."""
import base64
import copy
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
rows = []  # (kind, relative path, expected words, the file the message names)


def b64(data):
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


# A 2 m floor quad (4 vertices, 2 triangles) and a point light 1 m above it.
POS = struct.pack("<12f", -1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1)
NRM = struct.pack("<12f", *([0, 1, 0] * 4))
IDX = struct.pack("<6H", 0, 1, 2, 0, 2, 3)


def scene(positions=POS, indices=IDX, normals=None):
    data = positions + indices
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": len(positions)},
             {"buffer": 0, "byteOffset": len(positions), "byteLength": len(indices)}]
    attributes = {"POSITION": 0}
    accessors = [{"bufferView": 0, "componentType": 5126, "count": len(positions) // 12, "type": "VEC3",
                  "min": [-1, 0, -1], "max": [1, 0, 1]},
                 {"bufferView": 1, "componentType": 5123, "count": len(indices) // 2, "type": "SCALAR"}]
    if normals is not None:
        while len(data) % 4:
            data += b"\0"
        views.append({"buffer": 0, "byteOffset": len(data), "byteLength": len(normals)})
        data += normals
        accessors.append({"bufferView": 2, "componentType": 5126, "count": len(normals) // 12, "type": "VEC3"})
        attributes["NORMAL"] = 2
    return {
        "asset": {"version": "2.0", "generator": "qsgi tests/data/make_inputs.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "Bulb", "type": "point", "intensity": 10}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"name": "Floor", "mesh": 0},
                  {"name": "Lamp", "translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}}],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": 1}]}],
        "buffers": [{"byteLength": len(data), "uri": b64(data)}],
        "bufferViews": views,
        "accessors": accessors,
    }


def write(rel, content):
    path = os.path.join(HERE, rel)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(path, mode) as f:
        f.write(content)


def bad(kind, name, content, words, names=None):
    rel = f"bad/{kind}/{name}"
    if isinstance(content, dict) or isinstance(content, list):
        content = json.dumps(content, indent=1)
    write(rel, content)
    rows.append((kind, rel, words, names or name))


def edited(edit, base=None):
    m = copy.deepcopy(base or scene())
    edit(m)
    return m


def glb(doc, binary):
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks


def png(width, height, rgb_rows):
    """An 8-bit RGB PNG (no filter, one IDAT), so the tests need no image library to make one. The
    header may claim more rows than rgb_rows holds (a truncated or hostile file)."""
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
    raw = b"".join(b"\0" + bytes(row) for row in rgb_rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


# The 2 x 2 texture of good/texture_*.gltf; hostile_input_test.cpp expects its mean linear colour.
TEXTURE_PIXELS = [[255, 0, 0, 0, 255, 0], [0, 0, 255, 128, 128, 128]]


def textured(embedded):
    """The floor with a base colour texture: embedded in the buffer (a bufferView) or as a data
    URI, beside a second image that is garbage and that no material uses."""
    m = scene()
    image = png(2, 2, TEXTURE_PIXELS)
    data = POS + IDX + b"\0" * (-len(POS + IDX) % 4)
    garbage_at = len(data)
    data += b"not an image at all"
    if embedded:
        image_at = len(data)
        data += image
        images = [{"bufferView": 3, "mimeType": "image/png"}]
        m["bufferViews"].append({"buffer": 0, "byteOffset": image_at, "byteLength": len(image)})
    else:
        images = [{"uri": "data:image/png;base64," + base64.b64encode(image).decode()}]
    m["bufferViews"].insert(2, {"buffer": 0, "byteOffset": garbage_at, "byteLength": 19})
    images.append({"bufferView": 2, "mimeType": "image/png"})
    # The texture coordinates the texture reads (glTF requires the TEXCOORD_n it names).
    data += b"\0" * (-len(data) % 4)
    m["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": 32})
    data += struct.pack("<8f", 0, 0, 1, 0, 1, 1, 0, 1)
    m["accessors"].append({"bufferView": len(m["bufferViews"]) - 1, "componentType": 5126, "count": 4, "type": "VEC2"})
    m["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = len(m["accessors"]) - 1
    m["buffers"][0] = {"byteLength": len(data), "uri": b64(data)}
    m.update(images=images, textures=[{"source": 0}, {"source": 1}],
             materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [1, 1, 1, 1]}}])
    m["meshes"][0]["primitives"][0]["material"] = 0
    return m


# ---- valid edge cases (good/) ----
write("good/base.gltf", json.dumps(scene(normals=NRM), indent=1))

# An accessor without a bufferView is all zeros, here overridden by sparse values: the floor.
m = scene()
sparse_idx = struct.pack("<4B", 0, 1, 2, 3)
m["buffers"][0] = {"byteLength": len(IDX) + 4 + len(POS), "uri": b64(IDX + sparse_idx + POS)}
m["bufferViews"] = [{"buffer": 0, "byteOffset": 0, "byteLength": len(IDX)},
                    {"buffer": 0, "byteOffset": 12, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 16, "byteLength": len(POS)}]
m["accessors"] = [{"componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1],
                   "sparse": {"count": 4, "indices": {"bufferView": 1, "componentType": 5121},
                              "values": {"bufferView": 2}}},
                  {"bufferView": 0, "componentType": 5123, "count": 6, "type": "SCALAR"}]
write("good/accessor_without_bufferview.gltf", json.dumps(m, indent=1))

m = scene()
m["buffers"][0]["uri"] = m["buffers"][0]["uri"].replace("application/octet-stream", "application/gltf-buffer")
write("good/buffer_gltf_buffer_data_uri.gltf", json.dumps(m, indent=1))

m = scene()
m["buffers"].append({"byteLength": 1024, "name": "nothing reads this"})
write("good/buffer_without_uri_unused.gltf", json.dumps(m, indent=1))

# KHR_mesh_quantization: positions as normalized shorts scaled back by the node, normals as bytes.
qpos = struct.pack("<16h", -32767, 0, 32767, 0, 32767, 0, 32767, 0, 32767, 0, -32767, 0, -32767, 0, -32767, 0)
qnrm = struct.pack("<16b", *([0, 127, 0, 0] * 4))
m = scene(positions=qpos + qnrm)
m["extensionsUsed"].append("KHR_mesh_quantization")
m["extensionsRequired"] = ["KHR_mesh_quantization"]
m["bufferViews"][0] = {"buffer": 0, "byteOffset": 0, "byteLength": 32, "byteStride": 8}
m["bufferViews"].append({"buffer": 0, "byteOffset": 32, "byteLength": 16, "byteStride": 4})
# min and max in the components' own (raw) values, as glTF requires.
m["accessors"][0].update({"componentType": 5122, "normalized": True, "count": 4,
                          "min": [-32767, 0, -32767], "max": [32767, 0, 32767]})
m["accessors"].append({"bufferView": 2, "componentType": 5120, "normalized": True, "count": 4, "type": "VEC3"})
m["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 2
m["nodes"][0]["scale"] = [1, 1, 1]
write("good/quantized.gltf", json.dumps(m, indent=1))

# A GLB whose second buffer has no uri (only buffer 0 may be the BIN chunk) and is never read.
m = scene()
m["buffers"] = [{"byteLength": len(POS + IDX)}, {"byteLength": 64}]
write("good/glb_with_unused_second_buffer.glb", glb(m, POS + IDX))

write("good/texture_embedded.gltf", json.dumps(textured(True), indent=1))
write("good/texture_data_uri.gltf", json.dumps(textured(False), indent=1))

# Base colour textures that cannot be read render with their material's factor and a warning each:
# a header claiming 30000 x 30000 pixels (skipped before decoding), a PNG cut in half, garbage.
m = textured(True)
whole = png(2, 2, TEXTURE_PIXELS)
unreadable = [png(30000, 30000, [[7] * 90000]), whole[:len(whole) // 2], b"GIF89a and then nothing"]
data = base64.b64decode(m["buffers"][0]["uri"].split(",")[1])
for i, image in enumerate(unreadable):
    data += b"\0" * (-len(data) % 4)
    m["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": len(image)})
    data += image
    m["images"][i:i + 1] = [{"bufferView": len(m["bufferViews"]) - 1, "mimeType": "image/png"}]
m["buffers"][0] = {"byteLength": len(data), "uri": b64(data)}
m["textures"] = [{"source": 0}, {"source": 1}, {"source": 2}]
m["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": i}, "baseColorFactor": [0.5, 0.25, 1, 1]}}
                  for i in range(3)]
write("good/texture_unreadable.gltf", json.dumps(m, indent=1))


def png_file(width, height, scanlines, depth=8, colour=2, interlace=0, compression=0, filter_method=0,
             plte=None, ihdr_crc=None, idat=None):
    """A PNG from its raw scanlines (each with its filter byte), any IHDR values, an optional PLTE,
    a wrong IHDR CRC or IDAT bytes of one's own: a valid file or one hostile to a decoder."""
    def chunk(kind, data, crc=None):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) if crc is None else crc)
    ihdr = struct.pack(">IIBBBBB", width, height, depth, colour, compression, filter_method, interlace)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr, ihdr_crc) + (chunk(b"PLTE", plte) if plte else b"") +
            chunk(b"IDAT", zlib.compress(scanlines) if idat is None else idat) + chunk(b"IEND", b""))


def adam7(width, height, pixel):
    """The raw scanlines of an interlaced 8-bit RGB image: Adam7's seven passes, each row with filter 0."""
    passes = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
    raw = b""
    for x0, y0, dx, dy in passes:
        xs = range(x0, width, dx)
        if not xs:
            continue
        for y in range(y0, height, dy):
            raw += b"\0" + b"".join(bytes(pixel(x, y)) for x in xs)
    return raw


def images_scene(images, factor):
    """The floor with one material per image (embedded in buffer views), each base colour texture
    over `factor`; the primitive uses material 0, and every material's texture is decoded."""
    m = textured(True)
    data = base64.b64decode(m["buffers"][0]["uri"].split(",")[1])
    m["images"], m["textures"], m["materials"] = [], [], []
    for i, image in enumerate(images):
        data += b"\0" * (-len(data) % 4)
        m["bufferViews"].append({"buffer": 0, "byteOffset": len(data), "byteLength": len(image)})
        data += image
        m["images"].append({"bufferView": len(m["bufferViews"]) - 1, "mimeType": "image/png"})
        m["textures"].append({"source": i})
        m["materials"].append({"pbrMetallicRoughness": {"baseColorTexture": {"index": i}, "baseColorFactor": factor}})
    m["buffers"][0] = {"byteLength": len(data), "uri": b64(data)}
    return m


# PNGs that libpng refuses: each leaves its material's factor with a warning in qsgi's words, and
# nothing is printed by a library (hostile_input_test.cpp, texture_colour_test.cpp).
rgb_row = b"\0" + bytes([200, 100, 50] * 2)
valid_idat = zlib.compress(rgb_row * 2)
HOSTILE_PNGS = [
    ("0 x 0 pixels", png_file(0, 0, b"")),
    ("colour type 3 with bit depth 16", png_file(2, 2, rgb_row * 2, depth=16, colour=3, plte=bytes(6))),
    ("colour type 5", png_file(2, 2, rgb_row * 2, colour=5)),
    ("interlace method 2", png_file(2, 2, rgb_row * 2, interlace=2)),
    ("compression method 1", png_file(2, 2, rgb_row * 2, compression=1)),
    ("filter method 1", png_file(2, 2, rgb_row * 2, filter_method=1)),
    ("2147483648 x 1 pixels", png_file(2**31, 1, rgb_row)),
    ("corrupt PNG (libpng: IHDR: CRC error)", png_file(2, 2, rgb_row * 2, ihdr_crc=0)),
    ("corrupt PNG", png_file(2, 2, b"", idat=b"\x78\x9c not a deflate stream")),
    ("corrupt PNG", png_file(2, 2, b"\x05" + rgb_row[1:] + rgb_row)),   # filter type 5 does not exist
    ("corrupt PNG", png_file(2, 2, b"\0\0" * 2, depth=8, colour=3)),     # a palette image without PLTE
    ("corrupt PNG", png_file(2, 4, rgb_row * 2)),                         # two rows of the four it declares
    ("truncated PNG", png_file(2, 2, rgb_row * 2)[:40]),
]
write("good/texture_png_hostile.gltf",
      json.dumps(images_scene([image for _, image in HOSTILE_PNGS], [0.5, 0.25, 1, 1]), indent=1))
write("good/texture_png_hostile.tsv", "# material\twords its warning must contain (written by make_inputs.py)\n" +
      "".join(f"{i}\t{words}\n" for i, (words, _) in enumerate(HOSTILE_PNGS)))
# Valid PNGs a decoder may mishandle, each over a factor of 1, their means worked out in
# texture_colour_test.cpp: Adam7-interlaced 5 x 3 RGB, value (x * 37 + y * 11 + c * 50) % 256; a
# row of 1,100,000 grey pixels of 128, wider than libpng's default limit of 10^6.
write("good/texture_png_variants.gltf", json.dumps(images_scene([
    png_file(5, 3, adam7(5, 3, lambda x, y: [(x * 37 + y * 11 + c * 50) % 256 for c in range(3)]), interlace=1),
    png_file(1100000, 1, b"\0" + bytes([128]) * 1100000, colour=0),
], [1, 1, 1, 1]), indent=1))

# ---- glTF files that break the specification (bad/gltf) ----
def accessor(i, **kw):
    return lambda m: m["accessors"][i].update(kw)


bad("gltf", "asset_version_3.gltf", edited(lambda m: m["asset"].update(version="3.0")), "asset.version")
bad("gltf", "asset_missing.gltf", edited(lambda m: m.pop("asset")), "asset")
bad("gltf", "asset_version_missing.gltf", edited(lambda m: m["asset"].pop("version")), "asset.version")
bad("gltf", "asset_version_words.gltf", edited(lambda m: m["asset"].update(version="two")), "major.minor")
bad("gltf", "asset_min_version_2_1.gltf", edited(lambda m: m["asset"].update(minVersion="2.1")), "minVersion")
short_pos = struct.pack("<12h", -1, 0, 1, 1, 0, 1, 1, 0, -1, -1, 0, -1)
bad("gltf", "position_short_without_quantization.gltf",
    edited(accessor(0, componentType=5122), scene(positions=short_pos + b"\0" * 24)), "KHR_mesh_quantization")
bad("gltf", "position_unsigned_int.gltf", edited(accessor(0, componentType=5125)), "UNSIGNED_INT")
bad("gltf", "position_vec2.gltf", edited(accessor(0, type="VEC2")), "VEC3")
bad("gltf", "position_float_normalized.gltf", edited(accessor(0, normalized=True)), "8- and 16-bit integers only")
bad("gltf", "quantization_used_but_not_required.gltf",
    edited(lambda m: (m["extensionsUsed"].append("KHR_mesh_quantization"), accessor(0, componentType=5122)(m)),
           scene(positions=short_pos + b"\0" * 24)), "extensionsRequired")
def ubyte_normals(m):
    m["extensionsUsed"].append("KHR_mesh_quantization")
    m["extensionsRequired"] = ["KHR_mesh_quantization"]
    m["accessors"][2].update(componentType=5121, normalized=True)
bad("gltf", "normal_unsigned_byte_quantized.gltf", edited(ubyte_normals, scene(normals=NRM)), "not allowed")
bad("gltf", "indices_float.gltf", edited(accessor(1, componentType=5126, count=3)), "not allowed")
bad("gltf", "indices_normalized.gltf", edited(accessor(1, normalized=True)), "not allowed")
bad("gltf", "indices_vec3.gltf", edited(accessor(1, type="VEC3", count=2)), "SCALAR")
bad("gltf", "index_beyond_vertices.gltf", scene(indices=struct.pack("<6H", 0, 1, 2, 0, 2, 4)), "beyond")
bad("gltf", "index_primitive_restart.gltf", scene(indices=struct.pack("<6H", 0, 1, 2, 0, 2, 65535)), "primitive-restart")
bad("gltf", "view_past_buffer.gltf", edited(lambda m: m["bufferViews"][1].update(byteLength=40)), "reaches byte")
bad("gltf", "view_offset_wraps_around.gltf",
    edited(lambda m: m["bufferViews"][1].update(byteOffset=2**64 - 8)), "reaches byte")
bad("gltf", "texture_view_past_buffer.gltf",
    edited(lambda m: m["bufferViews"][3].update(byteOffset=2**62), textured(True)), "reaches byte")
bad("gltf", "view_missing_buffer.gltf", edited(lambda m: m["bufferViews"][1].update(buffer=7)), "buffer")
bad("gltf", "stride_smaller_than_element.gltf", edited(lambda m: m["bufferViews"][0].update(byteStride=8)), "smaller than")
bad("gltf", "stride_not_multiple_of_4.gltf", edited(lambda m: m["bufferViews"][0].update(byteStride=14)), "multiple of 4")
bad("gltf", "stride_over_252.gltf", edited(lambda m: m["bufferViews"][0].update(byteStride=256)), "byteStride")
bad("gltf", "accessor_misaligned.gltf", edited(accessor(0, byteOffset=2, count=3)), "byteOffset")
bad("gltf", "accessor_past_view.gltf", edited(accessor(0, count=5)), "past the end")
bad("gltf", "accessor_missing.gltf",
    edited(lambda m: m["meshes"][0]["primitives"][0]["attributes"].update(POSITION=9)), "does not exist")
bad("gltf", "accessor_huge_without_view.gltf",
    edited(lambda m: m["accessors"].append({"componentType": 5126, "count": 2**40, "type": "VEC3"})
           or m["meshes"][0]["primitives"][0]["attributes"].update(POSITION=2)), "would need")
nan_pos = struct.pack("<12f", -1, 0, 1, 1, float("nan"), 1, 1, 0, -1, -1, 0, -1)
bad("gltf", "positions_nan.gltf", scene(positions=nan_pos), "non-finite")
inf_pos = struct.pack("<12f", -1, 0, 1, 1, 0, float("inf"), 1, 0, -1, -1, 0, -1)
bad("gltf", "positions_inf.gltf", scene(positions=inf_pos), "non-finite")
bad("gltf", "matrix_overflow.gltf",
    json.dumps(scene()).replace('"name": "Floor"', '"name": "Floor", "matrix": [1e999,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]'),
    "JSON")
def sparse(edit):
    def f(m):
        m["buffers"][0] = {"byteLength": len(POS + IDX) + 4, "uri": b64(POS + IDX + struct.pack("<4B", *edit))}
        m["bufferViews"].append({"buffer": 0, "byteOffset": 60, "byteLength": 4})
        m["accessors"][0]["sparse"] = {"count": 2, "indices": {"bufferView": 2, "componentType": 5121},
                                       "values": {"bufferView": 0}}
    return f
bad("gltf", "sparse_index_beyond_count.gltf", edited(sparse([0, 9, 0, 0])), "beyond the accessor")
bad("gltf", "sparse_indices_not_increasing.gltf", edited(sparse([2, 1, 0, 0])), "strictly increase")
# Issue 23: negative offsets, which tinygltf took as 0 in one place and read before the view in another.
bad("gltf", "accessor_negative_offset.gltf", edited(accessor(0, byteOffset=-12)), "accessors[0].byteOffset")
bad("gltf", "sparse_values_negative_offset.gltf",
    edited(lambda m: (sparse([0, 1, 0, 0])(m), m["accessors"][0]["sparse"]["values"].update(byteOffset=-24))),
    "accessors[0].sparse.values.byteOffset")
bad("gltf", "view_negative_offset.gltf", edited(lambda m: m["bufferViews"][1].update(byteOffset=-4)), "bufferViews[1].byteOffset")
bad("gltf", "child_negative.gltf", edited(lambda m: m["nodes"][0].update(children=[-1])), "nodes[0].children[0]")
IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
bad("gltf", "node_matrix_and_translation.gltf",
    edited(lambda m: m["nodes"][0].update(matrix=IDENTITY, translation=[0, 1, 0])), "both a matrix and")
bad("gltf", "triangles_remainder.gltf", scene(indices=struct.pack("<8H", 0, 1, 2, 0, 2, 3, 0, 1)), "not a multiple of 3")
bad("gltf", "node_rotation_zero.gltf", edited(lambda m: m["nodes"][0].update(rotation=[0, 0, 0, 0])), "zero quaternion")
bad("gltf", "node_matrix_sheared.gltf",
    edited(lambda m: m["nodes"][0].update(matrix=[1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])), "shears")
bad("gltf", "node_matrix_projective.gltf",
    edited(lambda m: m["nodes"][0].update(matrix=[1, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])), "last row")
bad("gltf", "attribute_lengths_differ.gltf", edited(accessor(2, count=3), scene(normals=NRM)), "equal lengths")
bad("gltf", "node_two_parents.gltf",
    edited(lambda m: m["nodes"].extend([{"children": [0]}, {"children": [0]}]) or m["scenes"][0].update(nodes=[1, 2, 3])),
    "two parents")
bad("gltf", "node_cycle.gltf",
    edited(lambda m: m["nodes"].extend([{"children": [3]}, {"children": [2]}]) or m["scenes"][0].update(nodes=[0, 1])),
    "cycle")
bad("gltf", "node_own_child.gltf", edited(lambda m: m["nodes"][0].update(children=[0])), "cycle")
bad("gltf", "node_duplicate_child.gltf",
    edited(lambda m: m["nodes"].append({"children": [0, 0]}) or m["scenes"][0].update(nodes=[2, 1])), "twice")
bad("gltf", "node_root_is_a_child.gltf",
    edited(lambda m: m["nodes"].append({"children": [0]}) or m["scenes"][0].update(nodes=[0, 1, 2])), "not a root")
bad("gltf", "node_missing_child.gltf", edited(lambda m: m["nodes"][0].update(children=[12])), "does not exist")
bad("gltf", "node_missing_mesh.gltf", edited(lambda m: m["nodes"][0].update(mesh=3)), "does not exist")
bad("gltf", "material_missing.gltf", edited(lambda m: m["meshes"][0]["primitives"][0].update(material=4)), "does not exist")
bad("gltf", "scene_missing.gltf", edited(lambda m: m.update(scene=4)), "does not exist")
bad("gltf", "scenes_absent.gltf", edited(lambda m: m.pop("scenes") and m.pop("scene")), "no scene")
bad("gltf", "points_only.gltf", edited(lambda m: m["meshes"][0]["primitives"][0].update(mode=0)), "no triangles")
bad("gltf", "extension_required_draco.gltf",
    edited(lambda m: m.update(extensionsUsed=["KHR_lights_punctual", "KHR_draco_mesh_compression"],
                              extensionsRequired=["KHR_draco_mesh_compression"])), "KHR_draco_mesh_compression")
bad("gltf", "remote_buffer.gltf", edited(lambda m: m["buffers"][0].update(uri="https://example.com/floor.bin")),
    "local files only")
bad("gltf", "remote_image.gltf",
    edited(lambda m: m.update(images=[{"uri": "http://example.com/wood.png"}], textures=[{"source": 0}],
                              materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])),
    "local files only")
bad("gltf", "buffer_without_uri_read.gltf",
    edited(lambda m: m["buffers"].append({"byteLength": 48}) or m["bufferViews"][0].update(buffer=1)), "no uri")
bad("gltf", "buffer_data_uri_wrong_length.gltf", edited(lambda m: m["buffers"][0].update(byteLength=100)), "uri")
bad("gltf", "light_negative_intensity.gltf",
    edited(lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(intensity=-5)), "non-negative")
bad("gltf", "light_unknown_type.gltf",
    edited(lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(type="area")), "unknown light type")
bad("gltf", "light_missing.gltf",
    edited(lambda m: m["nodes"][1]["extensions"]["KHR_lights_punctual"].update(light=3)), "does not exist")
bad("gltf", "spot_cone_too_wide.gltf",
    edited(lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(
        type="spot", spot={"innerConeAngle": 0.1, "outerConeAngle": 2.0})), "outerConeAngle")
bad("gltf", "light_colour_above_one.gltf",
    edited(lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(color=[2, 1, 1])), "color")
bad("gltf", "base_colour_above_one.gltf",
    edited(lambda m: m.update(materials=[{"pbrMetallicRoughness": {"baseColorFactor": [1.5, 0.5, 0.5, 1]}}])
           or m["meshes"][0]["primitives"][0].update(material=0)), "baseColorFactor")
# Materials as the asset says them (issue 57): the values glTF bounds, refused where a rendered
# primitive uses them.
def material_edit(material):
    return edited(lambda m: m.update(materials=[material]) or m["meshes"][0]["primitives"][0].update(material=0))
bad("gltf", "alpha_cutoff_negative.gltf", material_edit({"alphaMode": "MASK", "alphaCutoff": -0.5}), "alphaCutoff")
bad("gltf", "alpha_mode_unknown.gltf", material_edit({"alphaMode": "CLIP"}), "alphaMode")
bad("gltf", "base_colour_alpha_above_one.gltf", material_edit({"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 2]}}),
    "baseColorFactor")
bad("gltf", "transmission_above_one.gltf",
    edited(lambda m: m.update(materials=[{"extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.5}}}],
                              extensionsUsed=m.get("extensionsUsed", []) + ["KHR_materials_transmission"])
           or m["meshes"][0]["primitives"][0].update(material=0)), "transmissionFactor")
bad("gltf", "transmission_texture_without_texcoord.gltf",
    edited(lambda m: m.update(materials=[{"extensions": {"KHR_materials_transmission": {
        "transmissionFactor": 0.5, "transmissionTexture": {"index": 0, "texCoord": 3}}}}],
        extensionsUsed=m.get("extensionsUsed", []) + ["KHR_materials_transmission"])
           or m["meshes"][0]["primitives"][0].update(material=0), base=textured(True)), "TEXCOORD_3")
bad("gltf", "texture_transform_offset_not_finite.gltf",
    edited(lambda m: m["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"].update(
        extensions={"KHR_texture_transform": {"offset": [0.5, "x"]}}), base=textured(True)), "offset")
bad("gltf", "index_view_with_stride.gltf", edited(lambda m: m["bufferViews"][1].update(byteStride=4)), "byteStride")
bad("gltf", "mesh_without_primitives.gltf", edited(lambda m: m["meshes"].append({"primitives": []})
                                                   or m["nodes"][0].update(mesh=1)), "at least one primitive")
bad("gltf", "position_without_bounds.gltf", edited(lambda m: m["accessors"][0].pop("min")), "without min and max")
bad("gltf", "required_extension_not_used.gltf",
    edited(lambda m: m.update(extensionsRequired=["KHR_materials_emissive_strength"])), "not listed in extensionsUsed")
bad("gltf", "spot_inner_not_below_outer.gltf",
    edited(lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(
        type="spot", spot={"innerConeAngle": 0.8, "outerConeAngle": 0.8})), "innerConeAngle")
bad("gltf", "camera_zfar_before_znear.gltf",
    edited(lambda m: m.update(cameras=[{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.5, "zfar": 0.1}}])
           or m["nodes"].append({"camera": 0}) or m["scenes"][0]["nodes"].append(2)), "zfar")
bad("gltf", "camera_zero_yfov.gltf",
    edited(lambda m: m.update(cameras=[{"type": "perspective", "perspective": {"yfov": 0, "znear": 0.1}}])
           or m["nodes"].append({"camera": 0}) or m["scenes"][0]["nodes"].append(2)), "yfov")
bad("gltf", "emissive_strength_negative.gltf",
    edited(lambda m: m.update(materials=[{"emissiveFactor": [1, 1, 1], "extensions": {
        "KHR_materials_emissive_strength": {"emissiveStrength": -2}}}]) or
        m["meshes"][0]["primitives"][0].update(material=0)), "emissiveStrength")
bad("gltf", "no_lights.gltf", edited(lambda m: m["nodes"][1].pop("extensions")), "no lights")
bad("gltf", "empty.gltf", "", "not valid JSON")
bad("gltf", "json_array.gltf", "[]", "object")
bad("gltf", "binary_noise.gltf", bytes((i * 73 + 41) % 256 for i in range(512)), "not valid JSON")
good_glb = glb(scene(), POS + IDX)
bad("gltf", "glb_truncated.glb", good_glb[:-8], "declares")
bad("gltf", "glb_container_version_1.glb", good_glb[:4] + struct.pack("<I", 1) + good_glb[8:], "container version")
bad("gltf", "glb_too_short.glb", good_glb[:14], "too short")
bad("gltf", "glb_json_chunk_overrun.glb", good_glb[:12] + struct.pack("<I", 1 << 20) + good_glb[16:], "runs past")
glb_doc = scene()
glb_doc["buffers"] = [{"byteLength": 4096}]
bad("gltf", "glb_buffer_longer_than_bin.glb", glb(glb_doc, POS + IDX), "byteLength")
def glb_unaligned_bin():
    doc = scene()
    doc["buffers"] = [{"byteLength": len(POS + IDX) - 2}]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary = (POS + IDX)[:-2]  # 58 bytes: not padded to a multiple of 4
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(chunks)) + chunks
bad("gltf", "glb_chunk_not_aligned.glb", glb_unaligned_bin(), "not a multiple of 4")


# Rules of glTF 2.0 the render reads (issue 23): in the rendered floor, each one refused naming it.
def with_extra_attribute(name, values, kind="VEC3", component=5126, target=None):
    """The floor with one more attribute (4 elements of `values` packed as floats) in a new buffer."""
    def edit(m):
        data = struct.pack("<%df" % len(values), *values)
        m["buffers"].append({"byteLength": len(data), "uri": b64(data)})
        m["bufferViews"].append({"buffer": len(m["buffers"]) - 1, "byteOffset": 0, "byteLength": len(data)})
        m["accessors"].append({"bufferView": len(m["bufferViews"]) - 1, "componentType": component, "count": 4,
                               "type": kind})
        prim = m["meshes"][0]["primitives"][0]
        if target is None:
            prim["attributes"][name] = len(m["accessors"]) - 1
        else:
            prim["targets"] = [{name: len(m["accessors"]) - 1}]
    return edit
bad("gltf", "position_bounds_wrong.gltf", edited(accessor(0, max=[1, 0, 2])), "exact bounds", "accessors[0].max")
bad("gltf", "attribute_unknown_name.gltf", edited(with_extra_attribute("FOO", [0] * 12)), "no attribute glTF defines")
bad("gltf", "attribute_texcoord_gap.gltf", edited(with_extra_attribute("TEXCOORD_1", [0] * 8, "VEC2")), "TEXCOORD_1 without")
bad("gltf", "morph_target_without_base.gltf", edited(with_extra_attribute("NORMAL", [0] * 12, target=True)),
    "morphs an attribute the primitive does not have")
bad("gltf", "color_above_one.gltf", edited(with_extra_attribute("COLOR_0", [1, 1, 1, 2, 0, 0, 0, 0, 0, 0, 0, 0])),
    "outside [0, 1]", "COLOR_0")
bad("gltf", "normal_not_unit.gltf", edited(with_extra_attribute("NORMAL", [0, 2, 0] * 4)), "not 1 (glTF requires unit normals)")
bad("gltf", "node_rotation_not_unit.gltf", edited(lambda m: m["nodes"][0].update(rotation=[0, 0, 0, 2])), "not 1", "nodes[0].rotation")
bad("gltf", "camera_two_projections.gltf", edited(lambda m: (
    m.update(cameras=[{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1},
                       "orthographic": {"xmag": 1, "ymag": 1, "znear": 0, "zfar": 1}}]),
    m["nodes"][1].update(camera=0))), "only the projection its type names", "cameras[0].orthographic")
bad("gltf", "node_weights_without_mesh.gltf", edited(lambda m: m["nodes"][1].update(weights=[0.5])), "without a mesh")
bad("gltf", "material_texture_missing.gltf", edited(lambda m: (
    m.update(materials=[{"emissiveTexture": {"index": 3}}]),
    m["meshes"][0]["primitives"][0].update(material=0))), "does not exist", "materials[0].emissiveTexture.index")
bad("gltf", "node_children_empty.gltf", edited(lambda m: m["nodes"][0].update(children=[])), "empty array", "nodes[0].children")
# KHR_texture_transform's texCoord overrides the textureInfo's: the set it names must exist, as
# for texCoord itself; and a light's range, where given, is positive (exclusiveMinimum 0).
def transform_texcoord(texture, value):
    def edit(m):
        info = {"index": 0, "extensions": {"KHR_texture_transform": {"texCoord": value, "scale": [2, 2]}}}
        if texture == "baseColorTexture":
            m["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = info
        else:
            m["materials"][0][texture] = info
        m["extensionsUsed"].append("KHR_texture_transform")
    return edit
bad("gltf", "texture_transform_texcoord_missing.gltf", edited(transform_texcoord("baseColorTexture", 1), textured(True)),
    "has no TEXCOORD_1, which materials[0].pbrMetallicRoughness.baseColorTexture.extensions.KHR_texture_transform.texCoord reads")
bad("gltf", "texture_transform_texcoord_missing_on_normal_map.gltf", edited(transform_texcoord("normalTexture", 3), textured(True)),
    "has no TEXCOORD_3, which materials[0].normalTexture.extensions.KHR_texture_transform.texCoord reads")
bad("gltf", "texture_transform_texcoord_negative.gltf", edited(transform_texcoord("baseColorTexture", -1), textured(True)),
    "KHR_texture_transform.texCoord: must be a non-negative integer")
bad("gltf", "texture_transform_texcoord_fraction.gltf", edited(transform_texcoord("emissiveTexture", 0.5), textured(True)),
    "materials[0].emissiveTexture.extensions.KHR_texture_transform.texCoord: must be a non-negative integer")
def light(**kw):
    return lambda m: m["extensions"]["KHR_lights_punctual"]["lights"][0].update(kw)
bad("gltf", "light_range_zero.gltf", edited(light(range=0)), "KHR_lights_punctual.lights[0].range: is 0; a light's range must be a positive number")
bad("gltf", "light_range_negative.gltf", edited(light(range=-2.5)), "KHR_lights_punctual.lights[0].range: is -2.5")
bad("gltf", "light_range_string.gltf", edited(light(range="10")), 'KHR_lights_punctual.lights[0].range: is "10"')
bad("gltf", "buffer_uri_directory.gltf", edited(lambda m: m["buffers"][0].update(uri=".")),
    "buffers[0].uri: '.' names a directory, not a file")
bad("gltf", "buffer_uri_missing_file.gltf", edited(lambda m: m["buffers"][0].update(uri="no-such.bin")),
    "buffers[0].uri: 'no-such.bin' names no file")

# Valid glTF that tinygltf alone refuses or that looks odd (issue 23): each loads as the floor.
m = scene()
m["bufferViews"][0]["byteLength"] = float(m["bufferViews"][0]["byteLength"])  # 48.0 is the integer 48
write("good/integer_written_as_float.gltf", json.dumps(m, indent=1))
m = scene()
m["buffers"][0]["uri"] = "data:application/gltf-buffer," + "".join("%%%02X" % b for b in POS + IDX)  # RFC 2397, not base64
write("good/data_uri_percent_encoded.gltf", json.dumps(m, indent=1))
trailing = glb(scene(), POS + IDX) + b"\0\0\0\0"  # bytes past the declared length: ignored with a warning
write("good/glb_trailing_bytes.glb", trailing)
m = scene()
m["meshes"][0]["primitives"].append({"attributes": {}})  # no POSITION: skipped, as glTF asks
write("good/primitive_without_position.gltf", json.dumps(m, indent=1))
# A light with a range and a texture whose KHR_texture_transform reads TEXCOORD_1, which exists.
m = edited(lambda m: with_extra_attribute("TEXCOORD_1", [0] * 8, "VEC2")(m), textured(True))
transform_texcoord("baseColorTexture", 1)(m)
m["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = 5
write("good/light_range_and_texture_transform.gltf", json.dumps(m, indent=1))

# ---- transform files (bad/animation), rendered with good/base.gltf ----
def anim(frames, **top):
    doc = {"format": "qsgi-animation", "version": 1, "frames": frames}
    doc.update(top)
    return doc

move = {"Floor": {"translation": [0, 0.5, 0]}}
bad("animation", "frame_string.json", anim([{"frame": "3", "nodes": move}]), "integer")
bad("animation", "frame_float.json", anim([{"frame": 1.5, "nodes": move}]), "integer")
bad("animation", "frame_negative.json", anim([{"frame": -1, "nodes": move}]), "[0, 10^7]")
bad("animation", "frame_huge.json", anim([{"frame": 10**15, "nodes": move}]), "[0, 10^7]")
bad("animation", "frames_out_of_order.json", anim([{"frame": 4}, {"frame": 2}]), "out of order")
bad("animation", "frames_empty.json", anim([]), "non-empty")
bad("animation", "unknown_top_key.json", {"format": "qsgi-animation", "version": 1, "frams": [{"frame": 0}]},
    'did you mean "frames"')
bad("animation", "unknown_frame_key.json", anim([{"frame": 0, "node": move}]), 'did you mean "nodes"')
bad("animation", "unknown_transform_key.json", anim([{"frame": 0, "nodes": {"Floor": {"translaton": [0, 1, 0]}}}]),
    'did you mean "translation"')
bad("animation", "translation_wrong_type.json", anim([{"frame": 0, "nodes": {"Floor": {"translation": "0 1 0"}}}]),
    "array of 3")
bad("animation", "rotation_zero.json", anim([{"frame": 0, "nodes": {"Floor": {"rotation": [0, 0, 0, 0]}}}]), "zero quaternion")
bad("animation", "fps_zero.json", anim([{"frame": 0}], fps=0), "fps")
bad("animation", "version_2.json", {"format": "qsgi-animation", "version": 2, "frames": [{"frame": 0}]}, "version")
bad("animation", "format_missing.json", {"version": 1, "frames": [{"frame": 0}]}, "format")
bad("animation", "node_unknown.json", anim([{"frame": 0, "nodes": {"Flor": {"translation": [0, 1, 0]}}}]), 'did you mean "Floor"')
bad("animation", "matrix_and_translation.json",
    anim([{"frame": 0, "nodes": {"Floor": {"matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1],
                                           "translation": [0, 1, 0]}}}]), "cannot be combined")
# A matrix that is no translation, rotation and scale, refused as on a glTF node (node_matrix_*.gltf).
bad("animation", "matrix_projective.json",
    anim([{"frame": 0}, {"frame": 3, "nodes": {"Floor": {"matrix": [1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}}}]),
    "frame 3, node 'Floor'.matrix: has a last row other than 0 0 0 1")
bad("animation", "matrix_sheared.json",
    anim([{"frame": 0}, {"frame": 3, "nodes": {"Floor": {"matrix": [1, 0, 0, 0, 0.5, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]}}}]),
    "frame 3, node 'Floor'.matrix: shears")
bad("animation", "moves_the_light.json", anim([{"frame": 0}, {"frame": 1, "nodes": {"Lamp": {"translation": [0, 2, 0]}}}]),
    "lights must be static")
bad("animation", "translation_overflows_float.json",
    anim([{"frame": 0}, {"frame": 1, "nodes": {"Floor": {"translation": [3.3e38, 0, 0], "scale": [1e38, 1, 1]}}}]),
    "supports up to 1e15")
bad("gltf", "scene_scaled_1e-30.gltf", edited(lambda m: m["nodes"][0].update(scale=[1e-30, 1e-30, 1e-30])),
    "spans only 2.83e-30 units")
bad("animation", "scene_spans_too_far.json",
    anim([{"frame": 0}, {"frame": 1, "nodes": {"Floor": {"translation": [1e20, 0, 0]}}}]), "supports up to 1e15")
bad("animation", "not_json.json", "frames: [0, 1, 2]", "not valid JSON")
bad("animation", "node_named_twice.json",
    anim([{"frame": 0, "nodes": {"Floor": {"translation": [0, 1, 0]}, "#0": {"translation": [0, 2, 0]}}}]), "twice")
bad("animation", "key_twice.json", '{"format": "qsgi-animation", "version": 1, "frames": [{"frame": 0}], '
    '"frames": [{"frame": 1}]}', "given twice", "frames")
bad("animation", "top_level_array.json", [anim([{"frame": 0}])], "JSON object")
bad("animation", "number_overflow.json", '{"format":"qsgi-animation","version":1,"frames":[{"frame":0,'
    '"nodes":{"Floor":{"translation":[0,1e999,0]}}}]}', "JSON")

# ---- configs (bad/config), given with --config; they name good/base.gltf unless they say otherwise ----
def config(name, doc, words, names=None):
    if isinstance(doc, dict):
        doc = {"scene": "../../good/base.gltf", **doc}
    bad("config", name, doc, words, names)


config("unknown_key.json", {"photon": 1000}, 'did you mean "photons"')
config("unknown_key_in_other_words.json", {"photon_count": 1000}, 'photon_count: unknown key (did you mean "photons"?)')
config("unknown_key_with_prefix.json", {"num_threads": 2}, 'did you mean "threads"')
config("photons_string.json", {"photons": "1000"}, "must be an integer")
config("photons_negative.json", {"photons": -1000}, "outside 1..4294967296")
config("photons_fraction.json", {"photons": 1000.5}, "must be an integer")
config("photons_beyond_path_index.json", {"photons": 2**33}, "2^32")
config("photons_beyond_memory.json", {"photons": 2**32}, "would need")
config("max_bounces_beyond_field.json", {"max_bounces": 70000}, "65536")
config("k_beyond.json", {"estimator": "photon-map", "k": 2**40}, "k")
config("radius_zero.json", {"radius": 0}, "positive number")
config("radius_string.json", {"radius": "1cm"}, "positive number")
config("threads_negative.json", {"threads": -2}, "outside 0..1024")
config("threads_beyond.json", {"threads": 100000}, "threads")
config("seed_fraction.json", {"seed": 0.5}, "must be an integer")
config("frames_words.json", {"frames": "first:last"}, "A:B")
config("frames_beyond_animation.json", {"frames": "0:99999"}, "last frame")
config("frames_huge_number.json", {"frames": "0:99999999999999999999"}, "A:B")
config("estimator_unknown.json", {"estimator": "dept"}, 'did you mean "detp"')
config("light_unknown_key.json", {"lights": [{"type": "point", "position": [0, 1, 0], "intensty": [1, 1, 1]}]},
    'did you mean "intensity"')
config("light_missing_intensity.json", {"lights": [{"type": "point", "position": [0, 1, 0]}]}, "intensity")
config("light_nan_position.json", '{"lights":[{"type":"point","position":[0,1e999,0],"intensity":[1,1,1]}]}', "JSON")
config("camera_unknown_key.json", {"camera": {"positon": [0, 1, 3], "target": [0, 0, 0]}}, 'did you mean "position"')
config("camera_target_at_eye.json", {"camera": {"position": [0, 1, 3], "target": [0, 1, 3]}}, "camera")
config("width_zero.json", {"width": 0}, "outside 1..16384")
config("spp_huge.json", {"spp": 10**6}, "spp")
config("scene_missing.json", {"scene": "no-such-scene.gltf"}, "no such file", "no-such-scene.gltf")
config("not_an_object.json", [1, 2, 3], "JSON object")
config("boolean_as_string.json", {"png": "yes"}, "true or false")
# Issue 23: found by a hostile set of files.
config("key_twice.json", '{"scene": "../../good/base.gltf", "photons": 1000, "photons": 2000}', "given twice", "photons")
config("nested_too_deep.json", '{"scene": "../../good/base.gltf", "_note": ' + "[" * 100000 + "]" * 100000 + "}",
       "nested deeper than 256")
config("radius_beyond_float.json", {"radius": 1e300}, "1e+300 is not a positive number")
config("photons_beyond_int64.json", {"photons": 1e20}, "1e+20 is outside 1..4294967296")
config("light_far_away.json", {"lights": [{"type": "point", "position": [1e20, 0, 0], "intensity": [1, 1, 1]}]},
       "units from the scene", "lights[0]")
config("light_overflowing_power.json",
       {"lights": [{"type": "point", "position": [0, 2, 0], "intensity": [3e38, 3e38, 3e38]}]}, "W qsgi carries", "lights[0]")
bad("gltf", "extras_nested_too_deep.gltf",
    json.dumps(scene())[:-1] + ', "extras": ' + "[" * 100000 + "]" * 100000 + "}", "nested deeper than 256")

# ---- PLY files (bad/ply), compared with good/frame.ply by `qsgi compare` ----
PLY_FIELDS = ["x", "y", "z", "nx", "ny", "nz", "radiosity_r", "radiosity_g", "radiosity_b"]
PLY_VERTICES = [(-1, 0, 1, 0, 1, 0, 1, 1, 1), (1, 0, 1, 0, 1, 0, 2, 2, 2), (1, 0, -1, 0, 1, 0, 3, 3, 3),
                (-1, 0, -1, 0, 1, 0, 4, 4, 4)]
PLY_FACES = [(0, 1, 2), (0, 2, 3)]


def ply(vertices=PLY_VERTICES, faces=PLY_FACES, vertex_count=None, face_count=None, fmt="binary_little_endian",
        types=None, extra_element="", extra_data=b"", extra_properties=(), header_end="end_header\n"):
    """A vertex-radiosity PLY as qsgi writes it (floats, then faces as uchar/int lists); counts,
    types, formats and extra elements or vertex properties may be changed to make it hostile."""
    types = types or {}
    names = PLY_FIELDS + [name for name, _, _ in extra_properties]
    header = f"ply\nformat {fmt} 1.0\nelement vertex {len(vertices) if vertex_count is None else vertex_count}\n"
    header += "".join(f"property {types.get(n, 'float')} {n}\n" for n in PLY_FIELDS)
    header += "".join(f"property {t} {n}\n" for n, t, _ in extra_properties)
    header += extra_element
    header += f"element face {len(faces) if face_count is None else face_count}\nproperty list uchar int vertex_indices\n"
    header += header_end
    data = b""
    for v in vertices:
        values = list(v) + [value for _, _, value in extra_properties]
        for n, value in zip(names, values):
            t = types.get(n, dict((p, t) for p, t, _ in extra_properties).get(n, "float"))
            data += struct.pack("<d" if t == "double" else "<f", value)
    data += extra_data
    for f in faces:
        data += struct.pack("<B%di" % len(f), len(f), *f)
    return header.encode() + data


def ply_case(name, content, words, names=None):
    bad("ply", name, content, words, names)


write("good/frame.ply", ply())
many = PLY_VERTICES * 20  # a file of about 3 KB
ply_case("vertex_count_huge.ply", ply(many, vertex_count=200000000),
         "header, element vertex (line 3): declares 200000000 vertices of at least 36 bytes each")
ply_case("face_count_huge.ply", ply(face_count=10**12), "declares 1000000000000 faces of at least 13 bytes each")
ply_case("ascii_vertex_count_huge.ply",
         "ply\nformat ascii 1.0\nelement vertex 1000000000\n" + "".join(f"property float {n}\n" for n in PLY_FIELDS) +
         "end_header\n" + "0 0 0 0 1 0 1 1 1\n" * 40, "declares 1000000000 vertices of at least 18 bytes each")
ply_case("other_element_count_huge.ply",
         ply(extra_element="element material 1000000000000000\nproperty float shininess\n"),
         "element material (line 13): declares 1000000000000000 elements")
ply_case("vertex_count_negative.ply", ply(vertex_count=-1), "element 'vertex' needs a count")
ply_case("vertex_count_words.ply", ply(vertex_count="many"), "element 'vertex' needs a count")
nan_y = [list(v) for v in PLY_VERTICES]
nan_y[2][1] = float("nan")
ply_case("position_nan.ply", ply(nan_y), "vertex 2: property 'y' is nan, not a finite number")
inf_nz = [list(v) for v in PLY_VERTICES]
inf_nz[3][5] = float("-inf")
ply_case("normal_inf.ply", ply(inf_nz), "vertex 3: property 'nz' is -inf, not a finite number")
nan_b = [list(v) for v in PLY_VERTICES]
nan_b[1][8] = float("inf")
ply_case("radiosity_inf.ply", ply(nan_b), "vertex 1: property 'radiosity_b' is inf")
ply_case("extra_property_nan.ply", ply(extra_properties=[("confidence", "float", float("nan"))]),
         "vertex 0: property 'confidence' is nan")
huge_x = [list(v) for v in PLY_VERTICES]
huge_x[0][0] = 1e300
ply_case("position_beyond_float.ply", ply(huge_x, types={"x": "double"}),
         "vertex 0: property 'x' is 1e+300, beyond the range of float")
ply_case("face_index_beyond.ply", ply(faces=[(0, 1, 2), (0, 2, 7)]), "face 1: refers to a vertex that does not exist")
ply_case("no_end_header.ply", ply(header_end=""), "has no end_header line")


with open(os.path.join(HERE, "bad", "generated.tsv"), "w") as f:
    f.write("# kind\tfile (relative to tests/data)\twords the error message must contain\tfile it names\n")
    f.write("# Written by tests/data/make_inputs.py; files found by fuzzing go to found.tsv.\n")
    for kind, rel, words, names in rows:
        f.write(f"{kind}\t{rel}\t{words}\t{names}\n")
print(f"{len(rows)} hostile files, {len(os.listdir(os.path.join(HERE, 'good')))} valid edge cases")
