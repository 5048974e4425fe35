#!/usr/bin/env python3
"""Checks OUT/asset.usda, as `qsgi render --usd-out` writes it (issue 46, item 2), with OpenUSD's own
library (usd-core, pinned by scripts/usd-check/requirements.txt), against the frames beside it.

    scripts/usd-check/venv/bin/python scripts/usd-check/check_usd.py OUT [--frames A:B]
        [--nodes N1,N2,...] [--rigid N1,...] [--deforming N1,...]

(the venv is made by scripts/setup.sh --test). What it checks, one line printed per failure:

  - the stage opens; layer metadata: defaultPrim "Scene" (an Xform of kind "assembly"), upAxis "Y",
    metersPerUnit 1, startTimeCode/endTimeCode the first and last frame (those of the
    OUT/frame_NNNN.ply present, which must be consecutive, or A and B with --frames),
    timeCodesPerSecond == framesPerSecond > 0, customLayerData's string "qsgi:version";
  - every prim's name is a valid USD identifier, and every prim lies under /Scene;
  - every Mesh: subdivisionScheme "none" (authored), every face a triangle, faceVertexIndices in
    range, the custom ints qsgi:firstVertex and qsgi:vertexCount (= its points at every frame);
    its triangles, moved by firstVertex, are the PLY's faces (as a multiset, over all meshes);
    primvars:radiance and primvars:irradiance are color3f[], not indexed, interpolation "vertex",
    with time samples at exactly every frame of the range (GetTimeSamples()), and at each frame,
    for the PLY's vertices firstVertex .. firstVertex + vertexCount - 1:
      irradiance == the PLY's irradiance, radiance == float32(radiosity * float32(1/pi)),
      each within 1 ulp of float32 (numpy's float32 spacing of the expected value);
    its extent, where authored, holds its points at that frame; its points placed by its world
    transform at that frame
    (UsdGeom.Xformable.ComputeLocalToWorldTransform) are the PLY's positions within 1e-5 of the
    frame's extent (the diagonal of the PLY's bounding box), and its normals (interpolation
    "vertex"), carried by the inverse transpose and normalised, the PLY's within 1e-4;
  - every PLY vertex belongs to exactly one mesh;
  - every Mesh is bound (UsdShade.MaterialBindingAPI.ComputeBoundMaterial) to a Material whose
    outputs:surface comes from a UsdPreviewSurface with inputs:diffuseColor (0, 0, 0) and
    inputs:ior 1, whose inputs:emissiveColor comes from the outputs:result of a
    UsdPrimvarReader_float3 whose inputs:varname is a string "radiance";
  - OpenUSD's own validation: every validator registered with UsdValidation's registry
    (ValidationRegistry().GetOrLoadAllValidators(), run by a ValidationContext over the stage
    and every time code) reports no error; its warnings are printed, and fail nothing.

With --nodes, the children of /Scene that place meshes (Materials apart) are exactly these names
(what the glTF's nodes are called); each node named by --rigid has a time-sampled transform (its
own or its meshes') and meshes whose points are not time-sampled, each named by --deforming meshes
whose points are time-sampled under transforms that are not, and every other node neither.

Ends with a summary line: meshes, vertices, frames, the largest errors, the file's bytes and bytes
per vertex-frame. Exit status: 0 when nothing failed, 1 on any failure, 2 on a wrong command line.
The checker itself is tested by tests/python/test_usd_out.py --self-test, on a hand-written asset
and broken copies of it."""
import argparse
import os
import re
import sys

import numpy as np

try:
    from pxr import Gf, Sdf, Tf, Usd, UsdGeom, UsdShade, UsdValidation
except ImportError as error:  # not the venv's python
    sys.exit(f"check_usd.py: OpenUSD's Python package is missing ({error}); run scripts/setup.sh --test "
             "and use scripts/usd-check/venv/bin/python")

FRAME_FILE = re.compile(r"^frame_(\d{4,})\.ply$")
INV_PI = np.float32(1.0 / np.pi)
POSITION_TOLERANCE = 1e-5   # of the frame's extent
NORMAL_TOLERANCE = 1e-4     # per component of unit normals
PRIMVARS = ("radiance", "irradiance")
BACK_PRIMVARS = ("backRadiance", "backIrradiance")
PLY_TYPES = {"char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1", "short": "<i2", "int16": "<i2",
             "ushort": "<u2", "uint16": "<u2", "int": "<i4", "int32": "<i4", "uint": "<u4",
             "uint32": "<u4", "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8"}


class PlyError(Exception):
    pass


def read_ply(path):
    """(vertices: a structured array of the vertex element, faces: int64 (T, 3)) of a binary
    little-endian PLY whose faces are triangles."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise PlyError("not a PLY file (no 'ply' line or no end_header)")
    body = end + len(b"end_header\n")
    elements = []  # [name, count, [(property, type) or (property, (count type, item type))]]
    for line in data[:end].decode("ascii", "replace").split("\n")[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            if words[1:2] != ["binary_little_endian"]:
                raise PlyError(f"format {' '.join(words[1:])}, not binary_little_endian")
        elif words[0] == "element":
            elements.append([words[1], int(words[2]), []])
        elif words[0] == "property" and elements:
            if words[1] == "list":
                elements[-1][2].append((words[4], (PLY_TYPES[words[2]], PLY_TYPES[words[3]])))
            else:
                elements[-1][2].append((words[2], PLY_TYPES[words[1]]))
    vertices = faces = None
    offset = body
    for name, count, properties in elements:
        lists = [p for p in properties if isinstance(p[1], tuple)]
        if not lists:
            dtype = np.dtype([(p, t) for p, t in properties])
            array = np.frombuffer(data, dtype, count, offset)
        elif name == "face" and len(properties) == 1:
            count_type, index_type = properties[0][1]
            dtype = np.dtype([("n", count_type), ("i", index_type, (3,))])
            array = np.frombuffer(data, dtype, count, offset)
            if count and not (array["n"] == 3).all():
                raise PlyError("a face is not a triangle")
        else:
            raise PlyError(f"element {name}: list properties other than the faces' are not read")
        offset += dtype.itemsize * count
        if name == "vertex":
            vertices = array
        elif name == "face":
            faces = array["i"].astype(np.int64)
    if vertices is None or faces is None:
        raise PlyError("no vertex or no face element")
    if offset > len(data):
        raise PlyError(f"{len(data)} bytes, its header promises {offset}")
    return vertices, faces


def columns(vertices, names):
    return np.stack([vertices[n] for n in names], axis=1)


def ulps(actual, expected):
    """|actual - expected| in units of float32 spacing at |expected| (both float32 arrays)."""
    if actual.size == 0:
        return 0.0
    difference = np.abs(actual.astype(np.float64) - expected.astype(np.float64))
    return float(np.max(difference / np.spacing(np.abs(expected)).astype(np.float64)))


def as_array(value, dtype=np.float64):
    return np.asarray(value if value is not None else [], dtype=dtype)


class Checker:
    def __init__(self, out, frames=None, nodes=None, rigid=(), deforming=()):
        self.out = out
        self.path = os.path.join(out, "asset.usda")
        self.requested_frames = frames
        self.nodes, self.rigid, self.deforming = nodes, set(rigid), set(deforming)
        self.failures = []
        self.warnings = []
        self.max = {"radiance": 0.0, "irradiance": 0.0, "position": 0.0, "normal": 0.0}
        self.meshes = 0
        self.vertices = 0
        self.frames = []
        self.size = 0
        self.checked_materials = {}

    def fail(self, message):
        self.failures.append(message)

    def run(self):
        if not self.find_frames():
            return self
        if not os.path.isfile(self.path):
            self.fail(f"{self.path}: no such file")
            return self
        self.size = os.path.getsize(self.path)
        try:
            stage = Usd.Stage.Open(self.path)
        except Tf.ErrorException as error:
            self.fail(f"{self.path}: OpenUSD cannot open it: " + " ".join(str(error).split())[:400])
            return self
        if not stage:
            self.fail(f"{self.path}: OpenUSD cannot open it")
            return self
        self.check_layer(stage)
        self.check_meshes(stage)
        self.validate(stage)
        return self

    def find_frames(self):
        present = {}
        try:
            names = os.listdir(self.out)
        except OSError as error:
            self.fail(f"{self.out}: {error.strerror}")
            return False
        for name in names:
            m = FRAME_FILE.match(name)
            if m:
                present[int(m.group(1))] = os.path.join(self.out, name)
        if self.requested_frames:
            first, last = self.requested_frames
        elif present:
            first, last = min(present), max(present)
        else:
            self.fail(f"{self.out}: no frame_NNNN.ply")
            return False
        missing = [f for f in range(first, last + 1) if f not in present]
        if missing:
            self.fail(f"{self.out}: frames {first}..{last}: no PLY for frame(s) {', '.join(map(str, missing[:10]))}"
                      + (" ..." if len(missing) > 10 else ""))
            return False
        self.frames = list(range(first, last + 1))
        self.ply_paths = {f: present[f] for f in self.frames}
        return True

    def check_layer(self, stage):
        layer = stage.GetRootLayer()
        first, last = self.frames[0], self.frames[-1]
        if layer.defaultPrim != "Scene":
            self.fail(f"defaultPrim is {layer.defaultPrim!r}, not 'Scene'")
        scene = stage.GetPrimAtPath("/Scene")
        if not scene or scene.GetTypeName() != "Xform":
            self.fail("/Scene is not an Xform")
        elif Usd.ModelAPI(scene).GetKind() != "assembly":
            self.fail(f"/Scene's kind is {Usd.ModelAPI(scene).GetKind()!r}, not 'assembly'")
        if not stage.HasAuthoredMetadata("upAxis") or UsdGeom.GetStageUpAxis(stage) != UsdGeom.Tokens.y:
            self.fail(f"upAxis is {UsdGeom.GetStageUpAxis(stage)!r} (authored: "
                      f"{stage.HasAuthoredMetadata('upAxis')}), not an authored 'Y'")
        if not UsdGeom.StageHasAuthoredMetersPerUnit(stage) or UsdGeom.GetStageMetersPerUnit(stage) != 1.0:
            self.fail(f"metersPerUnit is {UsdGeom.GetStageMetersPerUnit(stage)} (authored: "
                      f"{UsdGeom.StageHasAuthoredMetersPerUnit(stage)}), not an authored 1")
        if not layer.HasStartTimeCode() or layer.startTimeCode != first:
            self.fail(f"startTimeCode is {layer.startTimeCode if layer.HasStartTimeCode() else 'not authored'}, "
                      f"not the first frame {first}")
        if not layer.HasEndTimeCode() or layer.endTimeCode != last:
            self.fail(f"endTimeCode is {layer.endTimeCode if layer.HasEndTimeCode() else 'not authored'}, "
                      f"not the last frame {last}")
        tcps = layer.timeCodesPerSecond if layer.HasTimeCodesPerSecond() else None
        fps = layer.framesPerSecond if layer.HasFramesPerSecond() else None
        if tcps is None or fps is None or tcps != fps or not tcps > 0:
            self.fail(f"timeCodesPerSecond {tcps} and framesPerSecond {fps}: not both authored, equal and positive")
        version = layer.customLayerData.get("qsgi:version")
        if not isinstance(version, str) or not version:
            self.fail(f"customLayerData has no string qsgi:version (it has {dict(layer.customLayerData)!r:.200})")
        seen = set()
        for prim in stage.TraverseAll():
            path = prim.GetPath()
            if not Sdf.Path.IsValidIdentifier(prim.GetName()):
                self.fail(f"{path}: its name is not a valid USD identifier")
            if path in seen:
                self.fail(f"{path}: defined twice")
            seen.add(path)
            if not path.HasPrefix(Sdf.Path("/Scene")):
                self.fail(f"{path}: outside /Scene")

    def check_material(self, mesh_path, prim):
        binding = UsdShade.MaterialBindingAPI(prim)
        material, _ = binding.ComputeBoundMaterial()
        if not material:
            targets = [str(t) for t in prim.GetRelationship("material:binding").GetTargets()] \
                if prim.HasRelationship("material:binding") else []
            self.fail(f"{mesh_path}: no material bound (material:binding targets: {targets or 'none'})")
            return
        key = material.GetPath()
        if key not in self.checked_materials:
            problems = self.material_problems(material)
            self.checked_materials[key] = problems
            for p in problems:
                self.fail(f"{key} (bound to {mesh_path}): {p}")

    @staticmethod
    def source_shader(port, output_name, shader_id):
        """(shader, None) when `port` is connected to exactly the output `output_name` of a Shader
        whose info:id is `shader_id`; else (None, why)."""
        sources, invalid = port.GetConnectedSources()
        if invalid:
            return None, f"connected to missing {', '.join(str(p) for p in invalid)}"
        if len(sources) != 1:
            return None, f"connected to {len(sources)} sources, not one"
        source = sources[0]
        shader = UsdShade.Shader(source.source.GetPrim())
        if not shader or source.source.GetPrim().GetTypeName() != "Shader":
            return None, f"connected to {source.source.GetPath()}, not a Shader"
        if shader.GetShaderId() != shader_id:
            return None, f"connected to {source.source.GetPath()} of info:id {shader.GetShaderId()!r}, not {shader_id!r}"
        if source.sourceType != UsdShade.AttributeType.Output or source.sourceName != output_name:
            return None, f"connected to {source.source.GetPath()}'s {source.sourceName}, not outputs:{output_name}"
        return shader, None

    def material_problems(self, material):
        problems = []
        surface, why = self.source_shader(material.GetSurfaceOutput(), "surface", "UsdPreviewSurface")
        if not surface:
            return [f"outputs:surface {why}"]
        diffuse = surface.GetInput("diffuseColor")
        if not diffuse or diffuse.HasConnectedSource() or diffuse.Get() != Gf.Vec3f(0, 0, 0):
            problems.append(f"{surface.GetPath()}: inputs:diffuseColor is {diffuse.Get() if diffuse else 'absent'}, "
                            "not (0, 0, 0)")
        ior = surface.GetInput("ior")
        if not ior or ior.HasConnectedSource() or ior.Get() != 1:
            problems.append(f"{surface.GetPath()}: inputs:ior is {ior.Get() if ior else 'absent'}, not 1")
        emissive = surface.GetInput("emissiveColor")
        if not emissive:
            problems.append(f"{surface.GetPath()}: no inputs:emissiveColor")
            return problems
        reader, why = self.source_shader(emissive, "result", "UsdPrimvarReader_float3")
        if not reader:
            problems.append(f"{surface.GetPath()}: inputs:emissiveColor {why}")
            return problems
        varname = reader.GetInput("varname")
        if not varname or varname.GetAttr().GetTypeName() != Sdf.ValueTypeNames.String or varname.Get() != "radiance":
            problems.append(f"{reader.GetPath()}: inputs:varname is "
                            f"{(str(varname.GetAttr().GetTypeName()) + ' ' + repr(varname.Get())) if varname else 'absent'}"
                            ", not the string 'radiance'")
        return problems

    def check_meshes(self, stage):
        plys = {}
        for frame in self.frames:
            try:
                plys[frame] = read_ply(self.ply_paths[frame])
            except (OSError, PlyError, KeyError, ValueError) as error:
                self.fail(f"{self.ply_paths[frame]}: {error}")
                return
        first_vertices, first_faces = plys[self.frames[0]]
        count = len(first_vertices)
        for frame in self.frames[1:]:
            if len(plys[frame][0]) != count or not np.array_equal(plys[frame][1], first_faces):
                self.fail(f"{self.ply_paths[frame]}: other vertices or faces than frame {self.frames[0]}'s")
                return
        self.vertices = count
        cover = np.zeros(count, np.int64)
        triangles = []
        time_codes = [float(f) for f in self.frames]
        extents = {}
        for frame, (vertices, _) in plys.items():
            xyz = columns(vertices, ("x", "y", "z")).astype(np.float64)
            extents[frame] = float(np.linalg.norm(xyz.max(0) - xyz.min(0))) if len(xyz) else 0.0
        node_meshes = {}  # child of /Scene -> [(mesh prim, points time-sampled)]
        for prim in stage.Traverse():
            if not prim.IsA(UsdGeom.Mesh):
                continue
            self.meshes += 1
            path = prim.GetPath()
            mesh = UsdGeom.Mesh(prim)
            scheme = mesh.GetSubdivisionSchemeAttr()
            if not scheme.HasAuthoredValue() or scheme.Get() != UsdGeom.Tokens.none:
                self.fail(f"{path}: subdivisionScheme is {scheme.Get()!r} (authored: {scheme.HasAuthoredValue()}), "
                          "not an authored 'none'")
            first = prim.GetAttribute("qsgi:firstVertex").Get() if prim.HasAttribute("qsgi:firstVertex") else None
            n = prim.GetAttribute("qsgi:vertexCount").Get() if prim.HasAttribute("qsgi:vertexCount") else None
            if not isinstance(first, int) or not isinstance(n, int) or first < 0 or n < 0:
                self.fail(f"{path}: qsgi:firstVertex {first!r} and qsgi:vertexCount {n!r}: not both non-negative ints")
                continue
            if first + n > count:
                self.fail(f"{path}: vertices {first}..{first + n - 1} beyond the PLY's {count}")
                continue
            cover[first:first + n] += 1
            counts_attr, indices_attr = mesh.GetFaceVertexCountsAttr(), mesh.GetFaceVertexIndicesAttr()
            if counts_attr.GetNumTimeSamples() or indices_attr.GetNumTimeSamples():
                self.fail(f"{path}: its topology is time-sampled")
            counts = as_array(counts_attr.Get(), np.int64)
            indices = as_array(indices_attr.Get(), np.int64)
            if not (counts == 3).all():
                self.fail(f"{path}: {int((counts != 3).sum())} of {len(counts)} faces are not triangles")
            elif len(indices) != 3 * len(counts):
                self.fail(f"{path}: {len(indices)} faceVertexIndices for {len(counts)} triangles")
            elif len(indices) and (indices.min() < 0 or indices.max() >= n):
                self.fail(f"{path}: faceVertexIndices outside 0..{n - 1} (from {indices.min()} to {indices.max()})")
            else:
                faces = indices.reshape(-1, 3)
                if len(faces) and ((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])).any():
                    self.fail(f"{path}: faces naming a vertex twice (Blender's importer drops the mesh's primvars for them)")
                # Under a transform of negative determinant USD (as glTF) reverses the winding: the
                # PLY, in world space, holds such a mesh's triangles turned back.
                at_first = np.array(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode(self.frames[0])))
                if np.linalg.det(at_first[:3, :3]) < 0:
                    faces = faces[:, [0, 2, 1]]
                triangles.append(faces + first)
            self.check_material(path, prim)
            points_attr = mesh.GetPointsAttr()
            normals_attr = mesh.GetNormalsAttr()
            # Normals are optional (a rigid mesh the file gives none has none); where given, checked.
            if normals_attr.HasAuthoredValue() and mesh.GetNormalsInterpolation() != UsdGeom.Tokens.vertex:
                self.fail(f"{path}: normals of interpolation {mesh.GetNormalsInterpolation()!r}, not 'vertex'")
            node = path.GetPrefixes()[1].name if path.pathElementCount > 2 else None
            node_meshes.setdefault(node, []).append((prim, points_attr.GetNumTimeSamples() > 0,
                                                     normals_attr.GetNumTimeSamples() > 0))
            primvars = {}
            # A doubleSided mesh's back side has its own pair (backRadiance, backIrradiance): checked
            # like the front's where the mesh has them.
            backs = tuple(b for b in BACK_PRIMVARS if UsdGeom.PrimvarsAPI(prim).GetPrimvar(b).IsDefined())
            for name in PRIMVARS + backs:
                primvar = UsdGeom.PrimvarsAPI(prim).GetPrimvar(name)
                if not primvar or not primvar.IsDefined():
                    self.fail(f"{path}: no primvars:{name}")
                    continue
                problems = []
                if primvar.GetTypeName() != Sdf.ValueTypeNames.Color3fArray:
                    problems.append(f"of type {primvar.GetTypeName()}, not color3f[]")
                if primvar.GetInterpolation() != UsdGeom.Tokens.vertex:
                    problems.append(f"of interpolation {primvar.GetInterpolation()!r}, not 'vertex'")
                if primvar.IsIndexed():
                    problems.append("indexed")
                samples = primvar.GetAttr().GetTimeSamples()
                if list(samples) != time_codes:
                    lacking = sorted(set(time_codes) - set(samples))
                    extra = sorted(set(samples) - set(time_codes))
                    problems.append(f"time samples are not every frame {self.frames[0]}..{self.frames[-1]}"
                                    + (f": none at {', '.join('%g' % t for t in lacking[:10])}" if lacking else "")
                                    + (f"; samples outside at {', '.join('%g' % t for t in extra[:10])}" if extra else ""))
                if problems:
                    self.fail(f"{path}: primvars:{name} " + ", ".join(problems))
                else:
                    primvars[name] = primvar
            xformable = UsdGeom.Xformable(prim)
            extent_attr = mesh.GetExtentAttr()
            for frame in self.frames:
                vertices = plys[frame][0][first:first + n]
                t = Usd.TimeCode(frame)
                for name, primvar in primvars.items():
                    value = as_array(primvar.Get(t), np.float32)
                    if value.shape != (n, 3):
                        self.fail(f"{path}: primvars:{name} at frame {frame} holds {value.shape[0] if value.ndim else 0} "
                                  f"values for {n} vertices")
                        continue
                    prefix = "back_" if name.startswith("back") else ""
                    if name.lower().endswith("irradiance"):
                        expected = columns(vertices, tuple(prefix + "irradiance_" + c for c in "rgb")).astype(np.float32)
                        rule = f"the PLY's {prefix}irradiance"
                    else:
                        radiosity = columns(vertices, tuple(prefix + "radiosity_" + c for c in "rgb")).astype(np.float32)
                        expected = (radiosity * INV_PI).astype(np.float32)
                        rule = "float32(the PLY's radiosity x float32(1/pi))"
                    error = ulps(value, expected)
                    self.max[name] = max(self.max.get(name, 0.0), error)
                    if not error <= 1.0:
                        bad = np.abs(value.astype(np.float64) - expected) > np.spacing(np.abs(expected))
                        worst = int(np.argmax(np.max(np.abs(value.astype(np.float64) - expected)
                                                     / np.spacing(np.abs(expected)), axis=1)))
                        self.fail(f"{path}: primvars:{name} at frame {frame}: {int(bad.any(axis=1).sum())} of {n} "
                                  f"values differ from {rule} by more than 1 ulp (worst {error:.3g} ulp: point {worst}, "
                                  f"PLY vertex {first + worst}: {value[worst].tolist()} for {expected[worst].tolist()})")
                points = as_array(points_attr.Get(t))
                if points.shape != (n, 3):
                    self.fail(f"{path}: {points.shape[0] if points.ndim else 0} points at frame {frame}, "
                              f"qsgi:vertexCount says {n}")
                    continue
                if extent_attr.HasAuthoredValue() and n:
                    extent = as_array(extent_attr.Get(t))
                    slack = 1e-6 * max(1.0, float(np.abs(points).max()))
                    if extent.shape != (2, 3) or (points < extent[0] - slack).any() or (points > extent[1] + slack).any():
                        self.fail(f"{path}: extent at frame {frame} {extent.tolist()} does not hold its points "
                                  f"(from {points.min(0).tolist()} to {points.max(0).tolist()})")
                matrix = np.array(xformable.ComputeLocalToWorldTransform(t))
                world = points @ matrix[:3, :3] + matrix[3, :3]
                ply_xyz = columns(vertices, ("x", "y", "z")).astype(np.float64)
                # The PLY's positions are floats: far from the origin their own rounding (an ulp of
                # the coordinate) exceeds a share of the extent, and counts beside it.
                slack = 2 * np.spacing(np.abs(ply_xyz).astype(np.float32)).astype(np.float64)
                excess = np.abs(world - ply_xyz) - slack
                error = float(np.max(excess)) / extents[frame] if n and extents[frame] > 0 else 0.0
                self.max["position"] = max(self.max["position"], error)
                if not error <= POSITION_TOLERANCE:
                    worst = int(np.argmax(np.max(np.abs(world - ply_xyz), axis=1)))
                    self.fail(f"{path}: points placed at frame {frame} are not the PLY's positions: "
                              f"{error:.3g} of the extent {extents[frame]:.6g} (point {worst}, PLY vertex {first + worst}: "
                              f"{world[worst].tolist()} for {ply_xyz[worst].tolist()})")
                normals = as_array(normals_attr.Get(t))
                if not normals_attr.HasAuthoredValue():
                    continue
                if normals.shape != (n, 3):
                    self.fail(f"{path}: {normals.shape[0] if normals.ndim else 0} normals at frame {frame} for {n} points")
                    continue
                if abs(np.linalg.det(matrix[:3, :3])) < 1e-300:
                    continue  # a hidden node (scale 0): qsgi keeps its last normals, nothing to compare
                placed = normals @ np.linalg.inv(matrix[:3, :3]).T
                ply_normals = columns(vertices, ("nx", "ny", "nz")).astype(np.float64)
                error = float(np.max(np.abs(unit(placed) - unit(ply_normals)))) if n else 0.0
                self.max["normal"] = max(self.max["normal"], error)
                if not error <= NORMAL_TOLERANCE:
                    worst = int(np.argmax(np.max(np.abs(unit(placed) - unit(ply_normals)), axis=1)))
                    self.fail(f"{path}: normals placed at frame {frame} are not the PLY's: {error:.3g} "
                              f"(point {worst}: {unit(placed)[worst].tolist()} for {unit(ply_normals)[worst].tolist()})")
        if self.meshes == 0:
            self.fail("no Mesh")
        uncovered, doubled = int((cover == 0).sum()), int((cover > 1).sum())
        if uncovered or doubled:
            self.fail(f"PLY vertices not covered by exactly one mesh: {uncovered} of {count} by none, {doubled} by more "
                      f"than one (first: {int(np.argmax(cover != 1))})")
        mine = np.concatenate(triangles) if triangles else np.zeros((0, 3), np.int64)
        # The PLY's faces that name a vertex twice have no area: the USD leaves them out.
        kept = first_faces[(first_faces[:, 0] != first_faces[:, 1]) & (first_faces[:, 1] != first_faces[:, 2])
                           & (first_faces[:, 0] != first_faces[:, 2])] if len(first_faces) else first_faces
        if not np.array_equal(sort_rows(canonical(mine)), sort_rows(canonical(kept))):
            self.fail(f"the meshes' {len(mine)} triangles (moved by qsgi:firstVertex) are not the PLY's {len(first_faces)} faces")
        self.check_nodes(stage, node_meshes)

    def check_nodes(self, stage, node_meshes):
        names = sorted(n for n in node_meshes if n is not None)
        if self.nodes is not None and names != sorted(self.nodes):
            self.fail(f"the nodes that place meshes are {names}, not {sorted(self.nodes)}")
        if self.nodes is None and not self.rigid and not self.deforming:
            return
        for name in names:
            node = stage.GetPrimAtPath(Sdf.Path("/Scene").AppendChild(name))
            # The node's transform or its meshes' own (wherever between them the motion is written).
            xform_sampled = any(op.GetAttr().GetNumTimeSamples() > 0
                                for prim in Usd.PrimRange(node) if prim.IsA(UsdGeom.Xformable)
                                for op in UsdGeom.Xformable(prim).GetOrderedXformOps())
            points_sampled = any(p for _, p, _ in node_meshes[name])
            normals_sampled = any(p for _, _, p in node_meshes[name])
            kind = "rigid" if name in self.rigid else "deforming" if name in self.deforming else "static"
            expected = {"rigid": (True, False), "deforming": (False, True), "static": (False, False)}[kind]
            if (xform_sampled, points_sampled) != expected:
                self.fail(f"/Scene/{name} ({kind}): transform time-sampled {xform_sampled}, its meshes' points "
                          f"time-sampled {points_sampled}; expected {expected[0]} and {expected[1]}")
            if normals_sampled and not points_sampled:
                self.fail(f"/Scene/{name}: normals time-sampled where the points are not")

    def validate(self, stage):
        registry = UsdValidation.ValidationRegistry()
        validators = registry.GetOrLoadAllValidators()
        context = UsdValidation.ValidationContext(validators)
        self.validators = len(validators)
        for error in context.Validate(stage):
            if error.HasNoError():
                continue
            sites = ", ".join(str(s.GetPrim().GetPath()) if s.IsPrim() else str(s.GetProperty().GetPath())
                              if s.IsProperty() else "layer" for s in error.GetSites()[:3])
            line = f"UsdValidation {error.GetIdentifier()}: {error.GetMessage()}" + (f" [{sites}]" if sites else "")
            if error.GetType() == UsdValidation.ValidationErrorType.Error:
                self.fail(line)
            elif error.GetType() == UsdValidation.ValidationErrorType.Warn:
                self.warnings.append(line)

    def summary(self):
        vertex_frames = self.vertices * len(self.frames)
        per = f"{self.size / vertex_frames:.2f}" if vertex_frames else "-"
        span = f" ({self.frames[0]}..{self.frames[-1]})" if self.frames else ""
        return (f"check_usd: {self.path}: {self.meshes} meshes, {self.vertices} vertices, {len(self.frames)} frames{span}; "
                f"max error radiance {self.max['radiance']:.3g} ulp, irradiance {self.max['irradiance']:.3g} ulp, "
                + "".join(f"{name} {self.max[name]:.3g} ulp, " for name in BACK_PRIMVARS if name in self.max) +
                f"positions {self.max['position']:.3g} of the extent, normals {self.max['normal']:.3g}; "
                f"{self.size} bytes, {per} bytes per vertex-frame; "
                f"UsdValidation: {getattr(self, 'validators', 0)} validators, {len(self.warnings)} warnings; "
                f"{len(self.failures)} failures")


def unit(v):
    length = np.linalg.norm(v, axis=1, keepdims=True)
    return np.divide(v, length, out=np.zeros_like(v), where=length > 0)


def canonical(triangles):
    """Each triangle rotated to start at its smallest index: the same triangle, the same winding."""
    if not len(triangles):
        return triangles
    start = np.argmin(triangles, axis=1)
    rows = np.arange(len(triangles))[:, None]
    return triangles[rows, (start[:, None] + np.arange(3)) % 3]


def sort_rows(a):
    return a[np.lexsort(a.T[::-1])] if len(a) else a


def frame_range(text):
    m = re.fullmatch(r"(\d+):(\d+)", text)
    if not m or int(m.group(1)) > int(m.group(2)):
        raise argparse.ArgumentTypeError(f"{text!r} is not A:B with A <= B")
    return int(m.group(1)), int(m.group(2))


def names(text):
    return [n for n in text.split(",") if n]


def check(out, frames=None, nodes=None, rigid=(), deforming=()):
    """The Checker after its run: .failures, .warnings, .summary()."""
    return Checker(out, frames, nodes, rigid, deforming).run()


def main(argv=None):
    parser = argparse.ArgumentParser(description="Checks OUT/asset.usda (qsgi --usd-out) with OpenUSD against "
                                     "OUT/frame_NNNN.ply; the module's docstring lists the checks.")
    parser.add_argument("out", help="the output folder")
    parser.add_argument("--frames", type=frame_range, help="A:B, the frames the asset must cover "
                        "(default: those of the PLYs present)")
    parser.add_argument("--nodes", type=names, help="the children of /Scene that place meshes, comma-separated")
    parser.add_argument("--rigid", type=names, default=[], help="nodes moved by their transform")
    parser.add_argument("--deforming", type=names, default=[], help="nodes whose meshes' points move")
    args = parser.parse_args(argv)
    checker = check(args.out, args.frames, args.nodes, args.rigid, args.deforming)
    for line in checker.warnings:
        print("warning: " + line)
    for line in checker.failures:
        print(line)
    print(checker.summary())
    return 1 if checker.failures else 0


if __name__ == "__main__":
    sys.exit(main())
