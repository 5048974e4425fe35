#!/usr/bin/env python3
"""scripts/surface_score.py: the bake interpolated across each triangle, scored at surface points.

A field linear on each triangle is interpolated exactly, so a bake holding it at its vertices
scores 0 against a reference holding it at the points; a hidden point, however wrong, counts for
nothing; a known error at one vertex gives the error its barycentric weight predicts; and the
reference's noise is taken out as its mean squared standard error.

With --qsgi PATH it also renders data/cornell's frame 0 (cheap settings) and checks that `qsgi compare`
against the committed surface reference gives, overall, the figures this script's independent
numpy interpolation gives."""
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
import surface_score  # noqa: E402
from qsgibatch import ply  # noqa: E402

VERTEX = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4"),
                   ("radiosity_r", "<f4"), ("radiosity_g", "<f4"), ("radiosity_b", "<f4"),
                   ("irradiance_r", "<f4"), ("irradiance_g", "<f4"), ("irradiance_b", "<f4"),
                   ("red", "u1"), ("green", "u1"), ("blue", "u1")])
POINT = np.dtype([("triangle", "<i4")] + [(k, "<f4") for k in ("b1", "b2", "x", "y", "z", "nx", "ny", "nz",
                                                                "irradiance_r", "irradiance_g", "irradiance_b",
                                                                "stderr_r", "stderr_g", "stderr_b")] + [("hidden", "u1")])


def field(p):
    """Irradiance linear in position, distinct per channel."""
    return np.stack([1 + 2 * p[:, 0], 3 + p[:, 2], 2 + p[:, 0] - p[:, 2]], 1)


def write_frame(path, positions, faces, irradiance):
    v = np.zeros(len(positions), VERTEX)
    for i, k in enumerate("xyz"):
        v[k] = positions[:, i]
    v["ny"] = 1
    for i, c in enumerate("rgb"):
        v["irradiance_" + c] = irradiance[:, i]
        v["radiosity_" + c] = 0.5 * irradiance[:, i]
    props = "".join(f"property float {n}\n" for n in VERTEX.names[:12]) + "".join(f"property uchar {n}\n" for n in VERTEX.names[12:])
    fa = np.zeros(len(faces), np.dtype([("n", "u1"), ("v", "<i4", (3,))]))
    fa["n"], fa["v"] = 3, faces
    with open(path, "wb") as f:
        f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v)}\n{props}element face {len(fa)}\n"
                 "property list uchar int vertex_indices\nend_header\n").encode())
        f.write(v.tobytes() + fa.tobytes())


def write_points(path, points):
    props = "property int triangle\n" + "".join(f"property float {k}\n" for k in POINT.names[1:-1]) + "property uchar hidden\n"
    with open(path, "wb") as f:
        f.write(f"ply\nformat binary_little_endian 1.0\nelement point {len(points)}\n{props}end_header\n".encode())
        f.write(points.tobytes())


class SurfaceScore(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="qsgi-surface-score-")
        # A unit square of two triangles on y = 0.
        self.positions = np.array([[0, 0, 0], [1, 0, 0], [1, 0, 1], [0, 0, 1]], np.float64)
        self.faces = np.array([[0, 2, 1], [0, 3, 2]])
        rng = np.random.default_rng(3)
        n = 500
        self.points = np.zeros(n, POINT)
        self.points["triangle"] = rng.integers(0, 2, n)
        r1, r2 = rng.random(n), rng.random(n)
        self.points["b1"], self.points["b2"] = np.sqrt(r1) * (1 - r2), np.sqrt(r1) * r2
        corners = self.positions[self.faces[self.points["triangle"]]]
        b1, b2 = self.points["b1"].astype(np.float64)[:, None], self.points["b2"].astype(np.float64)[:, None]
        self.at = (1 - b1 - b2) * corners[:, 0] + b1 * corners[:, 1] + b2 * corners[:, 2]
        for i, c in enumerate("rgb"):
            self.points["irradiance_" + c] = field(self.at)[:, i]

    def run_script(self, frame, reference):
        out = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "surface_score.py"), frame, reference, "--json"],
                             capture_output=True, text=True)
        self.assertEqual(out.returncode, 0, out.stderr)
        import json
        return json.loads(out.stdout)

    def test_a_linear_field_is_interpolated_exactly_and_hidden_points_count_for_nothing(self):
        frame, reference = os.path.join(self.dir, "frame.ply"), os.path.join(self.dir, "surface.ply")
        write_frame(frame, self.positions, self.faces, field(self.positions))
        points = self.points.copy()
        points["hidden"][:50] = 1
        points["irradiance_r"][:50] = 1e6  # hidden: must not count
        write_points(reference, points)
        result = self.run_script(frame, reference)
        self.assertEqual(result["points"], 450)
        self.assertEqual(result["hidden"], 50)
        self.assertLess(result["relative_rms"], 1e-6)  # float32 storage of the values

    def test_an_error_at_one_vertex_spreads_by_its_barycentric_weight(self):
        values = field(self.positions)
        values[2] += np.array([0.3, 0.0, 0.0])  # vertex 2 is corner 1 of triangle 0 and corner 2 of triangle 1
        weight = np.where(self.points["triangle"] == 0, self.points["b1"], self.points["b2"]).astype(np.float64)
        reference_values = field(self.at)
        expected = np.sqrt(np.mean(np.concatenate([(0.3 * weight) ** 2, np.zeros(2 * len(weight))]))) / np.mean(np.abs(reference_values))
        result = surface_score.score(values, self.faces, self.points)
        self.assertAlmostEqual(result["relative_rms"], expected, delta=1e-6 * expected)

    def test_the_references_noise_is_taken_out_as_its_mean_squared_standard_error(self):
        points = self.points.copy()
        noise = 0.05
        for c in "rgb":
            points["stderr_" + c] = noise
        values = field(self.positions) + 0.1  # an error of 0.1 everywhere (interpolation keeps it)
        result = surface_score.score(values, self.faces, points)
        scale = np.mean(np.abs(field(self.at)))
        self.assertAlmostEqual(result["relative_rms"], 0.1 / scale, delta=1e-5)
        self.assertAlmostEqual(result["reference_noise"], noise / scale, delta=1e-6)
        self.assertAlmostEqual(result["relative_rms_without_noise"], np.sqrt(0.1 ** 2 - noise ** 2) / scale, delta=1e-5)

    def test_a_reference_of_another_mesh_is_refused(self):
        frame, reference = os.path.join(self.dir, "frame.ply"), os.path.join(self.dir, "surface.ply")
        write_frame(frame, self.positions, self.faces[:1], field(self.positions))
        write_points(reference, self.points)
        out = subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "surface_score.py"), frame, reference],
                             capture_output=True, text=True)
        self.assertEqual(out.returncode, 2)
        self.assertIn("another mesh", out.stderr)


QSGI = None


class CompareMatchesNumpy(unittest.TestCase):
    def test_qsgi_compare_over_the_surface_equals_the_numpy_interpolation(self):
        if QSGI is None:
            self.skipTest("no --qsgi given")
        out = tempfile.mkdtemp(prefix="qsgi-surface-compare-")
        reference = os.path.join(ROOT, "tests", "reference", "cornell_f0000_surface.ply")
        render = subprocess.run([QSGI, "render", os.path.join(ROOT, "data", "cornell", "cornell.gltf"), "--animation",
                                 os.path.join(ROOT, "data", "cornell", "animation.json"), "--frames", "0:0", "--out", out,
                                 "--photons", "20000", "--gather", "16", "--direct-samples", "4", "--no-exr", "--quiet"],
                                capture_output=True, text=True)
        self.assertEqual(render.returncode, 0, render.stderr)
        frame = os.path.join(out, "frame_0000.ply")
        compare = subprocess.run([QSGI, "compare", frame, reference, "--json"], capture_output=True, text=True)
        self.assertEqual(compare.returncode, 0, compare.stderr)
        import json
        ours = json.loads(compare.stdout)
        theirs = surface_score.score(ply.read(frame).irradiance(), ply.read(frame).triangles(), ply.read_points(reference))
        self.assertEqual(ours["all"]["points"], theirs["points"])
        self.assertEqual(ours["hidden"], theirs["hidden"])
        for key in ("relative_rms", "reference_noise", "relative_rms_without_noise"):
            self.assertAlmostEqual(ours["all"][key], theirs[key], delta=1e-6 * theirs[key], msg=key)
        # The bands partition the visible points.
        self.assertEqual(sum(ours[b]["points"] for b in ("contact", "edge", "interior")), ours["all"]["points"])


if __name__ == "__main__":
    if "--qsgi" in sys.argv:
        i = sys.argv.index("--qsgi")
        QSGI = sys.argv[i + 1]
        del sys.argv[i:i + 2]
    unittest.main()
