#!/usr/bin/python3
"""`qsgi render --usd-out` read back by OpenUSD itself (issue 46, item 4): every frame's primvars
against that frame's PLY, names, time codes, the preview material's wiring and UsdValidation, by
scripts/usd-check/check_usd.py in the venv scripts/setup.sh --test makes (usd-core, pinned by
scripts/usd-check/requirements.txt).

    /usr/bin/python3 tests/python/test_usd_out.py --qsgi build/cli/qsgi   renders data/walker
        (skinned, its glTF animation; also --subdivide) and data/cornell (a rigid mover by its
        transform file) with --usd-out, and checks each folder (a few seconds)
    /usr/bin/python3 tests/python/test_usd_out.py --self-test             the checker on a
        hand-written asset (two quads, three frames: one moved by its transform, one by its
        points) with its PLYs, which it must pass, and on broken copies of it, each of which it
        must fail naming the fault (a second or two)

Runs under the venv's python (it re-executes itself there); without the venv it fails, saying to
run scripts/setup.sh --test."""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
USD_CHECK = os.path.join(REPOSITORY, "scripts", "usd-check")
VENV_PYTHON = os.path.join(USD_CHECK, "venv", "bin", "python")
CHECKER = os.path.join(USD_CHECK, "check_usd.py")


def pinned_version():
    with open(os.path.join(USD_CHECK, "requirements.txt")) as f:
        for line in f:
            if line.startswith("usd-core=="):
                return line.split("==", 1)[1].split()[0]
    raise RuntimeError("scripts/usd-check/requirements.txt pins no usd-core")


def enter_venv():
    """Re-executes this script under the venv's python, or exits 1 saying how to make the venv."""
    if os.path.realpath(sys.prefix) == os.path.realpath(os.path.join(USD_CHECK, "venv")):
        return
    if not os.access(VENV_PYTHON, os.X_OK):
        sys.exit(f"test_usd_out.py: FAILED: {VENV_PYTHON} is missing: run scripts/setup.sh --test, which makes "
                 f"that venv with usd-core=={pinned_version()} (scripts/usd-check/requirements.txt)")
    os.execv(VENV_PYTHON, [VENV_PYTHON, os.path.abspath(__file__)] + sys.argv[1:])


def require_pinned_usd():
    import importlib.metadata
    try:
        installed = importlib.metadata.version("usd-core")
    except importlib.metadata.PackageNotFoundError:
        installed = None
    if installed != pinned_version():
        sys.exit(f"test_usd_out.py: FAILED: the venv has usd-core {installed or 'not at all'}, "
                 f"scripts/usd-check/requirements.txt pins {pinned_version()}: run scripts/setup.sh --test")


ARGS = None  # the command line's own options (--qsgi, --self-test)


# ----- the hand-written asset of the self-test ----------------------------------------------------

FRAMES = (0, 1, 2)
FPS = 24

USDA = """#usda 1.0
(
    customLayerData = {
        string "qsgi:version" = "self-test"
    }
    defaultPrim = "Scene"
    endTimeCode = @LAST@
    framesPerSecond = @FPS@
    metersPerUnit = 1
    startTimeCode = @FIRST@
    timeCodesPerSecond = @FPS@
    upAxis = "Y"
)

def Xform "Scene" (
    kind = "assembly"
)
{
    def Scope "Materials"
    {
        def Material "Baked"
        {
            token outputs:surface.connect = </Scene/Materials/Baked/Surface.outputs:surface>

            def Shader "Surface"
            {
                uniform token info:id = "UsdPreviewSurface"
                color3f inputs:diffuseColor = (0, 0, 0)
                color3f inputs:emissiveColor.connect = </Scene/Materials/Baked/Radiance.outputs:result>
                float inputs:ior = 1
                token outputs:surface
            }

            def Shader "Radiance"
            {
                uniform token info:id = "UsdPrimvarReader_float3"
                string inputs:varname = "radiance"
                float3 outputs:result
            }
        }
    }

    def Xform "Mover"
    {
        matrix4d xformOp:transform.timeSamples = {
@MOVER_TRANSFORM@
        }
        uniform token[] xformOpOrder = ["xformOp:transform"]

        def Mesh "Quad" (
            prepend apiSchemas = ["MaterialBindingAPI"]
        )
        {
            float3[] extent = @QUAD_EXTENT@
            int[] faceVertexCounts = [3, 3]
            int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]
            rel material:binding = </Scene/Materials/Baked>
            normal3f[] normals = @QUAD_NORMALS@ (
                interpolation = "vertex"
            )
            point3f[] points = @QUAD_POINTS@
            color3f[] primvars:irradiance (
                interpolation = "vertex"
            )
            color3f[] primvars:irradiance.timeSamples = {
@QUAD_IRRADIANCE@
            }
            color3f[] primvars:radiance (
                interpolation = "vertex"
            )
            color3f[] primvars:radiance.timeSamples = {
@QUAD_RADIANCE@
            }
            custom int qsgi:firstVertex = 0
            custom int qsgi:vertexCount = 4
            uniform token subdivisionScheme = "none"
        }
    }

    def Xform "Figure"
    {
        matrix4d xformOp:transform = ( (1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (0, 0, 0, 1) )
        uniform token[] xformOpOrder = ["xformOp:transform"]

        def Mesh "Body" (
            prepend apiSchemas = ["MaterialBindingAPI"]
        )
        {
            float3[] extent.timeSamples = {
@BODY_EXTENT@
            }
            int[] faceVertexCounts = [3, 3]
            int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]
            rel material:binding = </Scene/Materials/Baked>
            normal3f[] normals (
                interpolation = "vertex"
            )
            normal3f[] normals.timeSamples = {
@BODY_NORMALS@
            }
            point3f[] points.timeSamples = {
@BODY_POINTS@
            }
            color3f[] primvars:irradiance (
                interpolation = "vertex"
            )
            color3f[] primvars:irradiance.timeSamples = {
@BODY_IRRADIANCE@
            }
            color3f[] primvars:radiance (
                interpolation = "vertex"
            )
            color3f[] primvars:radiance.timeSamples = {
@BODY_RADIANCE@
            }
            custom int qsgi:firstVertex = 4
            custom int qsgi:vertexCount = 4
            uniform token subdivisionScheme = "none"
        }
    }
}
"""

PLY_HEADER = """ply
format binary_little_endian 1.0
comment qsgi self-test vertex radiosity (W/m^2)
element vertex {vertices}
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float radiosity_r
property float radiosity_g
property float radiosity_b
property float irradiance_r
property float irradiance_g
property float irradiance_b
property uchar red
property uchar green
property uchar blue
element face {faces}
property list uchar int vertex_indices
end_header
"""


def fixture_data():
    """The fixture's values: what the asset says and what the PLYs say, equal as qsgi would write them."""
    import numpy as np
    rng = np.random.default_rng(46)
    d = {"quad_points": np.array([[-1, 0, -1], [1, 0, -1], [1, 0, 1], [-1, 0, 1]], np.float32) * np.float32(0.5),
         "quad_normals": np.array([[0, 1, 0]] * 4, np.float32), "matrix": {}, "body_points": {}, "body_normals": {},
         "radiosity": {}, "irradiance": {}}
    for f in FRAMES:
        angle = 0.3 * f
        c, s = np.cos(angle), np.sin(angle)
        rotation = np.identity(4)
        rotation[0, 0], rotation[0, 1], rotation[1, 0], rotation[1, 1] = c, s, -s, c  # about Z, row vectors (p' = p M)
        m = np.diag([1.0, 1.0, 2.0, 1.0]) @ rotation  # scaled, then turned: normals need the inverse transpose
        m[3, :3] = (0.25 * f, 0.5, -0.125 * f)
        d["matrix"][f] = m
        bend = np.float32(0.1 * f)
        d["body_points"][f] = np.array([[2, 0, 0], [3, 0, 0], [3, 1, bend], [2, 1, bend]], np.float32)
        n = np.array([0, -bend, 1], np.float64)
        d["body_normals"][f] = np.array([[0, 0, 1], [0, 0, 1], n / np.linalg.norm(n), n / np.linalg.norm(n)], np.float32)
        # Lighting spanning magnitudes, a zero and a value past 1 (radiance is not clamped).
        radiosity = rng.uniform(0, 3, (8, 3)).astype(np.float32) * np.float32(10.0) ** rng.integers(-3, 2, (8, 1))
        radiosity[0, 0] = 0
        d["radiosity"][f] = radiosity.astype(np.float32)
        d["irradiance"][f] = (radiosity * np.float32(1.7) + np.float32(0.01)).astype(np.float32)
    d["usd_radiance"] = {f: (d["radiosity"][f] * np.float32(1 / np.pi)).astype(np.float32) for f in FRAMES}
    d["usd_irradiance"] = {f: d["irradiance"][f].copy() for f in FRAMES}
    d["ply_positions"] = {f: np.concatenate([
        (d["quad_points"].astype(np.float64) @ d["matrix"][f][:3, :3] + d["matrix"][f][3, :3]).astype(np.float32),
        d["body_points"][f]]) for f in FRAMES}
    d["ply_normals"] = {}
    for f in FRAMES:
        placed = d["quad_normals"].astype(np.float64) @ np.linalg.inv(d["matrix"][f][:3, :3]).T
        placed /= np.linalg.norm(placed, axis=1, keepdims=True)
        d["ply_normals"][f] = np.concatenate([placed.astype(np.float32), d["body_normals"][f]])
    d["faces"] = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]], np.int32)
    return d


def f32(x):
    """Shortest text that reads back as the float32 x."""
    import numpy as np
    return np.format_float_positional(np.float32(x), unique=True, trim="-") if abs(x) >= 1e-4 or x == 0 \
        else np.format_float_scientific(np.float32(x), unique=True, trim="-")


def vec3s(a):
    return "[" + ", ".join("(" + ", ".join(f32(v) for v in row) + ")" for row in a) + "]"


def samples(per_frame, indent=16):
    return ",\n".join(" " * indent + f"{f}: {vec3s(v)}" for f, v in per_frame.items())


def bounds(points):
    return [points.min(0), points.max(0)]


def matrix_text(m):
    return "( " + ", ".join("(" + ", ".join(repr(float(v)) for v in row) + ")" for row in m) + " )"


def write_fixture(folder, text_edit=None, data_edit=None):
    import numpy as np
    d = fixture_data()
    if data_edit:
        data_edit(d)
    frames = list(d["radiosity"])
    text = (USDA.replace("@FIRST@", str(frames[0])).replace("@LAST@", str(frames[-1])).replace("@FPS@", str(FPS))
            .replace("@MOVER_TRANSFORM@", ",\n".join(f"            {f}: {matrix_text(m)}" for f, m in d["matrix"].items()))
            .replace("@QUAD_EXTENT@", vec3s(bounds(d["quad_points"])))
            .replace("@BODY_EXTENT@", samples(d["body_extent"] if "body_extent" in d
                                              else {f: bounds(p) for f, p in d["body_points"].items()}))
            .replace("@QUAD_POINTS@", vec3s(d["quad_points"])).replace("@QUAD_NORMALS@", vec3s(d["quad_normals"]))
            .replace("@QUAD_RADIANCE@", samples({f: v[:4] for f, v in d["usd_radiance"].items()}))
            .replace("@QUAD_IRRADIANCE@", samples({f: v[:4] for f, v in d["usd_irradiance"].items()}))
            .replace("@BODY_POINTS@", samples(d["body_points"])).replace("@BODY_NORMALS@", samples(d["body_normals"]))
            .replace("@BODY_RADIANCE@", samples({f: v[4:] for f, v in d["usd_radiance"].items()}))
            .replace("@BODY_IRRADIANCE@", samples({f: v[4:] for f, v in d["usd_irradiance"].items()})))
    if text_edit:
        edited = text_edit(text)
        assert edited != text, "the broken case changed nothing in the fixture"
        text = edited
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "asset.usda"), "w") as f:
        f.write(text)
    vertex = np.dtype([("p", "<f4", 3), ("n", "<f4", 3), ("b", "<f4", 3), ("e", "<f4", 3), ("c", "u1", 3)])
    face = np.dtype([("k", "u1"), ("i", "<i4", 3)])
    for frame in frames:
        v = np.zeros(8, vertex)
        v["p"], v["n"] = d["ply_positions"][frame], d["ply_normals"][frame]
        v["b"], v["e"], v["c"] = d["radiosity"][frame], d["irradiance"][frame], 128
        faces = np.zeros(len(d["faces"]), face)
        faces["k"], faces["i"] = 3, d["faces"]
        with open(os.path.join(folder, f"frame_{frame:04d}.ply"), "wb") as f:
            f.write(PLY_HEADER.format(vertices=len(v), faces=len(faces)).encode("ascii"))
            f.write(v.tobytes())
            f.write(faces.tobytes())
    return folder


def replace(old, new, count=1):
    """A text edit replacing `count` occurrences of `old` (all: count 0), which must be there."""
    def edit(text):
        assert old in text, f"the fixture has no {old!r}"
        return text.replace(old, new) if count == 0 else text.replace(old, new, count)
    return edit


def drop_sample(name, frame):
    """Removes frame's sample of the first primvars:NAME.timeSamples."""
    def edit(text):
        start = text.index(f"color3f[] primvars:{name}.timeSamples = {{")
        line_start = text.index(f"\n                {frame}: ", start) + 1
        line_end = text.index("\n", line_start)
        sample = text[line_start:line_end]
        if sample.endswith(","):
            return text[:line_start] + text[line_end + 1:]
        return text[:line_start - 2] + text[line_end:]  # the last sample: drop the comma before it
    return edit


def bump(key, frame, vertex, component, ulps):
    """Moves one value of d[key][frame] by `ulps` float32 steps."""
    def edit(d):
        import numpy as np
        value = d[key][frame][vertex, component]
        for _ in range(abs(ulps)):
            value = np.nextafter(value, np.float32(np.inf if ulps > 0 else -np.inf), dtype=np.float32)
        d[key][frame][vertex, component] = value
    return edit


def set_value(key, frame, value):
    def edit(d):
        d[key][frame] = value(d) if callable(value) else value
    return edit


def remove_frame(frame):
    def edit(d):
        for key in ("radiosity", "irradiance", "usd_radiance", "usd_irradiance", "matrix", "body_points",
                    "body_normals", "ply_positions", "ply_normals"):
            del d[key][frame]
    return edit


# (what is broken, text edit, data edit, checker arguments, what a failure line must say)
BROKEN = [
    ("a missing radiance time sample", drop_sample("radiance", 1), None, {}, "primvars:radiance time samples"),
    ("a missing irradiance time sample (the last)", drop_sample("irradiance", 2), None, {}, "none at 2"),
    ("an irradiance value 2 ulp off", None, bump("usd_irradiance", 2, 5, 1, 2), {}, "primvars:irradiance at frame 2"),
    ("a radiance value 2 ulp off", None, bump("usd_radiance", 1, 3, 0, -2), {}, "primvars:radiance at frame 1"),
    ("radiance as B, not B/pi", None, set_value("usd_radiance", 0, lambda d: d["radiosity"][0].copy()), {},
     "primvars:radiance at frame 0"),
    ("radiance from the wrong frame", None, set_value("usd_radiance", 2, lambda d: d["usd_radiance"][1].copy()), {},
     "primvars:radiance at frame 2"),
    ("a binding to no material", replace("rel material:binding = </Scene/Materials/Baked>",
                                         "rel material:binding = </Scene/Materials/Missing>"), None, {},
     "no material bound"),
    ("no binding", replace("            rel material:binding = </Scene/Materials/Baked>\n", ""), None, {},
     "/Scene/Mover/Quad: no material bound"),
    ("MaterialBindingAPI not applied (only UsdValidation sees it)",
     replace('def Mesh "Quad" (\n            prepend apiSchemas = ["MaterialBindingAPI"]\n        )', 'def Mesh "Quad"'), None, {},
     "UsdValidation usdShadeValidators:MaterialBindingApiAppliedValidator"),
    ("emissiveColor unconnected", replace("color3f inputs:emissiveColor.connect = </Scene/Materials/Baked/Radiance.outputs:result>",
                                          "color3f inputs:emissiveColor = (1, 1, 1)"), None, {},
     "inputs:emissiveColor connected to 0 sources"),
    ("emissiveColor from a texture reader", replace('info:id = "UsdPrimvarReader_float3"', 'info:id = "UsdUVTexture"'),
     None, {}, "not 'UsdPrimvarReader_float3'"),
    ("varname a token", replace('string inputs:varname = "radiance"', 'token inputs:varname = "radiance"'), None, {},
     "inputs:varname is token"),
    ("varname irradiance", replace('string inputs:varname = "radiance"', 'string inputs:varname = "irradiance"'),
     None, {}, "inputs:varname is string 'irradiance'"),
    ("diffuse not black", replace("inputs:diffuseColor = (0, 0, 0)", "inputs:diffuseColor = (0.18, 0.18, 0.18)"),
     None, {}, "inputs:diffuseColor"),
    ("ior not authored (1.5 by default)", replace("                float inputs:ior = 1\n", ""), None, {}, "inputs:ior is absent"),
    ("surface not a preview surface", replace("token outputs:surface.connect = </Scene/Materials/Baked/Surface.outputs:surface>",
                                              "token outputs:surface"), None, {}, "outputs:surface connected to 0"),
    ("subdivisionScheme left to its default", replace('            uniform token subdivisionScheme = "none"\n', ""),
     None, {}, "subdivisionScheme is 'catmullClark'"),
    ("a quad face", replace("int[] faceVertexCounts = [3, 3]\n            int[] faceVertexIndices = [0, 1, 2, 0, 2, 3]",
                            "int[] faceVertexCounts = [4]\n            int[] faceVertexIndices = [0, 1, 2, 3]"),
     None, {}, "1 of 1 faces are not triangles"),
    ("an index out of range", replace("[0, 1, 2, 0, 2, 3]", "[0, 1, 2, 0, 2, 4]"), None, {}, "faceVertexIndices outside"),
    ("triangles turned round", replace("[0, 1, 2, 0, 2, 3]", "[0, 2, 1, 0, 2, 3]"), None, {}, "are not the PLY's 4 faces"),
    ("float3[] radiance", replace("color3f[] primvars:radiance", "float3[] primvars:radiance", 0), None, {},
     "primvars:radiance of type float3[]"),
    ("faceVarying irradiance", replace('color3f[] primvars:irradiance (\n                interpolation = "vertex"',
                                       'color3f[] primvars:irradiance (\n                interpolation = "faceVarying"'),
     None, {}, "of interpolation 'faceVarying'"),
    ("endTimeCode short of the last frame", replace("endTimeCode = 2", "endTimeCode = 1"), None, {},
     "endTimeCode is 1.0, not the last frame 2"),
    ("startTimeCode missing", replace("    startTimeCode = 0\n", ""), None, {}, "startTimeCode is not authored"),
    ("no metersPerUnit", replace("    metersPerUnit = 1\n", ""), None, {}, "metersPerUnit is 0.01"),
    ("Z up", replace('upAxis = "Y"', 'upAxis = "Z"'), None, {}, "upAxis is 'Z'"),
    ("framesPerSecond not timeCodesPerSecond", replace(f"framesPerSecond = {FPS}", "framesPerSecond = 30"), None, {},
     "framesPerSecond 30.0"),
    ("another defaultPrim", replace('defaultPrim = "Scene"', 'defaultPrim = "Figure"'), None, {},
     "defaultPrim is 'Figure'"),
    ("no qsgi:version", replace('string "qsgi:version" = "self-test"', 'string "other" = "x"'), None, {},
     "no string qsgi:version"),
    ("overlapping vertex ranges", replace("custom int qsgi:firstVertex = 4", "custom int qsgi:firstVertex = 2"),
     None, {}, "by more than one"),
    ("vertexCount not the points", replace("custom int qsgi:vertexCount = 4", "custom int qsgi:vertexCount = 3"),
     None, {}, "PLY vertices not covered"),
    ("a transform wrong at frame 1", None, lambda d: d["matrix"][1].__setitem__((3, 1), 0.51), {},
     "/Scene/Mover/Quad: points placed at frame 1"),
    ("deformed points wrong at frame 2", None, lambda d: d["body_points"][2].__setitem__((2, 2), 0.0), {},
     "/Scene/Figure/Body: points placed at frame 2"),
    ("normals not turned with the mover", None, lambda d: d["ply_normals"][2].__setitem__(slice(0, 4), (0, 1, 0)), {},
     "/Scene/Mover/Quad: normals placed at frame 2"),
    ("an extent left at frame 0's while the points move", None,
     lambda d: d.__setitem__("body_extent", {f: bounds(d["body_points"][0]) for f in d["body_points"]}), {},
     "/Scene/Figure/Body: extent at frame 1"),
    ("a duplicate prim (OpenUSD refuses the file)", replace('    def Xform "Figure"', '    def Xform "Mover"'), None, {},
     "OpenUSD cannot open it"),
    ("a frame's PLY missing", None, remove_frame(1), {}, "no PLY for frame(s) 1"),
    ("a range beyond the frames", None, None, {"frames": (0, 3)}, "no PLY for frame(s) 3"),
    ("a range inside the frames (the asset's time codes are wider)", None, None, {"frames": (1, 2)},
     "startTimeCode is 0.0, not the first frame 1"),
    ("other node names", None, None, {"nodes": ["Mover", "Walker"]}, "not ['Mover', 'Walker']"),
    ("a rigid mover said to deform", None, None, {"nodes": ["Mover", "Figure"], "deforming": ["Mover"]},
     "/Scene/Mover (deforming)"),
    ("a deforming mesh said static", None, None, {"nodes": ["Mover", "Figure"], "rigid": ["Mover"]},
     "/Scene/Figure (static)"),
]


class CheckerSelfTest(unittest.TestCase):
    """The checker passes the hand-written asset and fails each broken copy, naming the fault."""

    @classmethod
    def setUpClass(cls):
        sys.path.insert(0, USD_CHECK)
        import check_usd
        cls.check_usd = check_usd
        cls.scratch = tempfile.mkdtemp(prefix="qsgi-usd-self-test-")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.scratch, ignore_errors=True)

    def test_the_hand_written_asset_passes(self):
        folder = write_fixture(os.path.join(self.scratch, "good"))
        checker = self.check_usd.check(folder, nodes=["Mover", "Figure"], rigid=["Mover"], deforming=["Figure"])
        self.assertEqual(checker.failures, [], checker.summary())
        self.assertIn("2 meshes, 8 vertices, 3 frames (0..2)", checker.summary())
        self.assertEqual(checker.max["irradiance"], 0.0)
        self.assertLessEqual(checker.max["radiance"], 1.0)
        # Through the command line: exit 0, the summary last.
        run = subprocess.run([sys.executable, CHECKER, folder, "--frames", "0:2"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 0, run.stdout + run.stderr)
        self.assertTrue(run.stdout.splitlines()[-1].startswith("check_usd: "), run.stdout)
        print("\n  " + run.stdout.strip(), file=sys.stderr)

    def test_every_broken_copy_fails_naming_its_fault(self):
        for number, (what, text_edit, data_edit, arguments, expected) in enumerate(BROKEN):
            with self.subTest(what):
                folder = write_fixture(os.path.join(self.scratch, f"broken-{number}"), text_edit, data_edit)
                checker = self.check_usd.check(folder, **arguments)
                self.assertTrue(any(expected in line for line in checker.failures),
                                f"{what}: no failure line says {expected!r}; the checker said:\n  "
                                + "\n  ".join(checker.failures + [checker.summary()]))
                print(f"  {what}: {next(line for line in checker.failures if expected in line)}", file=sys.stderr)

    def test_a_broken_copy_exits_1_from_the_command_line(self):
        folder = write_fixture(os.path.join(self.scratch, "cli-broken"), drop_sample("radiance", 1))
        run = subprocess.run([sys.executable, CHECKER, folder], capture_output=True, text=True)
        self.assertEqual(run.returncode, 1, run.stdout + run.stderr)
        self.assertIn("/Scene/Mover/Quad: primvars:radiance time samples are not every frame 0..2: none at 1", run.stdout)
        run = subprocess.run([sys.executable, CHECKER, folder, "--frames", "2"], capture_output=True, text=True)
        self.assertEqual(run.returncode, 2, run.stdout + run.stderr)


# ----- qsgi's own assets ---------------------------------------------------------------------------

# Few photons and the cheap second pass of the C++ tests (kCheapSecondPass, tests/test_support.h).
CHEAP = ["--photons", "20000", "--gather", "16", "--direct-samples", "4", "--no-exr", "--quiet"]
WALKER = os.path.join(REPOSITORY, "data", "walker", "walker.gltf")
CORNELL = os.path.join(REPOSITORY, "data", "cornell", "cornell.gltf")
CORNELL_ANIMATION = os.path.join(REPOSITORY, "data", "cornell", "animation.json")
MATERIALS_ROOM = os.path.join(REPOSITORY, "tests", "data", "materials_room", "materials_room.gltf")


def mesh_nodes(gltf):
    """{name of a glTF node that places a mesh: its mesh's name} (every name in data/ is already a USD
    identifier, each mesh has one primitive)."""
    with open(gltf) as f:
        document = json.load(f)
    return {n["name"]: document["meshes"][n["mesh"]]["name"] for n in document["nodes"] if "mesh" in n}


class QsgiAssetsReadBack(unittest.TestCase):
    """qsgi's --usd-out on data/walker and data/cornell, every frame read back by OpenUSD."""

    @classmethod
    def setUpClass(cls):
        if not ARGS.qsgi:
            raise unittest.SkipTest("no --qsgi")
        sys.path.insert(0, USD_CHECK)
        import check_usd
        cls.check_usd = check_usd
        cls.scratch = tempfile.mkdtemp(prefix="qsgi-usd-out-")
        cls.keep = False

    @classmethod
    def tearDownClass(cls):
        if cls.keep:
            print(f"test_usd_out.py: the failed cases' folders are kept in {cls.scratch}", file=sys.stderr)
        else:
            shutil.rmtree(cls.scratch, ignore_errors=True)

    def render_and_check(self, name, arguments, frames, nodes, rigid=(), deforming=()):
        out = os.path.join(self.scratch, name)
        command = [ARGS.qsgi, "render"] + arguments + ["--frames", f"{frames[0]}:{frames[1]}"] + CHEAP + \
                  ["--usd-out", "--out", out]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            type(self).keep = True
        self.assertEqual(run.returncode, 0, f"{' '.join(command)}\n{run.stdout}{run.stderr}")
        checker = self.check_usd.check(out, frames, list(nodes), rigid, deforming)
        print(f"\n  {name}: {checker.summary()}", file=sys.stderr)
        for line in checker.warnings:
            print("  warning: " + line, file=sys.stderr)
        if checker.failures:
            type(self).keep = True
        self.assertEqual(checker.failures, [], f"{' '.join(command)}\n  " + "\n  ".join(checker.failures))
        from pxr import Usd, UsdGeom
        stage = Usd.Stage.Open(os.path.join(out, "asset.usda"))
        self.assertEqual(stage.GetTimeCodesPerSecond(), 24.0, "the animation's frame rate (--fps, 24 by default)")
        for node, mesh in nodes.items():  # named after the glTF's nodes and meshes
            self.assertTrue(stage.GetPrimAtPath(f"/Scene/{node}/{mesh}").IsA(UsdGeom.Mesh), f"no Mesh /Scene/{node}/{mesh}")
        return checker

    def test_walker_skinned_every_frame(self):
        self.render_and_check("walker", [WALKER, "--animation", "gltf"], (0, 4), deforming=["Figure"],
                              nodes=mesh_nodes(WALKER))

    def test_walker_subdivided(self):
        checker = self.render_and_check("walker-subdivided", [WALKER, "--animation", "gltf", "--subdivide", "0.25"],
                                        (0, 1), deforming=["Figure"], nodes=mesh_nodes(WALKER))
        with open(WALKER) as f:
            gltf = json.load(f)
        accessors = gltf["accessors"]
        unrefined = sum(accessors[p["attributes"]["POSITION"]]["count"]
                        for n in gltf["nodes"] if "mesh" in n for p in gltf["meshes"][n["mesh"]]["primitives"])
        self.assertGreater(checker.vertices, unrefined, "--subdivide: the asset holds the refined meshes")

    def test_cornell_rigid_mover_by_transform_file(self):
        self.render_and_check("cornell", [CORNELL, "--animation", CORNELL_ANIMATION], (0, 2), rigid=["Block"],
                              nodes=mesh_nodes(CORNELL))

    def test_cornell_frames_not_from_zero(self):
        # Time code = frame number, not the frame's index in the run.
        self.render_and_check("cornell-2-4", [CORNELL, "--animation", CORNELL_ANIMATION], (2, 4), rigid=["Block"],
                              nodes=mesh_nodes(CORNELL))

    def test_a_double_sided_card_carries_its_back(self):
        # The materials room's MASK card is doubleSided: its mesh alone has the back primvars, which
        # the checker reads against the PLY's back columns as it reads the front's.
        self.render_and_check("materials-room", [MATERIALS_ROOM, "--sky", "1,1,1"], (0, 0), nodes=mesh_nodes(MATERIALS_ROOM))
        from pxr import Usd, UsdGeom
        stage = Usd.Stage.Open(os.path.join(self.scratch, "materials-room", "asset.usda"))
        with_back = sorted(str(p.GetPath()) for p in stage.Traverse()
                           if p.IsA(UsdGeom.Mesh) and UsdGeom.PrimvarsAPI(p).GetPrimvar("backRadiance").IsDefined())
        self.assertEqual(with_back, ["/Scene/MaskCard/MaskCard"])
        back = UsdGeom.PrimvarsAPI(stage.GetPrimAtPath("/Scene/MaskCard/MaskCard")).GetPrimvar("backIrradiance").Get(0)
        self.assertGreater(max(max(c) for c in back), 0, "the card's back faces the ceiling panel: it is lit")


def main():
    global ARGS
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--qsgi", help="the qsgi executable: render data/walker and data/cornell with --usd-out")
    parser.add_argument("--self-test", action="store_true", help="only the checker on the hand-written asset and its "
                        "broken copies")
    ARGS = parser.parse_args()
    if not ARGS.self_test and not ARGS.qsgi:
        parser.error("give --qsgi PATH or --self-test")
    enter_venv()
    require_pinned_usd()
    tests = CheckerSelfTest if ARGS.self_test else QsgiAssetsReadBack
    suite = unittest.defaultTestLoader.loadTestsFromTestCase(tests)
    result = unittest.TextTestRunner(verbosity=2).run(suite)
    return 0 if result.wasSuccessful() and result.testsRun else 1


if __name__ == "__main__":
    sys.exit(main())
