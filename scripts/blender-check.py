#!/usr/bin/env python3
"""Open a qsgi output folder in Blender (the `bpy` module) the way an artist would, and check
that the bake plays there.

    /work/venvs/bpy/bin/python scripts/blender-check.py OUT [--frames 0,2,5]

Needs a Python 3.11 with `bpy==5.0.1` from PyPI (about 1 GB; it brings numpy and OpenUSD's
`pxr`), e.g.:

    python3.11 -m venv ~/venvs/bpy && ~/venvs/bpy/bin/pip install bpy==5.0.1

Not a CI test: Blender is too large for CI. What it does:

USD (OUT/asset.usda, written by `qsgi render --usd-out`):
  - imports it into a fresh scene with bpy.ops.wm.usd_import's default options, timed;
  - checks that Blender's frame range is the stage's startTimeCode..endTimeCode;
  - at each checked frame (default 0, 2 and 5, those within the run's range) reads every mesh
    object's evaluated POINT attribute "radiance" (depsgraph, evaluated_get) and compares it
    with OUT/frame_NNNN.ply's radiosity x float32(1/pi), vertex by vertex: the mesh's USD
    point i is PLY vertex qsgi:firstVertex + i. It also compares the evaluated world positions
    with the PLY's (so a rigid mover's time-sampled transform must play), and checks that
    every PLY vertex is covered once;
  - checks that the colours change between frames where the PLYs change (the bake animates);
  - checks that each mesh's material shows the bake by emission: an Attribute (or Color
    Attribute) node reading "radiance" feeds the Principled BSDF's Emission Color.
glTF (OUT/asset.glb, written by --gltf-out):
  - imports it into another fresh scene with bpy.ops.import_scene.gltf's default options,
    timed, and reports success or the exception;
  - if it imports, reads COLOR_0 and _RADIANCE at the first and last keyed frame and says
    whether they differ (in Blender 5.0.1 they do not: its shape keys carry positions only, so
    the bake of a glTF does not animate in Blender; use the USD).

Exit status: 0 when the USD matches the PLYs on every check and the glTF imports, 1 otherwise
(2 for a usage error).
"""
import argparse
import contextlib
import math
import os
import re
import sys
import tempfile
import time

try:
    import bpy
except ImportError:
    print("blender-check.py needs the bpy module: run it with a Python 3.11 that has "
          "`pip install bpy==5.0.1` (see the top of this file)", file=sys.stderr)
    sys.exit(2)
import numpy as np

INV_PI = np.float32(1.0 / math.pi)
# Radiance is written in shortest round-trip form and Blender keeps float32: equal bits are
# expected; allow a few ulps.
REL_TOL = 1e-6
ABS_TOL = 1e-30
# World positions go through float32 points, a double transform and Blender's float32
# matrix_world, which Blender keeps as float32 location, rotation and scale: decomposing a
# rotation near ±90° (gimbal lock) that way loses about 2e-4 radians (2CylinderEngine: 9.8e-5 of
# the extent, with the USD's matrices exact). Allow this fraction of the scene's extent.
POS_TOL = 2e-4

PLY_VERTEX_PROPS = ["x", "y", "z", "nx", "ny", "nz",
                    "radiosity_r", "radiosity_g", "radiosity_b",
                    "irradiance_r", "irradiance_g", "irradiance_b",
                    "red", "green", "blue"]
PLY_TYPES = {"float": "<f4", "float32": "<f4", "uchar": "u1", "uint8": "u1",
             "int": "<i4", "int32": "<i4", "uint": "<u4", "double": "<f8"}


def import_pxr():
    """bpy bundles OpenUSD's Python modules in its own tree, off sys.path: put them first, so
    that the stage is read by the same USD that Blender's importer links."""
    site = os.path.join(bpy.utils.resource_path("LOCAL"), "python", "lib",
                        "python%d.%d" % sys.version_info[:2], "site-packages")
    if os.path.isdir(os.path.join(site, "pxr")) and site not in sys.path:
        sys.path.insert(0, site)
    from pxr import Usd, UsdGeom  # noqa: F401
    return Usd, UsdGeom


def read_ply_vertices(path):
    """The vertex element of a qsgi PLY as a numpy structured array."""
    with open(path, "rb") as fh:
        if fh.readline().strip() != b"ply":
            raise ValueError(f"{path}: not a PLY file")
        fmt, count, props, element = None, None, [], None
        while True:
            line = fh.readline()
            if not line:
                raise ValueError(f"{path}: no end_header")
            words = line.decode("ascii", "replace").split()
            if not words or words[0] in ("comment", "obj_info"):
                continue
            if words[0] == "end_header":
                break
            if words[0] == "format":
                fmt = words[1]
            elif words[0] == "element":
                element = words[1]
                if element == "vertex":
                    count = int(words[2])
            elif words[0] == "property" and element == "vertex":
                if words[1] == "list":
                    raise ValueError(f"{path}: list property in the vertex element")
                props.append((words[2], PLY_TYPES[words[1]]))
        if fmt != "binary_little_endian":
            raise ValueError(f"{path}: format {fmt}, expected binary_little_endian")
        names = [n for n, _ in props]
        if names != PLY_VERTEX_PROPS:
            raise ValueError(f"{path}: vertex properties {names}, expected qsgi's {PLY_VERTEX_PROPS}")
        dt = np.dtype(props)
        data = np.frombuffer(fh.read(dt.itemsize * count), dtype=dt, count=count)
    return data


def ply_arrays(path):
    v = read_ply_vertices(path)
    pos = np.stack([v["x"], v["y"], v["z"]], axis=1)
    radiosity = np.stack([v["radiosity_r"], v["radiosity_g"], v["radiosity_b"]], axis=1)
    radiance = (radiosity * INV_PI).astype(np.float32)  # B/pi computed in float32, as qsgi does
    return pos, radiance


@contextlib.contextmanager
def captured_output(lines):
    """Catches what Blender and USD print to stdout/stderr (C level) while importing."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 1)
        os.dup2(tmp.fileno(), 2)
        try:
            yield
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            tmp.seek(0)
            lines.extend(tmp.read().decode("utf-8", "replace").splitlines())


def fresh_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)


def attribute_array(mesh, name, n):
    """Float RGB(A) values of a mesh attribute, or None when the attribute is missing."""
    a = mesh.attributes.get(name)
    if a is None:
        return None, None
    width = {"FLOAT_COLOR": 4, "BYTE_COLOR": 4, "FLOAT_VECTOR": 3, "FLOAT": 1}.get(a.data_type)
    if width is None:
        return None, a
    field = {"FLOAT_COLOR": "color", "BYTE_COLOR": "color", "FLOAT_VECTOR": "vector", "FLOAT": "value"}[a.data_type]
    buf = np.empty(len(a.data) * width, np.float32)
    a.data.foreach_get(field, buf)
    return buf.reshape(-1, width), a


def world_positions(obj_eval, mesh):
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3).astype(np.float64)
    m = np.array(obj_eval.matrix_world, dtype=np.float64)
    return co @ m[:3, :3].T + m[:3, 3]


def upstream_nodes(tree, socket):
    """Every node whose output reaches `socket`, through any chain of links."""
    seen, todo = set(), [socket]
    while todo:
        s = todo.pop()
        for link in tree.links:
            if link.to_socket == s and link.is_valid and not link.is_muted:
                n = link.from_node
                if n.name not in seen:
                    seen.add(n.name)
                    todo.extend(n.inputs)
    return [tree.nodes[n] for n in seen]


def check_material(mat, primvar="radiance"):
    """(ok, description) for a material that should show the bake by emission."""
    if mat is None:
        return False, "no material"
    tree = mat.node_tree
    if tree is None:
        return False, f"{mat.name}: no node tree"
    bsdfs = [n for n in tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"]
    if not bsdfs:
        return False, f"{mat.name}: no Principled BSDF"
    for p in bsdfs:
        readers = [n for n in upstream_nodes(tree, p.inputs["Emission Color"])
                   if (n.bl_idname == "ShaderNodeAttribute" and n.attribute_name == primvar)
                   or (n.bl_idname == "ShaderNodeVertexColor" and n.layer_name == primvar)]
        if readers:
            strength = p.inputs["Emission Strength"]
            if not strength.is_linked and strength.default_value <= 0:
                return False, f"{mat.name}: \"{primvar}\" feeds Emission Color but Emission Strength is 0"
            base = p.inputs["Base Color"]
            base_txt = "linked" if base.is_linked else "(%.3g, %.3g, %.3g)" % tuple(base.default_value[:3])
            return True, (f"{mat.name}: {readers[0].bl_idname[10:]} \"{primvar}\" -> Emission Color, strength "
                          f"{strength.default_value:g}, base colour {base_txt}, IOR {p.inputs['IOR'].default_value:g}")
    return False, f"{mat.name}: nothing reads \"{primvar}\" into a Principled BSDF's Emission Color"


# ---------------------------------------------------------------------------------------- USD

def usd_check(out, frames_wanted):
    """Returns (ok, list of problem lines)."""
    problems = []
    usda = os.path.join(out, "asset.usda")
    print(f"== USD: {usda}")
    if not os.path.isfile(usda):
        print("   missing (render with --usd-out)")
        return False, [f"{usda} is missing"]

    fresh_scene()
    log = []
    t0 = time.perf_counter()
    with captured_output(log):
        result = bpy.ops.wm.usd_import(filepath=os.path.abspath(usda))
    import_s = time.perf_counter() - t0
    print(f"   import: {sorted(result)} in {import_s:.3f} s (bpy.ops.wm.usd_import, default options)")
    notes = [l for l in log if l.strip() and not re.match(r"USD import of '.*' took", l)]
    warn = [l for l in notes if re.search(r"warn|error|fail|invalid|unsupported", l, re.I)]
    print(f"   importer messages: {len(notes)} ({len(warn)} warnings or errors)")
    for l in notes[:20]:
        print("     | " + l)
    if "FINISHED" not in result:
        return False, [f"usd_import returned {sorted(result)}"]
    # Opened only after the import: the layer registry is shared with Blender's importer in this
    # process, so a stage opened first would leave the parse out of the import time.
    Usd, UsdGeom = import_pxr()
    stage = Usd.Stage.Open(usda)
    start, end = stage.GetStartTimeCode(), stage.GetEndTimeCode()
    tcps, fps = stage.GetTimeCodesPerSecond(), stage.GetFramesPerSecond()
    print(f"   stage: time codes {start:g}..{end:g}, timeCodesPerSecond {tcps:g}, framesPerSecond {fps:g}, "
          f"upAxis {UsdGeom.GetStageUpAxis(stage)}, metersPerUnit {UsdGeom.GetStageMetersPerUnit(stage):g} "
          f"(OpenUSD {'.'.join(map(str, Usd.GetVersion()))} as bundled with bpy)")
    usd_meshes = {str(p.GetPath()): p for p in stage.Traverse() if p.IsA(UsdGeom.Mesh)}
    # USD interpolates linearly between time samples, and Blender reads the stage at time code =
    # frame: a frame left out would show a blend of its neighbours, never its own bake.
    lo, hi = round(start), round(end)
    every = set(range(lo, hi + 1))
    for path, prim in sorted(usd_meshes.items()):
        pv = UsdGeom.PrimvarsAPI(prim).GetPrimvar("radiance")
        if not pv:
            problems.append(f"{path} has no primvars:radiance")
            continue
        samples = set(pv.GetAttr().GetTimeSamples())
        if not every <= samples:
            gone = sorted(every - samples)
            problems.append(f"{path}.primvars:radiance has no time sample at frame(s) {gone[:10]}{' ...' if len(gone) > 10 else ''}")
    ply_frames = sorted(int(m.group(1)) for m in (re.fullmatch(r"frame_(\d+)\.ply", n) for n in os.listdir(out)) if m)
    if ply_frames and (ply_frames[0], ply_frames[-1]) != (lo, hi):
        problems.append(f"the PLYs in {out} are frames {ply_frames[0]}..{ply_frames[-1]}, the USD's time codes {start:g}..{end:g}")

    scene = bpy.context.scene
    bfps = scene.render.fps / scene.render.fps_base
    print(f"   Blender: frame range {scene.frame_start}..{scene.frame_end}, fps {bfps:g}")
    if abs(bfps - fps) > 1e-6 or abs(bfps - tcps) > 1e-6:
        print(f"   note: Blender keeps its own {bfps:g} fps (the importer does not apply the stage's); it reads time code = "
              f"frame, so every frame shows its own bake, but playback runs at {bfps:g} fps: set the scene's frame rate "
              f"to {fps:g} to play at the animation's speed")
    if (scene.frame_start, scene.frame_end) != (round(start), round(end)):
        problems.append(f"Blender's frame range {scene.frame_start}..{scene.frame_end} is not the USD's {start:g}..{end:g}")

    # Blender's world is Z up: a Y-up stage arrives rotated +90 degrees about X, scaled by
    # metersPerUnit (apply_unit_conversion_scale).
    mpu = UsdGeom.GetStageMetersPerUnit(stage)
    if UsdGeom.GetStageUpAxis(stage) == UsdGeom.Tokens.y:
        to_blender = np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]], np.float64) * mpu
    else:
        to_blender = np.eye(3) * mpu

    # Which mesh object is which USD mesh, and where its vertices sit in the PLY.
    objects = [o for o in scene.objects if o.type == "MESH"]
    mapping = []  # (object name, prim path or None, firstVertex, vertexCount, how)
    unmapped = []
    for o in objects:
        cache = [m for m in o.modifiers if m.type == "MESH_SEQUENCE_CACHE"]
        prim_path = cache[0].object_path if cache and cache[0].object_path in usd_meshes else None
        if prim_path is None:  # by name: Blender names the object after the Mesh prim
            base = re.sub(r"\.\d{3}$", "", o.data.name)
            cands = [p for p in usd_meshes if p.rsplit("/", 1)[1] == base]
            if len(cands) != 1:
                base = re.sub(r"\.\d{3}$", "", o.name)
                cands = [p for p in usd_meshes if p.rsplit("/", 1)[1] == base or p.rsplit("/", 2)[-2] == base]
            prim_path = cands[0] if len(cands) == 1 else None
        if "qsgi:firstVertex" in o.data.keys():
            first, how = int(o.data["qsgi:firstVertex"]), "the mesh data's custom property (Blender imports it)"
            count = int(o.data["qsgi:vertexCount"]) if "qsgi:vertexCount" in o.data.keys() else None
        elif prim_path is not None and usd_meshes[prim_path].GetAttribute("qsgi:firstVertex").HasValue():
            prim = usd_meshes[prim_path]
            first, how = int(prim.GetAttribute("qsgi:firstVertex").Get()), "read from the stage with pxr"
            c = prim.GetAttribute("qsgi:vertexCount")
            count = int(c.Get()) if c.HasValue() else None
        else:
            unmapped.append(o.name)
            continue
        mapping.append((o.name, prim_path, first, count, how))
    hows = sorted({m[4] for m in mapping})
    print(f"   meshes: {len(objects)} mesh objects, {len(usd_meshes)} USD meshes; qsgi:firstVertex: {', '.join(hows) or '-'}")
    if unmapped:
        problems.append(f"no qsgi:firstVertex for mesh objects {unmapped}")
    if len(objects) != len(usd_meshes):
        problems.append(f"{len(objects)} mesh objects for {len(usd_meshes)} USD meshes")

    # Materials.
    mat_lines = {}
    for o in objects:
        slots = [s.material for s in o.material_slots] or [None]
        for m in slots:
            ok, desc = check_material(m)
            mat_lines[desc] = ok
            if not ok:
                problems.append(f"{o.name}: material does not show the bake by emission ({desc})")
    print(f"   materials: {sum(mat_lines.values())} of {len(mat_lines)} show \"radiance\" by emission")
    for desc, ok in sorted(mat_lines.items()):
        print(f"     {'ok ' if ok else 'BAD'} {desc}")

    # Frames.
    frames = [f for f in frames_wanted if lo <= f <= hi]
    if len(frames) < 2 and hi > lo:
        # Fewer than two frames would leave the animation unchecked: add the range's ends.
        frames = sorted(set(frames) | {lo, hi})
        print(f"   of the frames {frames_wanted}, {len(frames_wanted) - len([f for f in frames_wanted if lo <= f <= hi])} "
              f"are outside the run's {lo}..{hi}: checking {frames}")
    elif not frames:
        frames = [lo]
    missing = [f for f in frames if not os.path.isfile(os.path.join(out, f"frame_{f:04d}.ply"))]
    for f in missing:
        problems.append(f"frame_{f:04d}.ply is missing")
    frames = [f for f in frames if f not in missing]

    rows = []
    ref = None  # (frame, {object: radiance}, ply radiance) of the first checked frame
    for f in frames:
        try:
            ply_pos, ply_rad = ply_arrays(os.path.join(out, f"frame_{f:04d}.ply"))
        except (ValueError, KeyError, OSError) as e:
            problems.append(f"frame_{f:04d}.ply: {e}")
            continue
        extent = float(np.abs(ply_pos).max()) if len(ply_pos) else 1.0
        t_eval = time.perf_counter()
        scene.frame_set(f)  # evaluates the depsgraph: the Mesh Sequence Cache reads this frame
        dg = bpy.context.evaluated_depsgraph_get()
        t_eval = time.perf_counter() - t_eval
        covered = np.zeros(len(ply_rad), np.int32)
        max_abs = max_rel = max_pos = 0.0
        n_cmp, n_bad, n_meshes = 0, 0, 0
        got = {}
        for name, prim_path, first, count, _ in mapping:
            o = scene.objects[name]
            oe = o.evaluated_get(dg)
            me = oe.to_mesh()
            try:
                vals, attr = attribute_array(me, "radiance", len(me.vertices))
                if attr is None:
                    problems.append(f"frame {f}: {name} has no attribute \"radiance\"")
                    continue
                if attr.domain != "POINT" or attr.data_type != "FLOAT_COLOR":
                    problems.append(f"frame {f}: {name}'s \"radiance\" is {attr.domain} {attr.data_type}, "
                                    "not POINT FLOAT_COLOR")
                    if vals is None or attr.domain != "POINT":
                        continue
                n = len(me.vertices)
                if count is not None and count != n:
                    problems.append(f"frame {f}: {name} has {n} vertices, qsgi:vertexCount says {count}")
                if first < 0 or first + n > len(ply_rad):
                    problems.append(f"frame {f}: {name}'s vertices {first}..{first + n - 1} are outside the PLY's {len(ply_rad)}")
                    continue
                rgb = vals[:, :3].astype(np.float32)
                want = ply_rad[first:first + n]
                err = np.abs(rgb.astype(np.float64) - want)
                mag = np.abs(want.astype(np.float64))
                rel = np.divide(err, mag, out=np.where(err > 0, np.inf, 0.0), where=mag > 0)
                bad = err > np.maximum(REL_TOL * mag, ABS_TOL)
                max_abs = max(max_abs, float(err.max()) if n else 0.0)
                max_rel = max(max_rel, float(rel.max()) if n else 0.0)
                n_bad += int(bad.any(axis=1).sum())
                pos = world_positions(oe, me)
                want_pos = ply_pos[first:first + n].astype(np.float64) @ to_blender.T
                max_pos = max(max_pos, float(np.abs(pos - want_pos).max() / max(extent * mpu, 1e-30)) if n else 0.0)
                covered[first:first + n] += 1
                n_cmp += n
                n_meshes += 1
                got[name] = rgb.copy()
            finally:
                oe.to_mesh_clear()
        if n_bad:
            problems.append(f"frame {f}: {n_bad} vertices' radiance differ from the PLY (max abs {max_abs:.3g}, rel {max_rel:.3g})")
        if max_pos > POS_TOL:
            problems.append(f"frame {f}: world positions differ from the PLY's by up to {max_pos:.3g} of the scene's extent "
                            "(a transform or deformation that does not play?)")
        unc, dup = int((covered == 0).sum()), int((covered > 1).sum())
        if unc or dup:
            problems.append(f"frame {f}: of the PLY's {len(ply_rad)} vertices, {unc} are in no mesh and {dup} in more than one")
        if ref is None:
            ref = (f, got, ply_rad)
            ply_changed = bl_changed = None
        else:
            ply_changed = not np.array_equal(ply_rad, ref[2])
            bl_changed = any(not np.array_equal(got[k], ref[1][k]) for k in got if k in ref[1])
            if ply_changed and not bl_changed:
                problems.append(f"frame {f}: the PLY differs from frame {ref[0]}'s but Blender shows frame {ref[0]}'s colours")
        rows.append((f, t_eval, n_meshes, n_cmp, len(ply_rad), max_abs, max_rel, max_pos, ply_changed, bl_changed, n_bad == 0 and max_pos <= POS_TOL and not unc and not dup))

    if rows:
        r0 = rows[0][0]
        print("   radiance = PLY radiosity x float32(1/pi) vs the evaluated POINT attribute \"radiance\"; positions vs the "
              "PLY's, in units of the scene's extent; eval s = frame_set's depsgraph evaluation")
        hdr = f"   {'frame':>5} {'eval s':>6} {'meshes':>6} {'vertices':>15} {'max abs err':>11} {'max rel err':>11} {'max pos err':>11} {f'PLY != f{r0}':>11} {f'Blender != f{r0}':>15}  result"
        print(hdr)
        for f, te, nm, nc, nply, ma, mr, mp, pc, bc, ok in rows:
            yn = lambda x: "-" if x is None else ("yes" if x else "no")
            print(f"   {f:>5} {te:>6.3f} {nm:>6} {f'{nc}/{nply}':>15} {ma:>11.3g} {mr:>11.3g} {mp:>11.3g} {yn(pc):>11} {yn(bc):>15}  {'ok' if ok else 'MISMATCH'}")
        if len(rows) > 1 and not any(r[8] for r in rows[1:]):
            print("   note: the PLYs of the checked frames are equal, so the animation of the bake could not be checked")
    else:
        problems.append("no frame checked")
    print(f"   USD import time: {import_s:.3f} s")
    return not problems, problems


# ---------------------------------------------------------------------------------------- glTF

def gltf_check(out):
    glb = os.path.join(out, "asset.glb")
    print(f"== glTF: {glb}")
    if not os.path.isfile(glb):
        print("   missing (render with --gltf-out)")
        return False, [f"{glb} is missing"]
    fresh_scene()
    log = []
    t0 = time.perf_counter()
    try:
        with captured_output(log):
            result = bpy.ops.import_scene.gltf(filepath=os.path.abspath(glb))
    except Exception as e:  # the importer raises through the operator as a RuntimeError
        dt = time.perf_counter() - t0
        msg = [l for l in str(e).splitlines() if l.strip()]
        # The operator wraps the importer's traceback: name the Python error it ended with.
        errs = [l.strip() for l in msg if re.match(r"\s*\w+(Error|Exception)\b.*:", l)]
        what = errs[-1] if errs else (msg[0].strip() if msg else type(e).__name__)
        print(f"   import FAILED after {dt:.3f} s: {what}")
        for l in [l for l in msg if l.strip().startswith("File ")][-3:]:
            print("     | " + l.strip())
        return False, [f"glTF import failed: {what}"]
    dt = time.perf_counter() - t0
    print(f"   import: {sorted(result)} in {dt:.3f} s (bpy.ops.import_scene.gltf, default options)")
    notes = [l for l in log if l.strip()]
    if notes:
        print(f"   importer messages: {len(notes)}")
        for l in notes[:10]:
            print("     | " + l)
    if "FINISHED" not in result:
        return False, [f"glTF import returned {sorted(result)}"]
    scene = bpy.context.scene
    meshes = [o for o in scene.objects if o.type == "MESH"]
    print(f"   {len(meshes)} mesh objects, {len(bpy.data.actions)} actions; Blender's frame range "
          f"{scene.frame_start}..{scene.frame_end}, fps {scene.render.fps / scene.render.fps_base:g}")
    # The frames to compare: where the asset's morph-target weights are first and last keyed
    # (Blender places a key at its time x the scene's fps).
    times = weight_key_times(glb)
    fps = scene.render.fps / scene.render.fps_base
    if times:
        f0, f1 = int(round(times[0] * fps)), int(round(times[1] * fps))
        print(f"   the asset's weights are keyed from {times[0]:g} s to {times[1]:g} s: Blender frames {f0}..{f1}")
    else:
        f0, f1 = scene.frame_start, scene.frame_end
    # Names Blender gives what the asset carries: COLOR_0 becomes a colour attribute ("Color"),
    # custom attributes keep their names.
    def colour_sets(dg):
        res = {}
        for o in meshes:
            oe = o.evaluated_get(dg)
            me = oe.to_mesh()
            try:
                for a in me.attributes:
                    if a.name.upper() in ("_RADIANCE", "_IRRADIANCE") or a.name in me.color_attributes.keys():
                        vals, _ = attribute_array(me, a.name, len(me.vertices))
                        if vals is not None:
                            res[(o.name, a.name, a.domain, a.data_type)] = vals.copy()
            finally:
                oe.to_mesh_clear()
        return res
    def shape_key_values():
        return {(o.name, k.name): k.value for o in meshes if o.data.shape_keys
                for k in o.data.shape_keys.key_blocks}
    scene.frame_set(f0)
    at0, sk0 = colour_sets(bpy.context.evaluated_depsgraph_get()), shape_key_values()
    scene.frame_set(f1)
    at1, sk1 = colour_sets(bpy.context.evaluated_depsgraph_get()), shape_key_values()
    moved = sum(1 for k in sk0 if sk0[k] != sk1.get(k))
    print(f"   shape keys: {len(sk0)}, {moved} of them change value between frames {f0} and {f1} (the weights play)")
    names = sorted({(k[1], k[2], k[3]) for k in at0})
    print(f"   colour attributes: {', '.join(f'{n} ({d} {t})' for n, d, t in names) or 'none'}")
    changed = sorted({k[1] for k in at0 if k in at1 and not np.array_equal(at0[k], at1[k])})
    base_fed = 0
    for m in bpy.data.materials:
        if m.node_tree:
            for p in (n for n in m.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"):
                if any(n.bl_idname in ("ShaderNodeVertexColor", "ShaderNodeAttribute") for n in upstream_nodes(m.node_tree, p.inputs["Base Color"])):
                    base_fed += 1
    if f0 == f1:
        print("   one keyed frame only: whether the colours animate cannot be seen")
    elif changed:
        print(f"   frames {f0} and {f1}: {', '.join(changed)} differ")
    else:
        print(f"   frames {f0} and {f1}: the colour attributes are EQUAL: glTF colours do not animate in Blender "
              "(its shape keys carry positions only); use asset.usda to see the bake play")
    if base_fed:
        print(f"   {base_fed} material(s) take the colour attribute as Base Color (albedo), not as emission")
    return True, []


def weight_key_times(glb):
    """(first, last) key time in seconds of the asset's morph-target weights channels, or None."""
    import json
    import struct
    with open(glb, "rb") as fh:
        head = fh.read(20)
        if len(head) < 20 or head[:4] != b"glTF":
            return None
        n = struct.unpack("<I", head[12:16])[0]
        doc = json.loads(fh.read(n))
    lo, hi = [], []
    for a in doc.get("animations", []):
        for c in a.get("channels", []):
            if c.get("target", {}).get("path") == "weights":
                acc = doc["accessors"][a["samplers"][c["sampler"]]["input"]]
                if "min" in acc and "max" in acc:
                    lo.append(acc["min"][0])
                    hi.append(acc["max"][0])
    return (min(lo), max(hi)) if lo else None


def main():
    ap = argparse.ArgumentParser(description="Check a qsgi output folder's asset.usda and asset.glb in Blender (bpy).")
    ap.add_argument("out", help="the output folder of a render with --usd-out (and --gltf-out)")
    ap.add_argument("--frames", default="0,2,5", help="frames to check, comma-separated (default 0,2,5; "
                    "those within the run's range)")
    a = ap.parse_args()
    try:
        frames = sorted({int(x) for x in a.frames.split(",") if x.strip()})
    except ValueError:
        ap.error(f"--frames {a.frames!r}: expected comma-separated frame numbers")
    if not os.path.isdir(a.out):
        ap.error(f"{a.out} is not a folder")
    print(f"Blender {bpy.app.version_string}, Python {sys.version.split()[0]}")
    usd_ok, usd_problems = usd_check(a.out, frames)
    gltf_ok, gltf_problems = gltf_check(a.out)
    print("== summary")
    print(f"   USD:  {'matches the PLYs' if usd_ok else 'FAILED'}")
    for p in usd_problems[:30]:
        print("     - " + p)
    if len(usd_problems) > 30:
        print(f"     - ... and {len(usd_problems) - 30} more")
    print(f"   glTF: {'imports' if gltf_ok else 'FAILED'}")
    for p in gltf_problems:
        print("     - " + p)
    return 0 if usd_ok and gltf_ok else 1


if __name__ == "__main__":
    sys.exit(main())
