"""Runs grid points: each renders into OUT/points/NAME/ and leaves result.json, the point's row of
sweep.csv. A point whose result.json exists is not recomputed, and a killed point's renders resume
where they stopped (qsgi render --resume), so a sweep can be interrupted and run again at will.

Points run `jobs` at a time, each render with cores/jobs threads. A point's timings are marked
`shared_cores` when another point ran during any part of it, or when processes outside the sweep
kept more than a quarter of a core busy on average while it ran (`other_cores`, from /proc/stat):
those numbers are not a quiet machine's, and the CSV says so.

Nothing here writes through a link planted in OUT (scripts/qsgibatch/output_folder.py): OUT/points
and each point's folder are real folders opened without following links (a link or file planted
there is refused, FolderError), result.json is written by output_folder.write_file (a link at the
name or its temporary is replaced, never followed), and a point's run/ and seed2/ are refused when a
link stands there, before qsgi renders into them or a stale one is removed."""
import concurrent.futures
import errno
import glob
import json
import math
import os
import shutil
import stat
import statistics
import threading
import time

import numpy as np

from . import ply
from .grid import DEFAULT_RADIUS_FRACTION
from .output_folder import open_folder, open_subfolder, write_file

RESULT_VERSION = 3  # 2: points have a sampler (results of 1 came from qsgi before Sobol: random photons);
# 3: the surface figures (a result of 2 has none, whether or not the config names a surface reference)


class Occupancy:
    """Which points are running when: enough to tell, when a point ends, whether any other point
    overlapped it (every point that did has started by then)."""

    def __init__(self):
        self._lock = threading.Lock()
        self._spans = {}  # name -> [start, end or None]

    def start(self, name):
        with self._lock:
            self._spans[name] = [time.monotonic(), None]

    def finish(self, name) -> bool:
        with self._lock:
            start = self._spans[name][0]
            end = self._spans[name][1] = time.monotonic()
            return any(other != name and s < end and (e is None or e > start)
                       for other, (s, e) in self._spans.items())


# Average cores busy outside the sweep above which a point's timings count as shared.
OTHER_CORES_SHARED = 0.25


def _busy_cpu_seconds():
    """CPU seconds the whole machine has spent busy since boot (Linux /proc/stat), or None."""
    try:
        with open("/proc/stat") as f:
            fields = [int(x) for x in f.readline().split()[1:]]
    except (OSError, ValueError):
        return None
    idle = fields[3] + (fields[4] if len(fields) > 4 else 0)  # idle + iowait
    return (sum(fields[:8]) - idle) / os.sysconf("SC_CLK_TCK")  # guest time is already in user


def _own_cpu_seconds():
    """CPU seconds of this process and its finished children (the renders)."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


class MachineLoad:
    """How busy the machine was outside the sweep over a span: (busy CPU time of the machine − this
    process's and its renders') / wall time, in cores. Other points' renders count as the sweep's
    own, so with jobs > 1 only outside load shows here (overlap is Occupancy's business)."""

    def __init__(self):
        self._start = (time.monotonic(), _busy_cpu_seconds(), _own_cpu_seconds())

    def other_cores(self) -> float:
        wall0, busy0, own0 = self._start
        busy1 = _busy_cpu_seconds()
        wall = time.monotonic() - wall0
        if busy0 is None or busy1 is None or wall <= 0:
            return math.nan
        return max(0.0, ((busy1 - busy0) - (_own_cpu_seconds() - own0)) / wall)


def _second_pass_s(frame: dict) -> float:
    """The frame's exact direct light and final gather (--direct exact; 0 under photons, and absent
    from the timing.json of a qsgi before them), which qsgi times apart from the estimation."""
    return frame.get("direct_s", 0.0) + frame.get("gather_s", 0.0)


def _frame_seconds(timing: dict) -> dict:
    """A frame's time is the photon update + the density estimation + the second pass (exact
    direct light and the gather): the whole solution of the frame, whatever its lighting."""
    frames = timing["frames"]
    first, later = frames[0], frames[1:]
    per_frame = [f["photon_update_s"] + f["estimation_s"] + _second_pass_s(f) for f in later]

    def median(key):
        return statistics.median(f.get(key, 0.0) for f in later) if later else math.nan

    return {
        "initial_s": first["photon_update_s"] + first["estimation_s"] + _second_pass_s(first),
        "initial_photon_s": first["photon_update_s"],
        "initial_estimation_s": first["estimation_s"],
        "initial_direct_s": first.get("direct_s", 0.0),
        "initial_gather_s": first.get("gather_s", 0.0),
        "median_frame_s": statistics.median(per_frame) if per_frame else math.nan,
        "median_photon_update_s": median("photon_update_s"),
        "median_estimation_s": median("estimation_s"),
        "median_direct_s": median("direct_s"),
        "median_gather_s": median("gather_s"),
        "segments": first["segments"],
        "photons_missing_scene": first["photons_missing_scene"],
        "tracked_bytes_per_segment": (later[-1]["tracked_bytes"] / later[-1]["tracked_segments"]
                                      if later and later[-1]["tracked_segments"] else math.nan),
    }


def _noise(a: str, b: str, reference: np.ndarray) -> float:
    """The spread between two seeds: RMS of their difference / √2 (one render's standard deviation),
    over the reference's mean, the normalisation of `qsgi compare`'s relative RMS."""
    difference = ply.read(a).radiosity() - ply.read(b).radiosity()
    mean = float(np.mean(reference))
    rms = float(np.sqrt(np.mean(difference ** 2) / 2))
    return rms / mean if mean > 0 else rms


def open_point_folder(out, name) -> int:
    """OUT/points/NAME, each made if missing, opened without following a link: a link or file
    planted at either is refused (output_folder.FolderError). Returns the folder's fd."""
    out_fd = open_folder(out)
    try:
        points_fd = open_subfolder(out_fd, "points", os.path.join(out, "points"), create=True)
    finally:
        os.close(out_fd)
    try:
        return open_subfolder(points_fd, name, os.path.join(out, "points", name), create=True)
    finally:
        os.close(points_fd)


def _other_lighting(config: dict, point) -> bool:
    """Whether a run's timing.json config had another lighting than the point's, or none: a qsgi
    before the lighting options, whose folders `--resume` refuses (a fingerprinted option added
    changes every earlier run's fingerprint)."""
    if config.get("direct") != point.direct:
        return True
    return point.direct == "exact" and (config.get("gather") != point.gather or
                                        config.get("direct_samples") != point.direct_samples)


def _discard_other_sampler(point_fd, name, where, point):
    """Removes the render folder `name` of the point's folder when another sampler or lighting (or
    qsgi before samplers or lightings: no "sampler" or "direct" in its timing.json) left it, which
    `qsgi render --resume` would refuse as rendered from other settings. A link or file standing at
    `name` (`where`, its path) is refused (FolderError) rather than followed, by qsgi's render or by
    the removal; the removal (relative to the point's folder, fd-based) follows no link inside it."""
    run_fd = open_subfolder(point_fd, name, where, create=False)
    if run_fd is None:
        return
    try:
        # O_NONBLOCK: a FIFO planted at the name must not hang the open.
        fd = os.open("timing.json", os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC, dir_fd=run_fd)
        with os.fdopen(fd) as f:
            config = json.load(f)["config"]
    except (OSError, ValueError, KeyError, TypeError):
        return  # nothing rendered yet, or nothing to judge by: qsgi decides
    finally:
        os.close(run_fd)
    sampler, _, bounces = point.sampler.partition(":")
    if config.get("sampler") != sampler or bounces and config.get("qmc_bounces") != int(bounces) or \
            _other_lighting(config, point):
        shutil.rmtree(name, dir_fd=point_fd)  # refuses a link at `name`, follows none inside (Linux)


def _lighting_columns(point) -> dict:
    return {"direct": point.direct, "gather": point.gather,
            "direct_samples": point.direct_samples if point.direct == "exact" else math.nan}


def _same_lighting(result: dict, point) -> bool:
    """Whether a result.json was rendered with the point's lighting. Results from before the
    lighting columns name none: their light was the photons' alone (the name says so too)."""
    if result.get("direct", "photons") != point.direct or result.get("gather", 0) != point.gather:
        return False
    return point.direct != "exact" or result.get("direct_samples") == point.direct_samples


def finished(out, point):
    """The point's result.json if there is one of this result version and the point's sampler and
    lighting, else None (whatever its reference: Sweep.cached checks that too). A link or other
    non-file planted at the name is no result (computing the point replaces it)."""
    path = os.path.join(out, "points", point.name, "result.json")
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | os.O_CLOEXEC)
    except OSError as e:
        if e.errno in (errno.ENOENT, errno.ENOTDIR, errno.ELOOP):
            return None
        raise
    with os.fdopen(fd) as f:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        result = json.load(f)
    same = result.get("result_version") == RESULT_VERSION and result.get("sampler") == point.sampler \
        and _same_lighting(result, point)
    return result if same else None


class Sweep:
    def __init__(self, config, qsgi, out, diagonal, reference_path, reference_description, jobs, cores):
        self.config, self.qsgi, self.out, self.diagonal = config, qsgi, out, diagonal
        self.reference_path, self.reference_description = reference_path, reference_description
        self.reference_radiosity = ply.read(reference_path).radiosity()
        self.jobs, self.threads = jobs, max(1, cores // jobs)
        self.occupancy = Occupancy()
        self.computed = 0  # points computed by this invocation (the others were found finished)
        self._computed_lock = threading.Lock()

    def folder(self, point):
        return os.path.join(self.out, "points", point.name)

    def cached(self, point):
        """The point's result if it was computed with this reference and this qsgi, else None."""
        result = finished(self.out, point)
        return result if result is not None and result.get("reference") == self.reference_description else None

    def run(self, point) -> dict:
        result = self.cached(point)
        if result is not None:
            result.update(_lighting_columns(point))  # a result from before the columns: its point's (photons)
            return result
        self.occupancy.start(point.name)
        load = MachineLoad()
        began = time.monotonic()
        try:
            result = self._compute(point)
        finally:
            overlapped = self.occupancy.finish(point.name)
        other = load.other_cores()
        result.update(shared_cores=overlapped or other > OTHER_CORES_SHARED, other_cores=other,
                      wall_s=time.monotonic() - began, **_lighting_columns(point))
        with self._computed_lock:
            self.computed += 1
        folder_fd = open_point_folder(self.out, point.name)
        try:
            write_file(folder_fd, "result.json", json.dumps(result, indent=1, sort_keys=True).encode())
        finally:
            os.close(folder_fd)
        return result

    def _compute(self, point) -> dict:
        folder = self.folder(point)
        run = os.path.join(folder, "run")
        seed, second_seed = self.config.seeds
        folder_fd = open_point_folder(self.out, point.name)  # real folders before qsgi renders into them
        try:
            for name in ("run", "seed2"):
                _discard_other_sampler(folder_fd, name, os.path.join(folder, name), point)
        finally:
            os.close(folder_fd)
        timing = self.qsgi.render(run, point.qsgi_options(self.diagonal), seed, self.threads)
        radius = (point.radius_fraction or DEFAULT_RADIUS_FRACTION) * self.diagonal
        frame0 = os.path.join(run, "frame_0000.ply")
        errors = self.qsgi.compare(frame0, self.reference_path, radius)
        plys = sorted(glob.glob(os.path.join(run, "frame_*.ply")))
        noise = math.nan
        if point.family != "full":  # --full-recompute writes the same bytes: its noise is the accuracy row's
            second = os.path.join(folder, "seed2")
            options = point.qsgi_options(self.diagonal)
            options[options.index("--frames") + 1] = "0:0"
            self.qsgi.render(second, options, second_seed, self.threads)
            noise = _noise(frame0, os.path.join(second, "frame_0000.ply"), self.reference_radiosity)
            plys.append(os.path.join(second, "frame_0000.ply"))
        nan = inf = 0
        for path in plys:
            n, i = ply.count_non_finite(path)
            nan, inf = nan + n, inf + i
        bounces = timing["config"].get("qmc_bounces")  # qsgi's K (its default for plain "sobol"); null: random
        result = {"result_version": RESULT_VERSION, "family": point.family, "estimator": point.label,
                  "sampler": point.sampler, "qmc_bounces": math.nan if bounces is None else bounces,
                  **_lighting_columns(point),
                  "photons": point.photons, "radius_fraction": point.radius_fraction,
                  "radius": point.radius_fraction * self.diagonal if point.radius_fraction else math.nan,
                  "k": point.k or math.nan, "full_recompute": point.full_recompute, "frames": point.frames,
                  "seed": seed, "noise_seed": second_seed if point.family != "full" else math.nan,
                  "threads": self.threads, "jobs": self.jobs, "reference": self.reference_description,
                  "qsgi_version": timing["version"], "noise": noise, "nan_count": nan, "inf_count": inf,
                  "edge_radius": radius}
        for region in ("all", "edge", "near_edge", "interior"):
            result[f"rms_{region}"] = errors[region]["relative_rms"]
            result[f"bias_{region}"] = errors[region]["relative_bias"]
            result[f"vertices_{region}"] = errors[region]["vertices"]
        if self.config.surface_reference:
            # Where the eye looks: frame 0's irradiance interpolated at the surface reference's points.
            surface = self.qsgi.compare(frame0, self.config.surface_reference, radius)
            def figure(value):  # an empty band has none (null), not 0
                return math.nan if value is None else value
            for band in ("all", "contact", "edge", "interior"):
                result[f"surface_rms_{band}"] = figure(surface[band]["relative_rms"])
                result[f"surface_points_{band}"] = surface[band]["points"]
            result["surface_rms_all_without_noise"] = figure(surface["all"]["relative_rms_without_noise"])
            result["surface_reference_noise"] = figure(surface["all"]["reference_noise"])
        result.update(_frame_seconds(timing))
        return result

    def run_all(self, points, progress) -> list:
        """Runs every point (cached ones return at once), `jobs` at a time, in grid order."""
        results = [None] * len(points)
        with concurrent.futures.ThreadPoolExecutor(max_workers=self.jobs) as pool:
            futures = {pool.submit(self.run, p): i for i, p in enumerate(points)}
            try:
                for done, future in enumerate(concurrent.futures.as_completed(futures), 1):
                    i = futures[future]
                    results[i] = future.result()
                    progress(done, len(points), points[i], results[i])
            except BaseException:
                pool.shutdown(wait=True, cancel_futures=True)  # finished points keep their result.json
                raise
        return results
