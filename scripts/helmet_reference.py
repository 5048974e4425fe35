#!/usr/bin/env python3
"""Independent per-vertex reference for a real asset under a uniform sky (issue 56), with Mitsuba 3.

Development only (CI never runs it). For every vertex v (normal n) of a qsgi frame PLY — the exact
points qsgi estimates at — from the start point o = v + OFFSET n (OFFSET 1e-6 m by default: the
vertex itself, not a point lifted by a scene-scaled amount):

  s_v   the sky share: the cosine-weighted fraction of the vertex-normal hemisphere from which a ray
        from o escapes (meets no triangle, either side); two independent passes of SKY_RAYS rays
        per vertex, each stratified (a jittered sqrt(N) x sqrt(N) grid warped to the cosine
        hemisphere); s_v is their mean and its variance (s1 - s2)^2 / 4. Direct irradiance under
        a uniform sky of radiance L is pi L s_v. A vertex with s_v = 0 ("dark") let none of its
        2 SKY_RAYS rays escape.
  E_v   the irradiance, sky plus interreflections: E = pi L s_v + E_ind, where E_ind = pi x the mean,
        over SPP cosine-distributed rays from o, of the radiance that comes back from the first
        surface hit (Mitsuba's `path` integrator; a ray that escapes adds 0 here: the sky it sees
        is in pi L s_v). Its standard error combines the spread of the SPP samples with the
        sky share's (from its two passes).
  contact  whether the ray from o along +n meets a triangle within CONTACT (1 mm): a strap lying on
        a shell, overlapping parts, the ground under the stand. The distance and the mesh met are
        kept.

Materials as qsgi reads them (docs/inputs.md): Lambertian, albedo = baseColorFactor x the base-colour
texture's mean linear colour, opaque (alphaMode ignored), no emission here. Each triangle's front
is qsgi's (lib/scene/scene.cpp frontFaceNormal: the CCW winding's side, turned to the side its
vertex normals face), and its back is black as in qsgi's gather (Mitsuba's one-sided `diffuse`;
`--two-sided` makes both sides reflect instead). The geometry is the PLY's world-space triangles
(flat faces; the vertex normals only choose the hemispheres); the glTF is flattened as qsgi does
(scene roots in order, depth-first, each primitive in order) for the albedo, the mesh and material
of each vertex, and its positions are checked against the PLY's.

Writes OUT.npz: positions, normals, faces (the PLY's), mesh_id / mesh_names, material_id /
material_names, albedo, sky_share, sky_share_var, sky_rays (in all), contact, contact_distance,
contact_mesh (-1: none), contact_own (the hit triangle contains the vertex), referenced (E computed
there), E (RGB), E_stderr (RGB), E_indirect (RGB), spp, offset, seed, sky, seconds, and a text
`comment`. scripts/helmet_score.py reads it.

FlightHelmet on the ground (scripts/make_helmet_ground.py, 55,513 vertices), every vertex, 2 x 1024
sky rays and 1024 paths a vertex: 227 s on one thread (sky shares 17 s, paths 209 s); the noise of
E over every lit vertex, sqrt(sum sigma^2 / sum E^2), 0.77 %. The answer moves by nothing beyond
noise between offsets 1e-7 and 1e-6 m (1e-5 m already lets 11 vertices through a surface).

Setup (Debian 12): pip install mitsuba drjit numpy pillow; apt-get install libllvm19 (see
scripts/reference.py: DRJIT_LIBLLVM_PATH is pointed at LLVM 19 when it is not set).

  scripts/helmet_reference.py SCENE.gltf FRAME.ply OUT.npz --sky 1,1,1 [--offset 1e-6] [--sky-rays 1024]
                              [--spp 256] [--vertices N] [--seed S] [--contact 1e-3] [--threads T] [--two-sided]

--vertices N: E_v at N vertices only, drawn uniformly without replacement (seeded by --seed);
s_v and the contact flag are computed at every vertex all the same (they are cheap).
"""
import argparse
import os
import sys
import tempfile
import time
import urllib.parse

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from reference import FACE_DTYPE, gltf_document, gltf_vertex_materials, per_vertex_samples, read_ply  # noqa: E402  (sets DRJIT_LIBLLVM_PATH)

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402


# ---------------------------------------------------------------------------------------------
# The glTF flattened as qsgi's loader does: positions, normals (static node transforms), and per
# vertex the mesh (node name, else mesh name) and material.

COMPONENTS = {5126: ("<f4", 4), 5125: ("<u4", 4), 5123: ("<u2", 2), 5121: ("u1", 1)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def quat_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], np.float64).reshape(4, 4).T
    m = np.eye(4)
    m[:3, :3] = quat_matrix(node.get("rotation", [0, 0, 0, 1])) @ np.diag(node.get("scale", [1, 1, 1]))
    m[:3, 3] = node.get("translation", [0, 0, 0])
    return m


def flatten_gltf(path):
    """Per vertex in qsgi's order: world position, normal, and the triangles (vertex indices); mesh id,
    material id; the mesh names
    (node name, else mesh name) and material names."""
    doc = gltf_document(path)
    folder = os.path.dirname(path)
    buffers = []
    for b in doc["buffers"]:
        with open(os.path.join(folder, urllib.parse.unquote(b["uri"])), "rb") as f:
            buffers.append(f.read())

    def accessor(i):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        dtype, size = COMPONENTS[a["componentType"]]
        width = WIDTH[a["type"]]
        stride = view.get("byteStride", size * width)
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        raw = np.frombuffer(buffers[view["buffer"]], np.uint8)
        rows = np.lib.stride_tricks.as_strided(raw[start:], (a["count"], size * width), (stride, 1))
        return rows.copy().view(dtype).reshape(a["count"], width)

    positions, normals, faces, mesh_id, material_id, mesh_names = [], [], [], [], [], []
    material_names = [m.get("name", "material%d" % i) for i, m in enumerate(doc.get("materials", []))] + ["(default)"]

    def visit(n, parent):
        node = doc["nodes"][n]
        world = parent @ node_matrix(node)
        if "mesh" in node:
            mesh = doc["meshes"][node["mesh"]]
            name = node.get("name") or mesh.get("name") or "mesh%d" % node["mesh"]
            for prim in mesh["primitives"]:
                if prim.get("mode", 4) not in (4, 5, 6):
                    continue
                p = accessor(prim["attributes"]["POSITION"]).astype(np.float64)
                nn = accessor(prim["attributes"]["NORMAL"]).astype(np.float64)
                if "indices" in prim:
                    index = accessor(prim["indices"]).reshape(-1).astype(np.int64)
                else:
                    index = np.arange(len(p))
                if prim.get("mode", 4) == 4:
                    tri = index.reshape(-1, 3)
                else:
                    sys.exit(f"{path}: triangle strips and fans are not read here")
                faces.append(tri + sum(len(q) for q in positions))
                p = p @ world[:3, :3].T + world[:3, 3]
                nn = nn @ np.linalg.inv(world[:3, :3])
                nn /= np.maximum(np.linalg.norm(nn, axis=1, keepdims=True), 1e-30)
                mesh_names.append(name)
                positions.append(p)
                normals.append(nn)
                mesh_id.append(np.full(len(p), len(mesh_names) - 1))
                material_id.append(np.full(len(p), prim.get("material", len(material_names) - 1)))
        for c in node.get("children", []):
            visit(c, world)

    for n in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(n, np.eye(4))
    return (np.concatenate(positions), np.concatenate(normals), np.concatenate(faces), np.concatenate(mesh_id),
            np.concatenate(material_id), mesh_names, material_names)


# ---------------------------------------------------------------------------------------------

def oriented_faces(positions, normals, faces):
    """The faces wound so that their CCW side is qsgi's front (the side the vertex normals face)."""
    a, b, c = positions[faces[:, 0]], positions[faces[:, 1]], positions[faces[:, 2]]
    g = np.cross(b - a, c - a)
    flip = np.sum(g * normals[faces].sum(1), 1) < 0
    out = faces.copy()
    out[flip] = out[flip][:, [0, 2, 1]]
    return out, int(flip.sum())


def build_scene(positions, faces, face_albedo, sky, two_sided, workdir):
    """One Mitsuba mesh per albedo; returns the scene and, per shape, the global face indices."""
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 64, "rr_depth": 8},
             "sky": {"type": "constant", "radiance": {"type": "rgb", "value": list(sky)}}}
    keys, inverse = np.unique(face_albedo, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    shape_faces = []
    for g, albedo in enumerate(keys):
        members = np.flatnonzero(inverse == g)
        tri = faces[members]
        used, remap = np.unique(tri.reshape(-1), return_inverse=True)
        path = os.path.join(workdir, f"group{g}.ply")
        verts = positions[used].astype("<f4")
        fa = np.zeros(len(tri), FACE_DTYPE)
        fa["n"] = 3
        fa["v"] = remap.reshape(-1, 3)
        with open(path, "wb") as f:
            f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\nproperty float x\n"
                     f"property float y\nproperty float z\nelement face {len(tri)}\n"
                     f"property list uchar int vertex_indices\nend_header\n").encode("ascii"))
            f.write(verts.tobytes())
            f.write(fa.tobytes())
        bsdf = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [float(x) for x in albedo]}}
        if two_sided:
            bsdf = {"type": "twosided", "bsdf": bsdf}
        scene[f"group{g:03d}"] = {"type": "ply", "filename": path, "face_normals": True, "bsdf": bsdf}
        shape_faces.append(members)
    loaded = mi.load_dict(scene)
    # Shapes come back in the dict's key order? Match them by face count and ids, not by trust.
    shapes = list(loaded.shapes())
    by_name = {}
    for s in shapes:
        by_name[s.id()] = s
    ordered = [by_name[f"group{g:03d}"] for g in range(len(keys))]
    for s, members in zip(ordered, shape_faces):
        if s.face_count() != len(members):
            sys.exit("helmet_reference.py: a Mitsuba shape's face count does not match its group")
    return loaded, ordered, shape_faces


def vec(a, idx=None):
    """A Dr.Jit 3-vector from an (n, 3) array, gathered by idx when given."""
    cols = [mi.Float(np.ascontiguousarray(a[:, k], np.float32)) for k in range(3)]
    if idx is not None:
        cols = [dr.gather(mi.Float, c, idx) for c in cols]
    return cols


def sky_share(scene, origins, normals, rays, seed, chunk):
    """The stratified cosine-weighted share of escaping rays from each origin about its normal."""
    side = int(round(np.sqrt(rays)))
    if side * side != rays:
        sys.exit("--sky-rays must be a square (e.g. 256, 1024)")
    out = np.zeros(len(origins))
    for start in range(0, len(origins), chunk):
        end = min(len(origins), start + chunk)
        size = (end - start) * rays
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(seed * 1000003 + start, size)
        i = dr.arange(mi.UInt32, size)
        idx = i // rays
        j = i - idx * rays
        sx, sy = mi.Float(j % side), mi.Float(j // side)
        u = sampler.next_2d()
        sample = mi.Point2f((sx + u.x) / side, (sy + u.y) / side)
        o = mi.Point3f(*vec(origins[start:end], idx))
        n = mi.Normal3f(*vec(normals[start:end], idx))
        d = mi.Frame3f(n).to_world(mi.warp.square_to_cosine_hemisphere(sample))
        blocked = scene.ray_test(mi.Ray3f(o, d))
        hits = np.array(blocked, dtype=bool).reshape(end - start, rays)
        out[start:end] = 1.0 - hits.mean(1)
    return out


def contacts(scene, shapes, shape_faces, origins, normals, distance):
    """The first hit along +n within `distance`: its distance (inf: none) and global face (-1)."""
    o = mi.Point3f(*vec(origins))
    d = mi.Vector3f(*vec(normals))
    ray = mi.Ray3f(o, d)
    ray.maxt = mi.Float(distance)
    si = scene.ray_intersect(ray)
    valid = np.array(si.is_valid(), dtype=bool)
    t = np.where(valid, np.array(si.t, np.float64), np.inf)
    prim = np.array(si.prim_index, np.int64)
    face = np.full(len(origins), -1, np.int64)
    for s, members in zip(shapes, shape_faces):
        mine = np.array(si.shape == mi.ShapePtr(s), dtype=bool) & valid
        face[mine] = members[prim[mine]]
    return t, face


def irradiance_indirect(scene, origins, normals, spp, seed, chunk):
    """pi x the mean radiance from the first surface hit along cosine rays (escaping rays: 0), and
    the standard error of that mean from the samples' spread (RGB)."""
    integrator = scene.integrator()

    def sample(o, nn, sampler):
        d = mi.Frame3f(nn).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d()))
        ray = mi.Ray3f(o, d)
        hit = scene.ray_intersect(ray).is_valid()
        L, _, _ = integrator.sample(scene, sampler, mi.RayDifferential3f(ray))
        return dr.select(hit, L, 0.0) * dr.pi

    return per_vertex_samples(origins, normals, spp, seed * 1000003 + 7919, chunk, sample)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("frame_ply")
    ap.add_argument("out")
    ap.add_argument("--sky", default="1,1,1", help="R,G,B radiance of the uniform sky (default 1,1,1)")
    ap.add_argument("--offset", type=float, default=1e-6, help="start points v + OFFSET n, metres (default 1e-6)")
    ap.add_argument("--sky-rays", type=int, default=1024, help="sky-share rays per vertex in each of two passes, a square "
                                                               "(default 1024: 2048 in all)")
    ap.add_argument("--spp", type=int, default=256, help="paths per vertex for the interreflections (default 256)")
    ap.add_argument("--vertices", type=int, help="E at this many vertices only, drawn uniformly (seeded)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--contact", type=float, default=1e-3, help="contact: a hit along +n within this (default 1e-3 m)")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit worker threads (0: all cores)")
    ap.add_argument("--chunk", type=int, default=1024, help="vertices per wavefront")
    ap.add_argument("--two-sided", action="store_true", help="both sides of every triangle reflect (default: the back is black, as in qsgi's gather)")
    args = ap.parse_args()

    mi.set_variant("llvm_ad_rgb")
    if args.threads > 0:
        dr.set_thread_count(args.threads)
    started = time.time()
    positions, normals, faces = read_ply(args.frame_ply)
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    g_positions, g_normals, g_faces, mesh_id, material_id, mesh_names, material_names = flatten_gltf(args.scene)
    if len(g_positions) != len(positions):
        sys.exit(f"{args.frame_ply} has {len(positions)} vertices but {args.scene} flattens to {len(g_positions)}")
    worst = float(np.abs(g_positions - positions).max())
    if worst > 1e-5:
        sys.exit(f"{args.frame_ply}: its vertices are not {args.scene}'s in qsgi's order (off by {worst:.3g} m)")
    normal_dot = np.sum(g_normals * normals, 1)
    same_faces = g_faces.shape == faces.shape and bool(np.all(g_faces == faces))
    albedo, emission = gltf_vertex_materials(args.scene)
    if np.any(emission > 0):
        print("helmet_reference.py: the scene has emissive materials; they are not counted here", file=sys.stderr)
    sky = [float(c) for c in args.sky.split(",")]
    sky = sky * 3 if len(sky) == 1 else sky
    oriented, flipped = oriented_faces(positions, normals, faces)
    face_albedo = albedo[faces[:, 0]]
    # A face whose corners disagree on albedo (a face across two materials) takes the first's.
    with tempfile.TemporaryDirectory() as workdir:
        scene, shapes, shape_faces = build_scene(positions, oriented, face_albedo, sky, args.two_sided, workdir)
    origins = positions + normals * args.offset
    chunk_rays = max(1, args.chunk * 256 // args.sky_rays)

    t0 = time.time()
    # Two independent stratified passes: s_v is their mean, and its variance is estimated by
    # (s1 - s2)^2 / 4 (unbiased; the true error of stratified rays, not a binomial bound).
    s1 = sky_share(scene, origins, normals, args.sky_rays, 2 * args.seed, chunk_rays)
    s2 = sky_share(scene, origins, normals, args.sky_rays, 2 * args.seed + 1, chunk_rays)
    s = 0.5 * (s1 + s2)
    s_var = 0.25 * (s1 - s2) ** 2
    t_sky = time.time() - t0
    contact_t, contact_face = contacts(scene, shapes, shape_faces, origins, normals, args.contact)
    contact = np.isfinite(contact_t)
    contact_mesh = np.where(contact_face >= 0, mesh_id[faces[np.maximum(contact_face, 0), 0]], -1)
    contact_own = np.zeros(len(positions), bool)
    hit = np.flatnonzero(contact_face >= 0)
    contact_own[hit] = np.any(faces[contact_face[hit]] == hit[:, None], axis=1)

    chosen = np.arange(len(positions))
    if args.vertices is not None and args.vertices < len(positions):
        chosen = np.sort(np.random.default_rng(args.seed).choice(len(positions), args.vertices, replace=False))
    referenced = np.zeros(len(positions), bool)
    referenced[chosen] = True
    t0 = time.time()
    ind, ind_err = irradiance_indirect(scene, origins[chosen], normals[chosen], args.spp, args.seed,
                                       max(1, args.chunk * 256 // args.spp))
    t_paths = time.time() - t0
    E = np.zeros((len(positions), 3))
    E_err = np.zeros((len(positions), 3))
    E_ind = np.zeros((len(positions), 3))
    direct = np.pi * np.array(sky)[None, :] * s[chosen, None]
    direct_err = np.pi * np.array(sky)[None, :] * np.sqrt(s_var[chosen])[:, None]
    E[chosen] = direct + ind
    E_ind[chosen] = ind
    E_err[chosen] = np.sqrt(ind_err ** 2 + direct_err ** 2)
    seconds = time.time() - started
    comment = (f"helmet reference: Mitsuba {mi.__version__}, offset {args.offset:g} m, {args.sky_rays} stratified sky rays "
               f"and {args.spp} paths per vertex ({'two-sided' if args.two_sided else 'one-sided'} Lambertian), "
               f"seed {args.seed}, E at {len(chosen)} of {len(positions)} vertices, contact within {args.contact:g} m; "
               f"{seconds:.0f} s (sky share {t_sky:.0f} s, paths {t_paths:.0f} s, {dr.thread_count()} threads); "
               f"{flipped} faces rewound to qsgi's front")
    tmp = args.out + ".tmp.npz"
    np.savez_compressed(tmp, positions=positions, normals=normals, faces=faces, mesh_id=mesh_id,
                        mesh_names=np.array(mesh_names), material_id=material_id, material_names=np.array(material_names),
                        albedo=albedo, sky_share=s, sky_share_var=s_var, sky_rays=2 * args.sky_rays, contact=contact, contact_distance=contact_t,
                        contact_mesh=contact_mesh, contact_own=contact_own, referenced=referenced, E=E, E_stderr=E_err,
                        E_indirect=E_ind, spp=args.spp, offset=args.offset, seed=args.seed, sky=np.array(sky),
                        seconds=seconds, gltf_normal_dot=normal_dot, comment=comment)
    os.replace(tmp, args.out)
    print(comment)
    print(f"contacts: {int(contact.sum())} vertices ({int(contact_own.sum())} of them meet a triangle of their own); "
          f"sky share 0 at {int((s == 0).sum())}; PLY normals vs glTF's: min dot {normal_dot.min():.4f}; "
          f"PLY triangles {'the same as' if same_faces else 'NOT the same as'} the glTF's")


if __name__ == "__main__":
    main()
