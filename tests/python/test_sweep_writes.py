#!/usr/bin/python3
"""The sweep writes nothing through a link planted in its --out (scripts/qsgibatch/output_folder.py):
a point's result.json, sweep.csv, the plots and the Slurm merge record are written through no link
planted at their final or temporary names, a link planted where the sweep needs a folder (points/,
a point's folder, its run/, probe/, slurm/) is refused and its target left alone. Fake results
stand in for renders; no qsgi and no Slurm needed.

    /usr/bin/python3 tests/python/test_sweep_writes.py        (two seconds or so)"""
import contextlib
import csv
import io
import json
import math
import os
import stat
import sys
import tempfile
import types
import unittest
from unittest import mock

try:
    import matplotlib  # noqa: F401
    import numpy  # noqa: F401
except ImportError:  # another python3 first on PATH (pyenv); Debian's has python3-numpy and -matplotlib
    if sys.executable != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPOSITORY, "scripts"))

import sweep  # noqa: E402  (scripts/sweep.py)
from qsgibatch import grid, output_folder, plots, runner, slurm, table  # noqa: E402

VICTIM_BYTES = b"not the sweep's to touch\n"
POINT = grid.Point(family="accuracy", estimator="detp", boundary="clip", photons=1000, radius_fraction=0.015, k=0,
                   full_recompute=False, frames="0:1", sampler="sobol")
OLD_TEMPORARIES = ["{}.tmp", "{}.tmp.png"]  # result.json.tmp, sweep.csv.tmp, pareto.png.tmp.png
PLOTS = ["error_vs_photons.png", "pareto.png", "time_vs_photons.png", "bias_vs_radius.png", "extremes.png"]


def temporary(name: str, n: int = 0) -> str:
    """The n-th temporary name output_folder.write_file tries for `name` in this process."""
    base = f".{name}{output_folder.TEMPORARY_MARKER}.{os.getpid()}"
    return base if n == 0 else f"{base}.{n}"


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def fake_results() -> list:
    """Rows enough for every plot: two estimators, two samplers, three photon counts, the three families."""
    results = []
    for family, samplers in (("accuracy", ("sobol", "random")), ("full", ("sobol",)), ("extreme", ("sobol",))):
        for estimator in ("impact-count", "detp:clip"):
            fractions = (0.0,) if estimator == "impact-count" else (1e-6, 0.015, 1.0) if family == "extreme" \
                else (0.01, 0.015)
            for sampler in samplers:
                for photons in (1000, 10000, 100000):
                    for fraction in fractions:
                        r = {c: 0.5 for c in table.COLUMNS}
                        r.update(family=family, estimator=estimator, sampler=sampler, photons=photons,
                                 radius_fraction=fraction, k=math.nan, full_recompute=family == "full",
                                 frames="0:1", seed=1, noise_seed=2, reference="committed: réf.ply",
                                 qsgi_version="test", shared_cores=False, nan_count=0, inf_count=0,
                                 rms_all=photons ** -0.5 * (1 + fraction), median_frame_s=1e-5 * photons,
                                 noise=0.3 * photons ** -0.5, bias_all=-0.01, bias_near_edge=-0.02,
                                 bias_interior=0.001)
                        results.append(r)
    return results


class Stop(Exception):
    """Raised by the fake qsgi where a real one would render."""


class FakeQsgi:
    def __init__(self):
        self.renders = []

    def render(self, out, options, seed, threads):
        self.renders.append(out)
        raise Stop(out)


class PlantedLinksTest(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="qsgi-sweep-writes-test.")
        self.out = os.path.join(self.scratch.name, "out")
        self.outside = os.path.join(self.scratch.name, "outside")  # what planted links point to
        os.makedirs(self.out)
        os.makedirs(self.outside)
        self.victim = os.path.join(self.outside, "victim")
        with open(self.victim, "wb") as f:
            f.write(VICTIM_BYTES)

    def tearDown(self):
        self.scratch.cleanup()

    def plant(self, folder: str, name: str) -> None:
        """Links at `name`, at its first two temporary names (to a file outside, and to a name outside
        that does not exist yet) and at the temporary names the sweep used before output_folder."""
        os.makedirs(folder, exist_ok=True)
        os.symlink(self.victim, os.path.join(folder, name))
        os.symlink(self.victim, os.path.join(folder, temporary(name)))
        os.symlink(os.path.join(self.outside, "created-" + name), os.path.join(folder, temporary(name, 1)))
        for old in OLD_TEMPORARIES:
            os.symlink(self.victim, os.path.join(folder, old.format(name)))

    def assertWrittenPast(self, folder: str, name: str, expected: bytes) -> None:
        """`name` is now a regular file holding `expected`; the file outside is unchanged, nothing was
        created outside, the planted temporaries were not touched and no temporary of ours is left."""
        path = os.path.join(folder, name)
        self.assertTrue(stat.S_ISREG(os.lstat(path).st_mode), f"{path} is not a regular file")
        self.assertEqual(read(path), expected)
        self.assertEqual(read(self.victim), VICTIM_BYTES)
        self.assertEqual(sorted(os.listdir(self.outside)), ["victim"])
        self.assertEqual(os.readlink(os.path.join(folder, temporary(name))), self.victim)
        self.assertTrue(os.path.islink(os.path.join(folder, temporary(name, 1))))
        for old in OLD_TEMPORARIES:
            self.assertEqual(os.readlink(os.path.join(folder, old.format(name))), self.victim)
        left = [n for n in os.listdir(folder) if n.startswith(f".{name}{output_folder.TEMPORARY_MARKER}")]
        self.assertEqual(sorted(left), sorted([temporary(name), temporary(name, 1)]))

    def assertOutsideUntouched(self) -> None:
        self.assertEqual(read(self.victim), VICTIM_BYTES)
        self.assertEqual(sorted(os.listdir(self.outside)), ["victim"])

    def make_sweep(self, qsgi=None) -> runner.Sweep:
        """A Sweep as sweep.py makes one, without reading a reference PLY."""
        s = runner.Sweep.__new__(runner.Sweep)
        s.config, s.qsgi, s.out, s.diagonal = types.SimpleNamespace(seeds=(1, 2)), qsgi, self.out, 2.0
        s.reference_path, s.reference_description = "/nonexistent/reference.ply", "committed: test"
        s.jobs, s.threads = 1, 1
        s.occupancy, s.computed, s._computed_lock = runner.Occupancy(), 0, runner.threading.Lock()
        return s

    # result.json ---------------------------------------------------------------------------------

    def test_result_json_is_written_past_links_at_its_name_and_temporaries(self):
        folder = os.path.join(self.out, "points", POINT.name)
        self.plant(folder, "result.json")
        with open(self.victim, "w") as f:  # a forged result is no result: the point is computed
            json.dump({"result_version": runner.RESULT_VERSION, "sampler": POINT.sampler,
                       "reference": "committed: test"}, f)
        forged = read(self.victim)
        self.assertIsNone(runner.finished(self.out, POINT))
        computed = {"result_version": runner.RESULT_VERSION, "sampler": POINT.sampler, "rms_all": 0.25,
                    "noise": math.nan, "reference": "committed: test"}
        with mock.patch.object(runner.Sweep, "_compute", side_effect=lambda point: dict(computed)):
            result = self.make_sweep().run(POINT)
        self.assertEqual(read(self.victim), forged)
        with open(self.victim, "wb") as f:
            f.write(VICTIM_BYTES)
        self.assertWrittenPast(folder, "result.json", json.dumps(result, indent=1, sort_keys=True).encode())
        self.assertEqual(runner.finished(self.out, POINT), json.loads(json.dumps(result)))

    def test_a_link_planted_as_points_or_a_point_folder_is_refused(self):
        for planted in (os.path.join(self.out, "points"), os.path.join(self.out, "points", POINT.name)):
            with self.subTest(planted=planted):
                os.makedirs(os.path.dirname(planted), exist_ok=True)
                os.symlink(self.outside, planted)
                qsgi = FakeQsgi()
                with self.assertRaisesRegex(output_folder.FolderError, f"{planted}: is not a folder"):
                    self.make_sweep(qsgi)._compute(POINT)  # before qsgi renders into it
                with mock.patch.object(runner.Sweep, "_compute", side_effect=lambda point: {"rms_all": 0.25}):
                    with self.assertRaisesRegex(output_folder.FolderError, f"{planted}: is not a folder"):
                        self.make_sweep(qsgi).run(POINT)  # planted once the point was computed
                self.assertEqual(qsgi.renders, [])
                self.assertOutsideUntouched()
                os.unlink(planted)

    def test_a_link_planted_as_a_run_folder_is_refused_before_qsgi_renders(self):
        # A folder outside that another sampler rendered: neither removed nor rendered into.
        target = os.path.join(self.outside, "run")
        os.makedirs(target)
        with open(os.path.join(target, "timing.json"), "w") as f:
            json.dump({"config": {"sampler": "random"}}, f)
        for name in ("run", "seed2"):
            with self.subTest(name=name):
                folder = os.path.join(self.out, "points", POINT.name)
                os.makedirs(folder, exist_ok=True)
                os.symlink(target, os.path.join(folder, name))
                qsgi = FakeQsgi()
                with self.assertRaisesRegex(output_folder.FolderError, f"{name}: is not a folder"):
                    self.make_sweep(qsgi)._compute(POINT)
                self.assertEqual(qsgi.renders, [])
                self.assertEqual(os.listdir(target), ["timing.json"])
                os.unlink(os.path.join(folder, name))

    def test_another_samplers_run_is_removed_without_following_links_inside(self):
        kept = os.path.join(self.outside, "kept")
        os.makedirs(kept)
        with open(os.path.join(kept, "frame_0000.ply"), "wb") as f:
            f.write(VICTIM_BYTES)
        run = os.path.join(self.out, "points", POINT.name, "run")
        os.makedirs(os.path.join(run, "sub"))
        with open(os.path.join(run, "timing.json"), "w") as f:
            json.dump({"config": {"sampler": "random"}}, f)
        os.symlink(kept, os.path.join(run, "linked-folder"))
        os.symlink(self.victim, os.path.join(run, "sub", "linked-file"))
        qsgi = FakeQsgi()
        with self.assertRaises(Stop):
            self.make_sweep(qsgi)._compute(POINT)
        self.assertEqual(qsgi.renders, [run])
        self.assertFalse(os.path.lexists(run))
        self.assertEqual(os.listdir(kept), ["frame_0000.ply"])
        self.assertEqual(read(self.victim), VICTIM_BYTES)

    def test_a_run_of_the_same_sampler_is_kept(self):
        run = os.path.join(self.out, "points", POINT.name, "run")
        os.makedirs(run)
        with open(os.path.join(run, "timing.json"), "w") as f:  # and the same lighting (POINT's: the paper's)
            json.dump({"config": {"sampler": "sobol", "direct": "photons", "gather": None}}, f)
        with self.assertRaises(Stop):
            self.make_sweep(FakeQsgi())._compute(POINT)
        self.assertEqual(os.listdir(run), ["timing.json"])

    # sweep.csv and the plots -------------------------------------------------------------------------

    def test_the_csv_is_written_past_links_at_its_name_and_temporaries(self):
        results = fake_results()
        expected = io.StringIO()
        writer = csv.writer(expected)
        writer.writerow(table.COLUMNS)
        for r in results:
            writer.writerow(["" if isinstance(r[c], float) and math.isnan(r[c]) else
                             repr(r[c]) if isinstance(r[c], float) else r[c] for c in table.COLUMNS])
        self.plant(self.out, "sweep.csv")
        table.write(os.path.join(self.out, "sweep.csv"), results)
        self.assertWrittenPast(self.out, "sweep.csv", expected.getvalue().encode())

    def test_the_plots_are_written_past_links_at_their_names_and_temporaries(self):
        table.write(os.path.join(self.out, "sweep.csv"), fake_results())
        rows = table.read(os.path.join(self.out, "sweep.csv"))
        for name in PLOTS:
            self.plant(self.out, name)
        with mock.patch.object(plots, "write_file", wraps=output_folder.write_file) as write_file:
            self.assertEqual(plots.draw_all(rows, self.out, "note")[0], PLOTS)
        rendered = {c.args[1]: c.args[2] for c in write_file.call_args_list}  # name -> the PNG drawn
        self.assertEqual(sorted(rendered), sorted(PLOTS))
        for name in PLOTS:
            self.assertEqual(rendered[name][:8], b"\x89PNG\r\n\x1a\n")
            self.assertGreater(len(rendered[name]), 10000)
            self.assertWrittenPast(self.out, name, rendered[name])

    # Slurm ---------------------------------------------------------------------------------------------

    def test_the_merge_record_is_written_past_links_and_no_job_read_through_one_is_cancelled(self):
        logs = os.path.join(self.out, "slurm")
        self.plant(logs, "merge-job")
        with open(self.victim, "wb") as f:
            f.write(b"4242\n")
        with mock.patch.object(slurm.subprocess, "run") as run:
            slurm.replace_merge_job(os.path.join(logs, "merge-job"), "77")
        run.assert_not_called()
        with open(self.victim, "wb") as f:
            f.write(VICTIM_BYTES)
        self.assertWrittenPast(logs, "merge-job", b"77\n")

    def test_a_link_planted_as_the_slurm_folder_is_refused(self):
        os.symlink(self.outside, os.path.join(self.out, "slurm"))
        with self.assertRaisesRegex(output_folder.FolderError, "slurm: is not a folder"):
            slurm.replace_merge_job(os.path.join(self.out, "slurm", "merge-job"), "77")
        args = types.SimpleNamespace(out=self.out, slurm_cpus=1, qsgi="/nonexistent/qsgi", quick=False,
                                     max_photons=None, slurm_option=[])
        config = types.SimpleNamespace(path="/nonexistent/sweep.json", points=[POINT])
        stderr = io.StringIO()
        with mock.patch.object(slurm, "require_sbatch"), \
                mock.patch.object(slurm, "sbatch", side_effect=AssertionError("nothing may be submitted")), \
                contextlib.redirect_stderr(stderr):
            self.assertEqual(slurm.submit_sweep(args, config, "/nonexistent/sweep.py"), 2)
        self.assertRegex(stderr.getvalue(), r"^sweep: .*/out/slurm: is not a folder .*\n$")
        self.assertOutsideUntouched()

    # sweep.py ------------------------------------------------------------------------------------------

    def test_a_link_planted_as_the_probe_folder_is_refused_before_qsgi_runs(self):
        os.symlink(self.outside, os.path.join(self.out, "probe"))
        stderr = io.StringIO()
        with mock.patch.object(sweep.Qsgi, "render", side_effect=AssertionError("qsgi may not run")), \
                contextlib.redirect_stderr(stderr):
            code = sweep.main([os.path.join(REPOSITORY, "tests", "data", "sweep-tiny.json"), "--out", self.out,
                               "--qsgi", "/bin/true"])
        self.assertEqual(code, 2)
        self.assertRegex(stderr.getvalue(), r"^sweep: .*/out/probe: is not a folder .*\n$")
        self.assertOutsideUntouched()


if __name__ == "__main__":
    unittest.main()
