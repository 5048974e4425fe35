"""The sweep config (configs/sweep-*.json) and the grid points it names.

A point is one qsgi render: estimator, boundary rule, photons, radius (as a fraction of the
animation's bounding-box diagonal, so one config fits any scale), k, update strategy, frames,
photon sampler and lighting (direct light from the photons or exact, and the final gather).
Three families: `accuracy` (the grid the plots of the trade are drawn from, for every sampler of
grid.samplers and every valid lighting of grid.direct x grid.gather), `full` (the same renders
with --full-recompute at one radius: the second line style of the Pareto plot) and `extreme`
(radius from 1e-6 of the diagonal to all of it, photons from 1 up: stability); those two use the
first sampler of the list only, and the paper's lighting (direct light from the photons, no
gather) whatever the grid's.

The `grid` keys: photons, radius_fraction, k (photon map; default [50]), estimators,
full_recompute_radius_fraction (default 0.015), samplers: a list of "random", "sobol" (qsgi's
default number of Sobol bounces: no --qmc-bounces) or "sobol:K" (--qmc-bounces K, 0..32); default
["sobol"], qsgi's default sampler; direct: a list of "photons" (the paper's method: all light from
the photons) and "exact" (shadow rays from each vertex), default ["photons"]; gather: a list of
final-gather ray counts per vertex, 0 for none, default [0]; direct_samples: shadow rays per vertex
under exact direct light, an integer or a list of them, default 64. A gather needs exact direct
light (qsgi exits 2 on --gather M > 0 with --direct photons): such pairs of direct x gather are left
out of the grid, and a grid with none left is a ConfigError.

Every point passes --direct and --gather (and --direct-samples under exact) explicitly, whatever
they are: a point means the same render whatever qsgi's defaults are. Names spell the lighting only
when it is not the paper's (photons, gather 0), so folders of sweeps from before keep their
names."""
import dataclasses
import json
import math
import os
import re

ESTIMATORS = ("impact-count", "photon-map", "photon-map:paper", "detp", "detp:clip", "detp:linear", "detp:paper")
DEFAULT_K = 50
DEFAULT_RADIUS_FRACTION = 0.015  # qsgi's default radius (render_settings.cpp: defaultRadius)
KNOWN_KEYS = {"scene", "animation", "reference", "surface_reference", "frames", "seeds", "grid", "extremes", "quick",
              "reference_build", "jobs"}
GRID_KEYS = {"photons", "radius_fraction", "k", "estimators", "full_recompute_radius_fraction", "samplers",
             "direct", "gather", "direct_samples"}
DEFAULT_SAMPLER = "sobol"  # qsgi's default sampler, at its default --qmc-bounces
MAX_QMC_BOUNCES = 32       # qsgi render --qmc-bounces: 0..32 (and at most max_bounces, 32 by default)
DIRECT_LIGHTING = ("photons", "exact")  # qsgi render --direct
# The sweep's lighting where a config names none: the paper's method, whatever qsgi's default is
# (points made before the lighting axes rendered it; their names and results stay valid).
DEFAULT_DIRECT = "photons"
DEFAULT_GATHER = 0
DEFAULT_DIRECT_SAMPLES = 64   # the sweep's, passed explicitly (not qsgi's default)
MAX_DIRECT_SAMPLES = 1 << 16  # qsgi render --direct-samples: 1..65536
MAX_GATHER = 1 << 16          # qsgi render --gather: 0..65536
EXTREME_KEYS = {"radius_fraction", "radius_photons", "photons", "estimators"}
REFERENCE_KEYS = {"photons", "seeds", "radius_fraction"}


def lighting_label(direct: str, gather: int, direct_samples=None) -> str:
    """The lighting as the plots name it: "photons", "exact", "exact+gather 256"; with
    direct_samples (where a sweep has several), "exact 64+gather 256"."""
    if direct != "exact":
        return direct
    label = "exact" if direct_samples is None else f"exact {direct_samples:g}"
    return label + (f"+gather {gather:g}" if gather else "")


class ConfigError(Exception):
    """A sweep config that cannot be run: the message names the file, the key and the problem."""


@dataclasses.dataclass(frozen=True)
class Point:
    family: str           # accuracy | full | extreme
    estimator: str        # impact-count | photon-map | detp
    boundary: str         # clip | linear | paper ("" for impact-count)
    photons: int
    radius_fraction: float  # of the animation's diagonal (0 for impact-count: it has no radius)
    k: int                # photon map only (0 otherwise)
    full_recompute: bool
    frames: str           # "A:B"
    sampler: str = DEFAULT_SAMPLER  # random | sobol (qsgi's default K) | sobol:K
    direct: str = DEFAULT_DIRECT    # photons | exact
    gather: int = DEFAULT_GATHER    # final-gather rays per vertex (exact only; 0 = none)
    direct_samples: int = 0         # shadow rays per vertex (exact only; 0 under photons: not passed)

    @property
    def label(self) -> str:
        """Estimator and rule as users write them: `detp:clip`, `photon-map:paper`."""
        if not self.boundary or self.estimator == "photon-map" and self.boundary == "clip":
            return self.estimator
        return f"{self.estimator}:{self.boundary}"

    @property
    def name(self) -> str:
        """A folder name that spells the parameters (resumption finds a point's results by it)."""
        parts = [self.label.replace(":", "-"), f"n{self.photons}"]
        if self.radius_fraction:
            parts.append(f"r{self.radius_fraction:g}")
        if self.k:
            parts.append(f"k{self.k}")
        parts.append("f" + self.frames.replace(":", "-"))
        if self.full_recompute:
            parts.append("full")
        if self.sampler != DEFAULT_SAMPLER:  # the default's names are those points had before samplers
            parts.append(self.sampler.replace(":", "-"))
        if self.direct != DEFAULT_DIRECT or self.gather != DEFAULT_GATHER:  # likewise before the lighting
            parts.append(f"{self.direct}-s{self.direct_samples}" if self.direct == "exact" else self.direct)
            if self.gather:
                parts.append(f"g{self.gather}")
        return "_".join(parts)

    def qsgi_options(self, diagonal: float) -> list:
        options = ["--estimator", self.estimator, "--photons", str(self.photons), "--frames", self.frames]
        if self.boundary:
            options += ["--detp-boundary", self.boundary]
        if self.radius_fraction:
            options += ["--radius", repr(self.radius_fraction * diagonal)]
        if self.k:
            options += ["--k", str(self.k)]
        if self.full_recompute:
            options.append("--full-recompute")
        sampler, _, bounces = self.sampler.partition(":")
        options += ["--sampler", sampler]
        if bounces:
            options += ["--qmc-bounces", bounces]
        # Always explicit, the paper's lighting too: qsgi's defaults may change, a point may not.
        options += ["--direct", self.direct, "--gather", str(self.gather)]
        if self.direct == "exact":
            options += ["--direct-samples", str(self.direct_samples)]
        return options


@dataclasses.dataclass
class SweepConfig:
    path: str
    scene: str
    animation: str
    reference: str          # a committed reference PLY (frame 0), or "" to build one
    frames: str
    seeds: tuple            # (the rendered seed, the second seed for the noise figure)
    reference_build: dict   # photons, seeds, radius_fraction of the built reference
    points: list
    jobs: int
    # A surface reference of frame 0 (scripts/reference.py --surface N), or "": each point is also
    # scored where the eye looks, its irradiance interpolated at the reference's points (issue 47).
    surface_reference: str = ""


def _fail(path, where, problem):
    raise ConfigError(f"{path}: {where}: {problem}")


def _check_keys(path, where, table, known):
    if not isinstance(table, dict):
        _fail(path, where, "must be an object")
    for key in table:
        if key not in known and not key.startswith("_"):
            _fail(path, where or key, f"unknown key '{key}' (known: {', '.join(sorted(known))})")


def _count(path, where, value, low=1, high=2 ** 32):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or value != math.floor(value) \
            or not low <= value <= high:
        _fail(path, where, f"must be an integer in {low}..{high}, not {json.dumps(value)}")
    return int(value)


def _fraction(path, where, value):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value <= 1:
        _fail(path, where, f"must be a fraction of the scene diagonal in (0, 1], not {json.dumps(value)}")
    return float(value)


def _list(path, where, value, item):
    if not isinstance(value, list) or not value:
        _fail(path, where, "must be a non-empty list")
    return [item(path, f"{where}[{i}]", v) for i, v in enumerate(value)]


def _estimator(path, where, value):
    if value not in ESTIMATORS:
        _fail(path, where, f"unknown estimator {json.dumps(value)} (known: {', '.join(ESTIMATORS)})")
    name, _, rule = value.partition(":")
    return name, ("" if name == "impact-count" else rule or "clip")


def _sampler(path, where, value):
    match = re.fullmatch(r"(random|sobol)(?::([0-9]+))?", value) if isinstance(value, str) else None
    if not match or match.group(1) == "random" and match.group(2) is not None:
        _fail(path, where, f"unknown sampler {json.dumps(value)} (known: \"random\", \"sobol\", "
                           f"\"sobol:K\" with K in 0..{MAX_QMC_BOUNCES})")
    if match.group(2) is None:
        return match.group(1)
    bounces = int(match.group(2))
    if bounces > MAX_QMC_BOUNCES:
        _fail(path, where, f"\"sobol:K\" needs K in 0..{MAX_QMC_BOUNCES}, not {json.dumps(value)}")
    return f"sobol:{bounces}"


def _direct(path, where, value):
    if value not in DIRECT_LIGHTING:
        _fail(path, where, f"unknown direct lighting {json.dumps(value)} (known: \"photons\", \"exact\")")
    return value


def _lightings(path, grid):
    """The grid's (direct, gather, direct_samples) triples in the config's order: direct x gather
    (x direct_samples under exact), less the pairs qsgi refuses (a gather under direct light from
    the photons: skipped, not an error, unless no pair is left); direct_samples 0 under photons."""
    directs = list(dict.fromkeys(_list(path, "grid.direct", grid.get("direct", [DEFAULT_DIRECT]), _direct)))
    gathers = list(dict.fromkeys(_list(path, "grid.gather", grid.get("gather", [DEFAULT_GATHER]),
                                       lambda p, w, v: _count(p, w, v, 0, MAX_GATHER))))
    samples = grid.get("direct_samples", DEFAULT_DIRECT_SAMPLES)

    def one_count(p, w, v):
        return _count(p, w, v, 1, MAX_DIRECT_SAMPLES)

    samples = list(dict.fromkeys(_list(path, "grid.direct_samples", samples, one_count) if isinstance(samples, list)
                                 else [one_count(path, "grid.direct_samples", samples)]))
    lightings = [(d, g, s) for d in directs for g in gathers for s in (samples if d == "exact" else [0])
                 if d == "exact" or g == 0]
    if not lightings:
        _fail(path, "grid.gather", f"no valid lighting in grid.direct {json.dumps(directs)} x grid.gather "
                                   f"{json.dumps(gathers)}: a gather > 0 needs direct \"exact\" (qsgi render "
                                   "--gather M needs --direct exact); add \"exact\" to grid.direct or 0 to "
                                   "grid.gather")
    return lightings


def _frames(path, where, value):
    try:
        a, b = (int(x) for x in str(value).split(":"))
    except ValueError:
        _fail(path, where, f"must be \"A:B\", not {json.dumps(value)}")
    if not 0 <= a <= b:
        _fail(path, where, f"must be \"A:B\" with 0 <= A <= B, not {json.dumps(value)}")
    return f"{a}:{b}"


def _merge(base: dict, override: dict) -> dict:
    merged = dict(base)
    for key, value in override.items():
        merged[key] = _merge(base.get(key, {}), value) if isinstance(value, dict) else value
    return merged


def _grid_points(path, grid, frames):
    _check_keys(path, "grid", grid, GRID_KEYS)
    photons = _list(path, "grid.photons", grid.get("photons"), _count)
    radii = _list(path, "grid.radius_fraction", grid.get("radius_fraction"), _fraction)
    ks = _list(path, "grid.k", grid.get("k", [DEFAULT_K]), lambda p, w, v: _count(p, w, v, 1, 2 ** 24))
    estimators = _list(path, "grid.estimators", grid.get("estimators"), _estimator)
    full_radius = _fraction(path, "grid.full_recompute_radius_fraction",
                            grid.get("full_recompute_radius_fraction", DEFAULT_RADIUS_FRACTION))
    samplers = list(dict.fromkeys(_list(path, "grid.samplers", grid.get("samplers", [DEFAULT_SAMPLER]), _sampler)))
    lightings = _lightings(path, grid)
    first = samplers[0]  # the full and extreme families' sampler (and the paper's lighting: Point's default)
    points = []
    for name, rule in estimators:
        for n in photons:
            if name == "impact-count":
                points += [Point("accuracy", name, rule, n, 0.0, 0, False, frames, s, *lighting)
                           for s in samplers for lighting in lightings]
                points.append(Point("full", name, rule, n, 0.0, 0, True, frames, first))
                continue
            for s in samplers:
                for lighting in lightings:
                    for r in radii:
                        for k in (ks if name == "photon-map" else [0]):
                            points.append(Point("accuracy", name, rule, n, r, k, False, frames, s, *lighting))
            k = DEFAULT_K if name == "photon-map" else 0
            points.append(Point("full", name, rule, n, full_radius, k, True, frames, first))
    return points, first


def _extreme_points(path, extremes, sampler):
    _check_keys(path, "extremes", extremes, EXTREME_KEYS)
    radii = _list(path, "extremes.radius_fraction", extremes.get("radius_fraction"), _fraction)
    radius_photons = _count(path, "extremes.radius_photons", extremes.get("radius_photons", 100000))
    if radius_photons > 100000:
        _fail(path, "extremes.radius_photons", "at most 1e5: a disc the size of the scene costs hours at 1e7")
    photons = _list(path, "extremes.photons", extremes.get("photons"), _count)
    estimators = _list(path, "extremes.estimators", extremes.get("estimators"), _estimator)
    points = []
    for name, rule in estimators:
        k = DEFAULT_K if name == "photon-map" else 0
        if name != "impact-count":
            points += [Point("extreme", name, rule, radius_photons, r, k, False, "0:0", sampler) for r in radii]
        points += [Point("extreme", name, rule, n, DEFAULT_RADIUS_FRACTION if name != "impact-count" else 0.0,
                         k, False, "0:0", sampler) for n in photons]
    return points


def load(path: str, quick: bool) -> SweepConfig:
    try:
        with open(path) as f:
            raw = json.load(f)
    except OSError as e:
        raise ConfigError(f"{path}: cannot read ({e.strerror})")
    except json.JSONDecodeError as e:
        raise ConfigError(f"{path}: line {e.lineno}: {e.msg}")
    _check_keys(path, "", raw, KNOWN_KEYS)
    if quick:
        if "quick" not in raw:
            _fail(path, "quick", "--quick needs a \"quick\" section (overrides of grid, extremes, frames)")
        raw = _merge(raw, raw["quick"])
    here = os.path.dirname(os.path.abspath(path))

    def input_file(key, required):
        if key not in raw:
            if required:
                _fail(path, key, "missing")
            return ""
        resolved = os.path.normpath(os.path.join(here, raw[key]))
        if not os.path.isfile(resolved):
            _fail(path, key, f"no such file: {resolved}")
        return resolved

    frames = _frames(path, "frames", raw.get("frames", "0:5"))
    seeds = _list(path, "seeds", raw.get("seeds", [1, 2]), lambda p, w, v: _count(p, w, v, 0, 2 ** 63))
    if len(seeds) != 2 or seeds[0] == seeds[1]:
        _fail(path, "seeds", "must be two different seeds: the render's, and the second one for the noise figure")
    reference_build = raw.get("reference_build", {})
    _check_keys(path, "reference_build", reference_build, REFERENCE_KEYS)
    grid = raw.get("grid") or _fail(path, "grid", "missing")
    points, first_sampler = _grid_points(path, grid, frames)
    if "extremes" in raw:
        points += _extreme_points(path, raw["extremes"], first_sampler)
    unique = list(dict.fromkeys(points))
    smallest = min(p.radius_fraction for p in points if p.family == "accuracy" and p.radius_fraction) \
        if any(p.radius_fraction for p in points if p.family == "accuracy") else DEFAULT_RADIUS_FRACTION
    build = {"photons": _count(path, "reference_build.photons", reference_build.get("photons", 4000000)),
             "seeds": _list(path, "reference_build.seeds", reference_build.get("seeds", [1001, 1002, 1003, 1004]),
                            lambda p, w, v: _count(p, w, v, 0, 2 ** 63)),
             "radius_fraction": _fraction(path, "reference_build.radius_fraction",
                                          reference_build.get("radius_fraction", smallest))}
    return SweepConfig(path=os.path.abspath(path), scene=input_file("scene", True),
                       animation=input_file("animation", False), reference=input_file("reference", False),
                       frames=frames, seeds=tuple(seeds), reference_build=build, points=unique,
                       jobs=_count(path, "jobs", raw.get("jobs", 1), 1, 256),
                       surface_reference=input_file("surface_reference", False))
