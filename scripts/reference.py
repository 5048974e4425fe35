#!/usr/bin/env python3
"""Independent per-vertex reference for qsgi, computed with Mitsuba 3 (a renderer nobody here wrote).

Development only (CI reads the committed outputs; it never runs this). It takes the geometry of a
frame from a qsgi PLY (world-space positions, normals, triangles: exactly the vertices qsgi
estimates at) and the materials from the glTF scene, renders the irradiance at every vertex with
Mitsuba's path tracer, and writes a PLY that `qsgi compare` reads, with radiosity B = rho E + pi L_e.

Irradiance at vertex v (normal n), E = E_direct + E_indirect:
  - E_direct: next-event estimation to the emitters from v (Mitsuba's sample_emitter_direction,
    visibility tested), times max(0, cos) — for area lights and point lights alike;
  - E_indirect: pi x the mean radiance along cosine-weighted rays about n from Mitsuba's `path`
    integrator, minus the emission of each ray's first hit (that light is in E_direct).
Queries start 1e-4 of the scene's diagonal off the surface along n and a further 5e-4 of it
towards the centroid of the vertex's incident triangles, so a vertex on an edge is evaluated on
its own surface, not inside the adjacent wall.

Setup (Debian 12): pip install mitsuba drjit numpy; apt-get install libllvm19. Debian's LLVM 14/15
make Dr.Jit's JIT fail ("Cannot select fminimum"), so this script points DRJIT_LIBLLVM_PATH at
LLVM 19 when it is not set.

  scripts/reference.py SCENE.gltf QSGI_FRAME.ply OUT.ply [--spp N] [--seed S] [--config CONFIG] [--sky R,G,B]
                       [--vertices N]

--vertices N: a dense mesh's reference at N vertices only, drawn uniformly (seeded by --seed);
OUT.ply flags them in a `referenced` vertex property
(the others hold 0) and `qsgi compare` judges a solution on them alone, region by region.

--surface N: the reference where the eye looks (issue 47): N points drawn uniformly by area over the
frame's triangles (seeded by --seed), each recorded by its triangle (the frame PLY's face index)
and barycentrics, with its irradiance E, the standard error of E (from the spread of its samples)
and whether it is hidden. OUT is then a PLY of `element point N`: int triangle, float b1 b2 (the
weights of the triangle's second and third corners), float x y z (world position), float nx ny nz
(the side that receives light: the face's normal turned towards its vertex normals), float
irradiance_r/g/b, float stderr_r/g/b, uchar hidden. A point is hidden when no light reaches it
and the ray along its normal meets the back of a face (it lies inside or under closed geometry:
the floor under a block); a score leaves hidden points out.

--agree-with VERTEX_REFERENCE.ply (with --surface N): the check that the two kinds of reference agree
where both exist. The N points are then drawn at vertices (a vertex uniformly, one of its triangles
uniformly, the point at that corner) of the flat interior — every incident face's normal within
10^-3 of the vertex normal, so that both queries leave from the same plane, and no incident edge on
a border, where a point on the surface touches the next one — and each point's E is
compared with the vertex reference's E = B / albedo there (an emitter's vertices, hidden points and
points dark in both left out), in
units of their combined standard error (the vertex reference's from this run's spread scaled to its
path count, read from its comment). It prints the mean and RMS of those z-scores and the share
beyond 3, and exits 1 when the RMS exceeds 1.5 or the mean 0.5 (the two agree within their noise:
RMS 1, mean 0, 0.3 % beyond 3). OUT is written as for --surface.

CONFIG: a qsgi config whose "lights" are added (point lights and a uniform sky only here); --sky R,G,B
adds a uniform sky as qsgi's --sky does (Mitsuba's `constant` emitter). Light that escapes to the sky
is the sky's emission: it is in E_direct, and subtracted from the gathered rays as a hit's emission is.
"""
import argparse
import base64
import glob
import json
import os
import struct
import sys
import tempfile
import time

import numpy as np

if "DRJIT_LIBLLVM_PATH" not in os.environ:
    for pattern in ("/usr/lib/x86_64-linux-gnu/libLLVM.so.19*", "/usr/lib/llvm-19/lib/libLLVM.so*",
                    "/usr/lib/x86_64-linux-gnu/libLLVM-19.so*"):
        found = sorted(glob.glob(pattern))
        if found:
            os.environ["DRJIT_LIBLLVM_PATH"] = found[0]
            break

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

# ---------------------------------------------------------------------------------------------
# PLY in and out (qsgi's frame_NNNN.ply layout)

VERTEX_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
                         ("radiosity_r", "<f4"), ("radiosity_g", "<f4"), ("radiosity_b", "<f4"),
                         ("red", "u1"), ("green", "u1"), ("blue", "u1")])
FACE_DTYPE = np.dtype([("n", "u1"), ("v", "<i4", (3,))])


def read_ply(path):
    """A qsgi frame PLY's world positions, normals and triangles."""
    v, faces = read_ply_records(path)
    positions = np.stack([v["x"], v["y"], v["z"]], 1).astype(np.float64)
    normals = np.stack([v["nx"], v["ny"], v["nz"]], 1).astype(np.float64)
    return positions, normals, faces


def read_ply_records(path):
    """A qsgi frame PLY's vertex records (every property its header lists) and triangles."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    vertices = faces = 0
    fields, element = [], None  # the vertex properties as the header lists them (qsgi adds columns over time)
    types = {"float": "<f4", "double": "<f8", "uchar": "u1", "int": "<i4", "uint": "<u4"}
    for line in header:
        if line.startswith("element "):
            element = line.split()[1]
        if line.startswith("element vertex"):
            vertices = int(line.split()[2])
        elif line.startswith("element face"):
            faces = int(line.split()[2])
        elif line.startswith("property ") and element == "vertex" and line.split()[1] in types:
            fields.append((line.split()[2], types[line.split()[1]]))
    if "property uchar blue" not in header or "format binary_little_endian 1.0" not in header:
        sys.exit(f"{path}: not a qsgi frame PLY")
    vertex_dtype = np.dtype(fields)
    v = np.frombuffer(data, vertex_dtype, vertices, end)
    fa = np.frombuffer(data, FACE_DTYPE, faces, end + vertices * vertex_dtype.itemsize)
    return v, fa["v"].astype(np.int64)


def write_ply(path, positions, normals, faces, radiosity, comment, referenced=None):
    dtype = VERTEX_DTYPE if referenced is None else np.dtype(VERTEX_DTYPE.descr + [("referenced", "u1")])
    v = np.zeros(len(positions), dtype)
    for i, k in enumerate("xyz"):
        v[k] = positions[:, i]
        v["n" + k] = normals[:, i]
    for i, k in enumerate(("radiosity_r", "radiosity_g", "radiosity_b")):
        v[k] = radiosity[:, i]
    fa = np.zeros(len(faces), FACE_DTYPE)
    fa["n"] = 3
    fa["v"] = faces
    properties = "".join(f"property float {n}\n" for n in VERTEX_DTYPE.names[:9])
    properties += "".join(f"property uchar {n}\n" for n in dtype.names[9:])
    if referenced is not None:
        v["referenced"] = referenced
    header = (f"ply\nformat binary_little_endian 1.0\ncomment {comment}\nelement vertex {len(v)}\n{properties}"
              f"element face {len(fa)}\nproperty list uchar int vertex_indices\nend_header\n")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(v.tobytes())
        f.write(fa.tobytes())
    os.replace(tmp, path)


# ---------------------------------------------------------------------------------------------
# Materials per vertex, in qsgi's flattening order (docs/design.md §2; lib/scene/gltf_loader.cpp): scene
# roots in order, depth-first pre-order, each node's mesh primitives in order.

def mean_texture_colour(gltf_path, doc, texture):
    """The mean linear colour of a base-colour texture, as qsgi takes it (docs/inputs.md: albedo =
    baseColorFactor x the texture's mean colour, each pixel through the sRGB curve first)."""
    from PIL import Image  # only scenes with textures need it (pip install pillow)
    uri = doc["images"][doc["textures"][texture["index"]]["source"]]["uri"]
    image = Image.open(os.path.join(os.path.dirname(gltf_path), uri))
    pixels = np.asarray(image.convert("RGB"), np.float64) / 255.0
    linear = np.where(pixels <= 0.04045, pixels / 12.92, ((pixels + 0.055) / 1.055) ** 2.4)
    return linear.reshape(-1, 3).mean(0)


def gltf_document(path):
    """The JSON of a .gltf, or of a .glb's first chunk (qsgi's asset.glb: a refined mesh's
    materials per vertex, in the same flattening order as its frame PLYs)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] == b"glTF":
        length, kind = struct.unpack_from("<II", data, 12)
        if kind != 0x4E4F534A:
            sys.exit(f"{path}: a GLB whose first chunk is not JSON")
        return json.loads(data[20:20 + length])
    return json.loads(data)


def gltf_vertex_materials(path):
    doc = gltf_document(path)
    scene = doc["scenes"][doc.get("scene", 0)]
    materials = doc.get("materials", [])
    albedo, emission = [], []
    for m in materials:
        pbr = m.get("pbrMetallicRoughness", {})
        base = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
        if "baseColorTexture" in pbr:
            base = list(np.array(base) * mean_texture_colour(path, doc, pbr["baseColorTexture"]))
        strength = m.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        albedo.append(base)
        emission.append([c * strength for c in m.get("emissiveFactor", [0, 0, 0])])
    default = ([1.0, 1.0, 1.0], [0.0, 0.0, 0.0])
    per_vertex_albedo, per_vertex_emission = [], []

    def visit(n):
        node = doc["nodes"][n]
        if "mesh" in node:
            for prim in doc["meshes"][node["mesh"]]["primitives"]:
                if prim.get("mode", 4) not in (4, 5, 6):
                    continue
                count = doc["accessors"][prim["attributes"]["POSITION"]]["count"]
                mat = prim.get("material")
                a, e = (albedo[mat], emission[mat]) if mat is not None else default
                per_vertex_albedo.extend([a] * count)
                per_vertex_emission.extend([e] * count)
        for c in node.get("children", []):
            visit(c)

    for n in scene["nodes"]:
        visit(n)
    return np.array(per_vertex_albedo, np.float64), np.array(per_vertex_emission, np.float64)


def gltf_point_lights(path, config):
    """KHR_lights_punctual point lights on root-level nodes with a translation, plus config lights."""
    doc = gltf_document(path)
    lights = []
    defs = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for node in doc.get("nodes", []):
        ext = node.get("extensions", {}).get("KHR_lights_punctual")
        if ext is None:
            continue
        light = defs[ext["light"]]
        if light["type"] != "point":
            sys.exit(f"{path}: only point lights are supported by this script")
        colour = light.get("color", [1, 1, 1])
        lights.append((node.get("translation", [0, 0, 0]), [c * light.get("intensity", 1.0) for c in colour]))
    if config:
        for light in json.load(open(config)).get("lights", []):
            if light["type"] == "sky":
                continue  # read by config_sky
            if light["type"] != "point":
                sys.exit(f"{config}: only point lights and a sky are supported by this script")
            lights.append((light["position"], light["intensity"]))
    return lights


def config_sky(config):
    """The radiance of a config's sky (its "sky" key or a "lights" entry of type sky), or None."""
    if not config:
        return None
    doc = json.load(open(config))
    if "sky" in doc:
        value = doc["sky"]
        return [float(value)] * 3 if isinstance(value, (int, float)) else [float(c) for c in value]
    for light in doc.get("lights", []):
        if light["type"] == "sky":
            value = light["radiance"]
            return [float(value)] * 3 if isinstance(value, (int, float)) else [float(c) for c in value]
    return None


# ---------------------------------------------------------------------------------------------

def build_scene(positions, faces, albedo, emission, point_lights, sky, workdir):
    shapes = {"type": "scene", "integrator": {"type": "path", "max_depth": 64, "rr_depth": 8}}
    # One mesh per material, from the PLY's world-space triangles.
    face_material = [(tuple(albedo[f[0]]), tuple(emission[f[0]])) for f in faces]
    groups = {}
    for i, key in enumerate(face_material):
        groups.setdefault(key, []).append(i)
    for g, ((a, e), members) in enumerate(groups.items()):
        tri = faces[members]
        used, remap = np.unique(tri.reshape(-1), return_inverse=True)
        # Each group goes to Mitsuba as a PLY of its own (flat shading: face normals).
        path = os.path.join(workdir, f"group{g}.ply")
        verts = positions[used].astype("<f4")
        with open(path, "wb") as f:
            f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\nproperty float x\n"
                     f"property float y\nproperty float z\nelement face {len(tri)}\n"
                     f"property list uchar int vertex_indices\nend_header\n").encode("ascii"))
            f.write(verts.tobytes())
            fa = np.zeros(len(tri), FACE_DTYPE)
            fa["n"] = 3
            fa["v"] = remap.reshape(-1, 3)
            f.write(fa.tobytes())
        shape = {"type": "ply", "filename": path, "face_normals": True,
                 "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": list(a)}}}
        if max(e) > 0:
            shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": list(e)}}
        shapes[f"group{g}"] = shape
    for i, (p, intensity) in enumerate(point_lights):
        shapes[f"light{i}"] = {"type": "point", "position": list(p), "intensity": {"type": "rgb", "value": list(intensity)}}
    if sky is not None:
        shapes["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(sky)}}
    return mi.load_dict(shapes)


def query_points(positions, normals, faces, diagonal):
    """Start points: off the surface along n, and a step toward the incident triangles' centroid."""
    centroid_sum = np.zeros_like(positions)
    count = np.zeros(len(positions))
    centres = positions[faces].mean(1)
    for k in range(3):
        np.add.at(centroid_sum, faces[:, k], centres)
        np.add.at(count, faces[:, k], 1)
    towards = centroid_sum / np.maximum(count, 1)[:, None] - positions
    towards -= normals * np.sum(towards * normals, 1, keepdims=True)
    length = np.linalg.norm(towards, axis=1, keepdims=True)
    towards = np.where(length > 1e-9 * diagonal, towards / np.maximum(length, 1e-30), 0)
    return positions + normals * (1e-4 * diagonal) + towards * (5e-4 * diagonal)


def per_vertex_samples(origins, normals, spp, seed, chunk, sample):
    """Each vertex's mean of spp RGB samples and its standard error (inf with one sample):
    `sample(o, n, sampler)` gets Dr.Jit arrays holding each vertex's origin and normal spp times
    over, for `chunk` vertices at a time, and an independent sampler seeded `seed` + the chunk's
    first vertex; it returns one RGB value per entry."""
    mean = np.zeros((len(origins), 3))
    err = np.zeros((len(origins), 3))
    for start in range(0, len(origins), chunk):
        end = min(len(origins), start + chunk)
        n = end - start
        size = n * spp
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(seed + start, size)
        idx = dr.arange(mi.UInt32, size) // spp
        o = mi.Point3f(*[dr.gather(mi.Float, mi.Float(origins[start:end, k].astype(np.float32)), idx) for k in range(3)])
        nn = mi.Normal3f(*[dr.gather(mi.Float, mi.Float(normals[start:end, k].astype(np.float32)), idx) for k in range(3)])
        values = np.array(mi.TensorXf(dr.ravel(sample(o, nn, sampler)), (size, 3))).reshape(n, spp, 3).astype(np.float64)
        mean[start:end] = values.mean(1)
        err[start:end] = values.std(1, ddof=1) / np.sqrt(spp) if spp > 1 else np.inf
    return mean, err


def irradiance(scene, origins, normals, spp, seed, chunk, errors=None):
    """E at each origin about its normal; with `errors` (an array like the result), the standard
    error of each mean from the spread of its spp samples."""
    integrator = scene.integrator()

    def sample(o, nn, sampler):
        # Direct light: one emitter sample per path.
        it = dr.zeros(mi.Interaction3f)
        it.p = o
        it.n = nn
        it.wavelengths = dr.zeros(mi.Color0f)
        ds, weight = scene.sample_emitter_direction(it, sampler.next_2d(), True)
        direct = weight * dr.maximum(0, dr.dot(ds.d, nn))
        # Indirect light: cosine-weighted rays, minus the first hit's own emission.
        d = mi.Frame3f(nn).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d()))
        ray = mi.Ray3f(o, d)
        L, _, _ = integrator.sample(scene, sampler, ray)
        si = scene.ray_intersect(ray)
        # A ray that escapes meets the environment: si.emitter() is then the scene's sky (none: 0).
        emitted = si.emitter(scene).eval(si)
        return direct + dr.pi * (L - emitted)

    out, err = per_vertex_samples(origins, normals, spp, seed, chunk, sample)
    if errors is not None:
        errors[:] = err
    return out


def surface_points(positions, normals, faces, count, seed):
    """`count` points uniformly by area over the triangles: face index, barycentrics (b1, b2) of
    the second and third corners, world position, and the face's normal turned to its vertex
    normals' side (the side that receives light)."""
    a, b, c = positions[faces[:, 0]], positions[faces[:, 1]], positions[faces[:, 2]]
    cross = np.cross(b - a, c - a)
    area = 0.5 * np.linalg.norm(cross, axis=1)
    rng = np.random.default_rng(seed)
    triangle = rng.choice(len(faces), count, p=area / area.sum())
    r1, r2 = rng.random(count), rng.random(count)
    s = np.sqrt(r1)
    b1, b2 = s * (1 - r2), s * r2  # uniform over the triangle
    p = (1 - b1 - b2)[:, None] * a[triangle] + b1[:, None] * b[triangle] + b2[:, None] * c[triangle]
    n = cross[triangle] / np.maximum(np.linalg.norm(cross[triangle], axis=1, keepdims=True), 1e-300)
    vertex_side = normals[faces[triangle]].sum(1)
    n *= np.where(np.sum(n * vertex_side, 1, keepdims=True) < 0, -1.0, 1.0)
    return triangle, b1, b2, p, n


def vertex_points(positions, normals, faces, count, seed):
    """`count` points at vertices of the flat interior (every incident face's normal within 1e-3 of
    the vertex normal, no incident border edge), each as surface_points records it: the corner of one incident triangle
    (b1, b2 the corner's weights), and the vertex index it sits on."""
    a, b, c = positions[faces[:, 0]], positions[faces[:, 1]], positions[faces[:, 2]]
    face_normal = np.cross(b - a, c - a)
    face_normal /= np.maximum(np.linalg.norm(face_normal, axis=1, keepdims=True), 1e-300)
    flat = np.ones(len(positions), bool)
    for k in range(3):
        off = np.sum(face_normal * normals[faces[:, k]], 1) < 1 - 1e-3
        flat[faces[off, k]] = False
    # Not on a border either (an edge only one triangle uses: a wall's foot on the floor), where a
    # point on the surface meets the next surface and the vertex reference steps inward.
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    unique, uses = np.unique(edges, axis=0, return_counts=True)
    flat[unique[uses == 1].ravel()] = False
    incident = [[] for _ in range(len(positions))]
    for f, tri in enumerate(faces):
        for k in range(3):
            incident[tri[k]].append((f, k))
    candidates = np.flatnonzero(flat & np.array([len(i) > 0 for i in incident]))
    rng = np.random.default_rng(seed)
    vertex = rng.choice(candidates, min(count, len(candidates)), replace=False)
    triangle, b1, b2 = [], [], []
    for v in vertex:
        f, k = incident[v][rng.integers(len(incident[v]))]
        triangle.append(f)
        b1.append(1.0 if k == 1 else 0.0)
        b2.append(1.0 if k == 2 else 0.0)
    triangle = np.array(triangle)
    n = face_normal[triangle] * np.where(np.sum(face_normal[triangle] * normals[vertex], 1, keepdims=True) < 0, -1.0, 1.0)
    return triangle, np.array(b1), np.array(b2), positions[vertex], n, vertex


def paths_in_comment(path):
    """The path count a reference PLY's comment records ("…, 16384 paths …")."""
    with open(path, "rb") as f:
        header = f.read(4096).split(b"end_header")[0].decode("ascii", "replace")
    for line in header.split("\n"):
        if line.startswith("comment") and " paths" in line:
            words = line.split()
            return int(words[words.index("paths") - 1])
    sys.exit(f"{path}: no path count in its comment")


def under_geometry(scene, origins, normals):
    """Whether the ray along each normal first meets the back of a face: the point lies inside or
    under closed geometry."""
    o = mi.Point3f(*[mi.Float(origins[:, k].astype(np.float32)) for k in range(3)])
    d = mi.Vector3f(*[mi.Float(normals[:, k].astype(np.float32)) for k in range(3)])
    si = scene.ray_intersect(mi.Ray3f(o, d))
    back = si.is_valid() & (dr.dot(si.n, d) > 0)
    return np.array(back, dtype=bool)


def write_surface_ply(path, triangle, b1, b2, p, n, E, errors, hidden, comment):
    names = ["b1", "b2", "x", "y", "z", "nx", "ny", "nz", "irradiance_r", "irradiance_g", "irradiance_b",
             "stderr_r", "stderr_g", "stderr_b"]
    dtype = np.dtype([("triangle", "<i4")] + [(k, "<f4") for k in names] + [("hidden", "u1")])
    v = np.zeros(len(triangle), dtype)
    v["triangle"], v["b1"], v["b2"], v["hidden"] = triangle, b1, b2, hidden
    for i, k in enumerate("xyz"):
        v[k] = p[:, i]
        v["n" + k] = n[:, i]
    for i, k in enumerate("rgb"):
        v["irradiance_" + k] = E[:, i]
        v["stderr_" + k] = errors[:, i]
    properties = "property int triangle\n" + "".join(f"property float {k}\n" for k in names) + "property uchar hidden\n"
    header = (f"ply\nformat binary_little_endian 1.0\ncomment {comment}\nelement point {len(v)}\n{properties}"
              "end_header\n")
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(v.tobytes())
    os.replace(tmp, path)


def agreement(vertex_reference, vertex, albedo, emission, E, errors, spp, hidden):
    """Prints how the surface points' E agrees with the vertex reference's at the same vertices
    (hidden points, which a score leaves out, left out); returns the exit status (0: within their
    noise)."""
    records, _ = read_ply_records(vertex_reference)
    if len(records) != len(albedo):
        sys.exit(f"{vertex_reference} has {len(records)} vertices, the frame {len(albedo)}")
    B = np.stack([records["radiosity_r"], records["radiosity_g"], records["radiosity_b"]], 1).astype(np.float64)
    # The vertex reference's standard error: this run's, scaled from its paths to the reference's.
    vertex_error = errors * np.sqrt(spp / paths_in_comment(vertex_reference))
    usable = (albedo[vertex].min(1) > 0) & (emission[vertex].max(1) == 0) & ~hidden
    E_vertex = B[vertex] / np.where(albedo[vertex] > 0, albedo[vertex], 1)
    # Points dark in both (below 10^-3 of the median), where a stray path's 10^-7 is many of its
    # own standard errors, say nothing about agreement.
    usable &= np.maximum(E, E_vertex).max(1) > 1e-3 * np.median(E.max(1))
    sigma = np.sqrt(errors ** 2 + vertex_error ** 2)
    ok = usable[:, None] & (sigma > 0)
    z = ((E - E_vertex) / np.where(sigma > 0, sigma, 1))[ok]
    rms, mean, beyond = float(np.sqrt(np.mean(z ** 2))), float(np.mean(z)), float(np.mean(np.abs(z) > 3))
    worst = np.argsort(-np.abs(np.where(ok, (E - E_vertex) / np.where(sigma > 0, sigma, 1), 0)).max(1))[:5]
    for i in worst:
        print(f"  vertex {vertex[i]}: surface E {E[i].round(4)} ± {errors[i].max():.2g}, vertex E {E_vertex[i].round(4)}")
    print(f"surface points at {int(usable.sum())} flat interior vertices against {vertex_reference}: z-scores "
          f"(difference / combined standard error, per channel) RMS {rms:.3f}, mean {mean:+.3f}, {100 * beyond:.2f} % beyond 3")
    return 0 if rms <= 1.5 and abs(mean) <= 0.5 else 1


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("frame_ply")
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024, help="paths per vertex (default 1024)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--config", help="qsgi config whose point lights and sky are added")
    ap.add_argument("--sky", help="R,G,B: a uniform sky of this radiance, as qsgi's --sky")
    ap.add_argument("--chunk", type=int, default=2048, help="vertices per wavefront")
    ap.add_argument("--vertices", type=int, help="only this many vertices, drawn uniformly (dense meshes)")
    ap.add_argument("--surface", type=int, help="instead of the vertices, this many points uniformly by area over the "
                                                "surface (OUT: a PLY of points; see above)")
    ap.add_argument("--agree-with", metavar="VERTEX_REFERENCE", help="with --surface: points at flat interior vertices, "
                                                                     "checked against this vertex reference (see above)")
    args = ap.parse_args()
    if args.agree_with and args.surface is None:
        ap.error("--agree-with needs --surface N")
    if args.surface is not None and (args.surface < 1 or args.vertices is not None):
        ap.error("--surface must be at least 1, and not with --vertices")
    if args.vertices is not None and args.vertices < 1:
        ap.error("--vertices must be at least 1")

    mi.set_variant("llvm_ad_rgb")
    positions, normals, faces = read_ply(args.frame_ply)
    albedo, emission = gltf_vertex_materials(args.scene)
    if len(albedo) != len(positions):
        sys.exit(f"{args.frame_ply} has {len(positions)} vertices but {args.scene} flattens to {len(albedo)}")
    diagonal = float(np.linalg.norm(positions.max(0) - positions.min(0)))
    with tempfile.TemporaryDirectory() as workdir:
        sky = [float(c) for c in args.sky.split(",")] if args.sky else config_sky(args.config)
        if sky is not None and len(sky) == 1:
            sky = sky * 3
        scene = build_scene(positions, faces, albedo, emission, gltf_point_lights(args.scene, args.config), sky, workdir)
    started = time.time()
    if args.surface is not None:
        if args.agree_with:
            triangle, b1, b2, p, n, at_vertex = vertex_points(positions, normals, faces, args.surface, args.seed)
        else:
            triangle, b1, b2, p, n = surface_points(positions, normals, faces, args.surface, args.seed)
        origins = p + n * (1e-4 * diagonal)
        errors = np.zeros((len(p), 3))
        E = irradiance(scene, origins, n, args.spp, args.seed, args.chunk, errors)
        hidden = (E.max(1) == 0) & under_geometry(scene, origins, n)
        comment = (f"qsgi surface reference: Mitsuba {mi.__version__} path tracer, {args.spp} paths + emitter samples per "
                   f"point, seed {args.seed}, {len(p)} points ({int(hidden.sum())} hidden), {time.time() - started:.0f} s")
        write_surface_ply(args.out, triangle, b1, b2, p, n, E, errors, hidden.astype(np.uint8), comment)
        print(comment)
        if args.agree_with:
            sys.exit(agreement(args.agree_with, at_vertex, albedo, emission, E, errors, args.spp, hidden))
        return
    origins = query_points(positions, normals, faces, diagonal)
    chosen = np.arange(len(positions))
    referenced = None
    if args.vertices is not None and args.vertices < len(positions):
        chosen = np.sort(np.random.default_rng(args.seed).choice(len(positions), args.vertices, replace=False))
        referenced = np.zeros(len(positions), np.uint8)
        referenced[chosen] = 1
    E = np.zeros((len(positions), 3))
    E[chosen] = irradiance(scene, origins[chosen], normals[chosen], args.spp, args.seed, args.chunk)
    B = albedo * E + np.pi * emission
    if referenced is not None:
        B[referenced == 0] = 0
    comment = (f"qsgi reference: Mitsuba {mi.__version__} path tracer, {args.spp} paths + emitter samples per vertex, "
               f"seed {args.seed}, {len(chosen)} of {len(positions)} vertices, {time.time() - started:.0f} s")
    write_ply(args.out, positions, normals, faces, B, comment, referenced)
    print(comment)


if __name__ == "__main__":
    main()
