#!/usr/bin/python3
"""The sweep's lighting axes (scripts/qsgibatch/grid.py: grid.direct, grid.gather,
grid.direct_samples): the grid expands direct x gather and skips the pairs qsgi refuses (a gather
with direct light from the photons), a grid left with none is a ConfigError naming the file and the
key, the points of the paper's lighting keep the names they had before the axes (their folders stay
valid), every point passes its lighting to qsgi explicitly (qsgi's defaults may change), and the
results, the CSV and the Pareto plot keep the lightings apart. No qsgi needed.

    /usr/bin/python3 tests/python/test_sweep_lighting.py        (a few seconds)"""
import contextlib
import io
import json
import math
import os
import sys
import tempfile
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
from qsgibatch import grid, plots, runner, table  # noqa: E402

SCENE = os.path.join(REPOSITORY, "data", "cornell", "cornell.gltf")
PAPER = ("photons", 0, 0)  # (direct, gather, direct_samples) of the paper's method


def lighting(p):
    return p.direct, p.gather, p.direct_samples


def option_pairs(options):
    """qsgi options as {option: value} (the flags without a value map to None)."""
    pairs, i = {}, 0
    while i < len(options):
        if i + 1 < len(options) and not options[i + 1].startswith("--"):
            pairs[options[i]] = options[i + 1]
            i += 2
        else:
            pairs[options[i]] = None
            i += 1
    return pairs


class ConfigTest(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="qsgi-sweep-lighting-test.")
        self.path = os.path.join(self.scratch.name, "sweep.json")

    def tearDown(self):
        self.scratch.cleanup()

    def load(self, quick=False, **grid_keys):
        config = {"scene": SCENE, "frames": "0:1",
                  "grid": dict({"photons": [1000], "radius_fraction": [0.015], "estimators": ["detp:clip"]},
                               **grid_keys)}
        with open(self.path, "w") as f:
            json.dump(config, f)
        return grid.load(self.path, quick)

    def assertConfigError(self, key, **grid_keys):
        with self.assertRaises(grid.ConfigError) as caught:
            self.load(**grid_keys)
        message = str(caught.exception)
        self.assertTrue(message.startswith(f"{self.path}: {key}: "), message)
        return message


class GridTest(ConfigTest):
    def test_direct_times_gather_skips_a_gather_under_photons(self):
        config = self.load(direct=["photons", "exact"], gather=[0, 64, 256])
        accuracy = [lighting(p) for p in config.points if p.family == "accuracy"]
        self.assertEqual(accuracy, [PAPER, ("exact", 0, 64), ("exact", 64, 64), ("exact", 256, 64)])
        # The full and extreme families keep the paper's lighting whatever the grid's.
        self.assertEqual({lighting(p) for p in config.points if p.family != "accuracy"}, {PAPER})

    def test_every_axis_multiplies_the_valid_lightings(self):
        config = self.load(photons=[1000, 10000], estimators=["impact-count", "detp:clip"], samplers=["sobol", "random"],
                           direct=["photons", "exact"], gather=[0, 256])
        accuracy = [p for p in config.points if p.family == "accuracy"]
        self.assertEqual(len(accuracy), 2 * 2 * 2 * 3)  # photons x estimators x samplers x 3 valid lightings
        self.assertEqual(len(set(accuracy)), len(accuracy))
        self.assertEqual(len({p.name for p in config.points}), len(config.points))
        self.assertEqual(len([p for p in config.points if p.family == "full"]), 2 * 2)

    def test_direct_samples_default_64_an_integer_or_a_list_under_exact_only(self):
        self.assertEqual({lighting(p) for p in self.load(direct=["exact"]).points if p.family == "accuracy"},
                         {("exact", 0, 64)})
        self.assertEqual({lighting(p) for p in self.load(direct=["exact"], direct_samples=16).points
                          if p.family == "accuracy"}, {("exact", 0, 16)})
        config = self.load(direct=["photons", "exact"], gather=[0, 256], direct_samples=[16, 128])
        self.assertEqual([lighting(p) for p in config.points if p.family == "accuracy"],
                         [PAPER, ("exact", 0, 16), ("exact", 0, 128), ("exact", 256, 16), ("exact", 256, 128)])

    def test_a_config_without_the_axes_is_the_paper_lighting(self):
        plain = self.load().points
        self.assertEqual(self.load(direct=["photons"], gather=[0]).points, plain)
        self.assertEqual({lighting(p) for p in plain}, {PAPER})

    def test_only_invalid_pairs_is_a_config_error_naming_the_file_and_key(self):
        message = self.assertConfigError("grid.gather", direct=["photons"], gather=[64, 256])
        self.assertIn("--direct exact", message)
        self.assertEqual(message.count("\n"), 0)

    def test_bad_lighting_values_name_their_key(self):
        self.assertConfigError("grid.direct[1]", direct=["photons", "shadow-rays"])
        self.assertConfigError("grid.direct", direct="exact")  # a list, as every axis
        self.assertConfigError("grid.direct", direct=[])
        self.assertConfigError("grid.gather[0]", gather=[-1])
        self.assertConfigError("grid.gather[0]", gather=[1.5])
        self.assertConfigError("grid.gather[0]", gather=[grid.MAX_GATHER + 1])
        self.assertConfigError("grid.direct_samples", direct=["exact"], direct_samples=0)
        self.assertConfigError("grid.direct_samples[1]", direct=["exact"], direct_samples=[16, True])
        self.assertConfigError("grid", directs=["exact"])  # an unknown key

    def test_sweep_py_refuses_a_config_of_invalid_pairs_in_one_line_exit_2(self):
        with open(self.path, "w") as f:
            json.dump({"scene": SCENE, "grid": {"photons": [1000], "radius_fraction": [0.015], "estimators": ["detp"],
                                                "direct": ["photons"], "gather": [256]}}, f)
        out = os.path.join(self.scratch.name, "out")
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            self.assertEqual(sweep.main([self.path, "--out", out, "--list"]), 2)
        self.assertRegex(stderr.getvalue(), r"^sweep: .*/sweep\.json: grid\.gather: [^\n]*\n$")
        self.assertFalse(os.path.exists(out))

    def test_the_quick_section_overrides_the_axes(self):
        config = {"scene": SCENE, "grid": {"photons": [1000], "radius_fraction": [0.015], "estimators": ["detp"],
                                           "direct": ["photons", "exact"], "gather": [0, 64, 256]},
                  "quick": {"grid": {"gather": [0]}}}
        with open(self.path, "w") as f:
            json.dump(config, f)
        self.assertEqual(len([p for p in grid.load(self.path, False).points if p.family == "accuracy"]), 4)
        self.assertEqual([lighting(p) for p in grid.load(self.path, True).points if p.family == "accuracy"],
                         [PAPER, ("exact", 0, 64)])


class NameTest(ConfigTest):
    def test_the_paper_lighting_keeps_the_names_from_before_the_axes(self):
        # tests/data/sweep-tiny.json: the folders Sweep.* and scripts/test-slurm.sh rendered before.
        tiny = grid.load(os.path.join(REPOSITORY, "tests", "data", "sweep-tiny.json"), False)
        self.assertEqual([p.name for p in tiny.points], [
            "impact-count_n1000_f0-1", "impact-count_n1000_f0-1_full", "impact-count_n10000_f0-1",
            "impact-count_n10000_f0-1_full", "detp-clip_n1000_r0.015_f0-1", "detp-clip_n1000_r0.015_f0-1_full",
            "detp-clip_n10000_r0.015_f0-1", "detp-clip_n10000_r0.015_f0-1_full", "detp-clip_n1000_r1e-06_f0-0",
            "detp-clip_n1000_r0.1_f0-0", "detp-clip_n1_r0.015_f0-0"])
        config = self.load(samplers=["sobol", "random"], direct=["photons", "exact"], gather=[0, 256])
        paper = sorted(p.name for p in config.points if lighting(p) == PAPER and p.family == "accuracy")
        self.assertEqual(paper, ["detp-clip_n1000_r0.015_f0-1", "detp-clip_n1000_r0.015_f0-1_random"])

    def test_other_lightings_spell_direct_samples_and_gather(self):
        point = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1")
        self.assertEqual(point.name, "detp-clip_n1000_r0.015_f0-1")
        exact = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1", "random", "exact", 0, 64)
        self.assertEqual(exact.name, "detp-clip_n1000_r0.015_f0-1_random_exact-s64")
        gathered = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1", "sobol", "exact", 256, 16)
        self.assertEqual(gathered.name, "detp-clip_n1000_r0.015_f0-1_exact-s16_g256")

    def test_every_committed_config_has_unique_names_and_paper_names_without_lighting(self):
        for name in ("sweep-cornell.json", "sweep-tree.json"):
            for quick in (False, True):
                with self.subTest(config=name, quick=quick):
                    config = grid.load(os.path.join(REPOSITORY, "configs", name), quick)
                    self.assertEqual(len({p.name for p in config.points}), len(config.points))
                    for p in config.points:
                        spelled = "_exact-" in p.name or "_photons" in p.name
                        self.assertEqual(spelled, lighting(p) != PAPER, p.name)


class OptionsTest(unittest.TestCase):
    def test_the_paper_lighting_is_passed_explicitly(self):
        for family, full in (("accuracy", False), ("full", True), ("extreme", False)):
            point = grid.Point(family, "detp", "clip", 1000, 0.015, 0, full, "0:1")
            options = point.qsgi_options(2.0)
            with self.subTest(family=family):
                self.assertEqual(option_pairs(options)["--direct"], "photons")
                self.assertEqual(option_pairs(options)["--gather"], "0")
                self.assertNotIn("--direct-samples", options)

    def test_exact_passes_direct_gather_and_direct_samples(self):
        for gather in (0, 256):
            point = grid.Point("accuracy", "photon-map", "clip", 1000, 0.015, 50, False, "0:1", "sobol", "exact",
                               gather, 32)
            pairs = option_pairs(point.qsgi_options(2.0))
            with self.subTest(gather=gather):
                self.assertEqual((pairs["--direct"], pairs["--gather"], pairs["--direct-samples"]),
                                 ("exact", str(gather), "32"))
                self.assertEqual(pairs["--estimator"], "photon-map")

    def test_the_probe_and_the_reference_build_pass_the_paper_lighting(self):
        from qsgibatch import qsgi, reference
        calls = []

        class Enough(Exception):
            pass

        class Recorder(qsgi.Qsgi):
            def render(self, out, options, seed, threads):
                calls.append(options)
                if "impact-count" in options:
                    return {"scene": {"animation_diagonal": 2.0}}
                raise Enough  # the reference build's first render

        recorder = Recorder("/nonexistent/qsgi", SCENE, "")
        recorder.animation_diagonal("/nonexistent/probe")
        with tempfile.TemporaryDirectory() as out:
            config = mock.Mock(reference="", scene=SCENE, animation="",
                               reference_build={"photons": 1000, "seeds": [1], "radius_fraction": 0.01})
            with self.assertRaises(Enough):
                reference.prepare(config, recorder, out, 2.0, 1)
        self.assertEqual(len(calls), 2)
        for options in calls:
            self.assertEqual((option_pairs(options)["--direct"], option_pairs(options)["--gather"]), ("photons", "0"))


class ResultTest(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="qsgi-sweep-lighting-test.")
        self.out = self.scratch.name

    def tearDown(self):
        self.scratch.cleanup()

    def write_result(self, point, result):
        folder = os.path.join(self.out, "points", point.name)
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, "result.json"), "w") as f:
            json.dump(dict({"result_version": runner.RESULT_VERSION, "sampler": point.sampler}, **result), f)

    def test_a_result_from_before_the_axes_is_the_paper_lightings_and_no_other(self):
        paper = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1")
        self.write_result(paper, {"rms_all": 0.5})  # no lighting recorded: direct light from the photons
        self.assertIsNotNone(runner.finished(self.out, paper))
        self.write_result(paper, {"rms_all": 0.5, "direct": "exact", "gather": 0, "direct_samples": 64})
        self.assertIsNone(runner.finished(self.out, paper))

    def test_an_exact_result_must_match_gather_and_direct_samples(self):
        point = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1", "sobol", "exact", 256, 64)
        self.write_result(point, {"direct": "exact", "gather": 256, "direct_samples": 64})
        self.assertIsNotNone(runner.finished(self.out, point))
        for other in ({"direct": "exact", "gather": 64, "direct_samples": 64},
                      {"direct": "exact", "gather": 256, "direct_samples": 16}, {}):
            with self.subTest(other=other):
                self.write_result(point, other)
                self.assertIsNone(runner.finished(self.out, point))

    def test_a_run_of_another_lighting_is_discarded_before_resuming(self):
        # timing.json's config as qsgi records it: gather and direct_samples null under photons; a
        # qsgi before the lighting options records no "direct", and --resume refuses its folders.
        exact = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1", "sobol", "exact", 256, 64)
        paper = grid.Point("accuracy", "detp", "clip", 1000, 0.015, 0, False, "0:1")
        photons = {"direct": "photons", "gather": None, "direct_samples": None}
        for point, config, kept in ((exact, {"direct": "exact", "gather": 256, "direct_samples": 64}, True),
                                    (exact, {"direct": "exact", "gather": 0, "direct_samples": 64}, False),
                                    (exact, {"direct": "exact", "gather": 256, "direct_samples": 16}, False),
                                    (exact, photons, False),
                                    (exact, {}, False),
                                    (paper, photons, True),
                                    (paper, {"direct": "exact", "gather": 0, "direct_samples": 64}, False),
                                    (paper, {}, False)):
            with self.subTest(point=point.name, config=config):
                run = os.path.join(self.out, "points", point.name, "run")
                os.makedirs(run, exist_ok=True)
                with open(os.path.join(run, "timing.json"), "w") as f:
                    json.dump({"config": dict({"sampler": "sobol"}, **config)}, f)
                fd = runner.open_point_folder(self.out, point.name)
                try:
                    runner._discard_other_sampler(fd, "run", run, point)
                finally:
                    os.close(fd)
                self.assertEqual(os.path.isdir(run), kept)

    def test_frame_time_includes_the_second_pass(self):
        frame = {"photon_update_s": 0.5, "estimation_s": 1.0, "segments": 10, "photons_missing_scene": 0,
                 "tracked_bytes": 8, "tracked_segments": 2}
        timing = {"frames": [dict(frame, direct_s=0.25, gather_s=2.0), dict(frame, direct_s=0.125, gather_s=1.0)]}
        seconds = runner._frame_seconds(timing)
        self.assertEqual(seconds["initial_s"], 3.75)
        self.assertEqual(seconds["median_frame_s"], 2.625)
        self.assertEqual((seconds["median_direct_s"], seconds["median_gather_s"]), (0.125, 1.0))
        old = runner._frame_seconds({"frames": [frame, frame]})  # a qsgi before the second pass
        self.assertEqual((old["initial_s"], old["median_frame_s"], old["median_gather_s"]), (1.5, 1.5, 0.0))


def rows_of_three_lightings():
    """sweep.csv rows read back: detp:clip and impact count, photons / exact / exact+gather 256."""
    results = []
    for family, lightings in (("accuracy", (PAPER, ("exact", 0, 64), ("exact", 256, 64))), ("full", (PAPER,))):
        for estimator in ("impact-count", "detp:clip"):
            for direct, gather, samples in lightings:
                for photons in (1000, 10000, 100000):
                    r = {c: 0.5 for c in table.COLUMNS}
                    r.update(family=family, estimator=estimator, sampler="sobol", photons=photons, direct=direct,
                             gather=gather, direct_samples=samples if direct == "exact" else math.nan,
                             radius_fraction=0.0 if estimator == "impact-count" else 0.015, k=math.nan,
                             full_recompute=family == "full", frames="0:1", reference="committed: test",
                             qsgi_version="test", nan_count=0, inf_count=0, rms_all=photons ** -0.5 / (1 + gather),
                             median_frame_s=1e-5 * photons + gather * 1e-3)
                    results.append(r)
    return results


class TableAndPlotTest(unittest.TestCase):
    def test_the_csv_has_the_lighting_columns(self):
        with tempfile.TemporaryDirectory() as out:
            table.write(os.path.join(out, "sweep.csv"), rows_of_three_lightings())
            rows = table.read(os.path.join(out, "sweep.csv"))
        for column in ("direct", "gather", "direct_samples", "median_direct_s", "median_gather_s"):
            self.assertIn(column, table.COLUMNS)
        self.assertEqual({(r["direct"], r["gather"]) for r in rows}, {("photons", 0.0), ("exact", 0.0), ("exact", 256.0)})
        self.assertTrue(all(math.isnan(r["direct_samples"]) for r in rows if r["direct"] == "photons"))

    def test_the_pareto_plot_draws_a_series_per_lighting(self):
        with tempfile.TemporaryDirectory() as out:
            table.write(os.path.join(out, "sweep.csv"), rows_of_three_lightings())
            rows = table.read(os.path.join(out, "sweep.csv"))
            legends = {}

            def save(figure, out, name, note):
                legends[name] = [t.get_text() for axis in figure.axes if axis.get_legend()
                                 for t in axis.get_legend().get_texts()]
                plots.plt.close(figure)
                return name

            with mock.patch.object(plots, "_save", side_effect=save):
                plots.draw_all(rows, out, "note")
        pareto = legends["pareto.png"]
        for series in ("detp:clip, sobol, photons: incremental (front)", "detp:clip, sobol, exact: incremental (front)",
                       "detp:clip, sobol, exact+gather 256: incremental (front)",
                       "detp:clip, sobol, photons: --full-recompute", "impact-count, sobol, exact+gather 256: incremental (front)"):
            self.assertIn(series, pareto)
        self.assertEqual(len(pareto), 2 * 3 + 2)  # 2 estimators x 3 lightings, and the full lines (photons)
        self.assertFalse([t for t in pareto if "exact" in t and "full-recompute" in t])

    def test_rows_of_the_paper_lighting_alone_are_named_as_before(self):
        rows = [r for r in rows_of_three_lightings() if r["direct"] == "photons"]
        for r in rows:  # a CSV from before the lighting columns
            for column in ("direct", "gather", "direct_samples"):
                del r[column]
        self.assertEqual({r["lighting"] for r in plots.with_lighting(rows)}, {"photons"})
        self.assertEqual(plots._series_name("detp:clip", "sobol", "photons", ["photons"]), "detp:clip, sobol")

    def test_several_direct_samples_are_spelled_in_the_label(self):
        rows = [{"direct": "exact", "gather": 256.0, "direct_samples": 16.0},
                {"direct": "exact", "gather": 0.0, "direct_samples": 64.0}, {"direct": "photons"}]
        self.assertEqual([r["lighting"] for r in plots.with_lighting(rows)],
                         ["exact 16+gather 256", "exact 64", "photons"])


class CommittedConfigTest(unittest.TestCase):
    def test_sweep_cornell_sweeps_the_lighting_and_quick_restricts_it(self):
        path = os.path.join(REPOSITORY, "configs", "sweep-cornell.json")
        full = {lighting(p) for p in grid.load(path, False).points}
        self.assertEqual(full, {PAPER} | {("exact", g, 64) for g in (0, 64, 256, 1024)})
        self.assertEqual({lighting(p) for p in grid.load(path, True).points},
                         {PAPER, ("exact", 0, 64), ("exact", 256, 64)})

    def test_the_paper_table_keeps_the_published_method(self):
        with open(os.path.join(REPOSITORY, "configs", "paper.json")) as f:
            paper = json.load(f)
        self.assertEqual((paper["direct"], paper["gather"]), ("photons", 0))


if __name__ == "__main__":
    unittest.main()
