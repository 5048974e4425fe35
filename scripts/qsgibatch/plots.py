"""The sweep's plots, drawn from sweep.csv alone (so a merge job can draw them from rows that other
machines computed). Every axis names its quantity and unit; errors are relative to the
reference's mean radiosity at frame 0, times are per frame on this machine (the second pass of
exact direct light and the gather included). Rows of different photon samplers (the CSV's
`sampler`) or lightings (`direct`, `gather`, `direct_samples`) are never joined into one line: each
plot draws one series per estimator, sampler and lighting (colour: estimator, darker for each
lighting after the first; line style: sampler; marker: sampler, or lighting where the rows have
several) or one panel each. Series are named "estimator, sampler" and, where the rows have another
lighting than the paper's, ", lighting" ("detp:clip, sobol, exact+gather 256").

Each plot is drawn in memory and written by output_folder.write_file: a link planted at its name or
its temporary is replaced, never written through."""
import io
import math
import os

import matplotlib

matplotlib.use("Agg")  # headless: files only
import matplotlib.colors  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .grid import DEFAULT_RADIUS_FRACTION, lighting_label  # noqa: E402
from .output_folder import open_folder, write_file  # noqa: E402

ERROR_AXIS = "relative RMS error at frame 0"
MIN_PHOTONS_FOR_SLOPE = 1e4  # below, the fixed cost per frame (regions, setup) hides the growth


# Per sampler, in the order the rows name them: (line style, marker). "s" (square) is left to the
# --full-recompute lines.
SAMPLER_STYLES = [("-", "o"), (":", "^"), ("-.", "v"), ((0, (5, 1, 1, 1, 1, 1)), "D"), ((0, (1, 3)), "P")]
# Per lighting, where the rows have several: the marker (the line style stays the sampler's).
LIGHTING_MARKERS = ["o", "^", "v", "D", "P", "X", "*", "h"]


def _estimators(rows):
    return list(dict.fromkeys(r["estimator"] for r in rows))


def _samplers(rows):
    return list(dict.fromkeys(r["sampler"] for r in rows))


def _sampler_styles(samplers):
    return {s: SAMPLER_STYLES[i % len(SAMPLER_STYLES)] for i, s in enumerate(samplers)}


def _number(value, default):
    return default if value is None or isinstance(value, float) and math.isnan(value) else value


def with_lighting(rows):
    """The rows, each with "lighting": its label (grid.lighting_label), its shadow rays spelled
    only where the exact rows have several counts. A row without the lighting columns (a CSV from
    before them) had direct light from the photons."""
    exact = [r for r in rows if r.get("direct") == "exact"]
    several = len({_number(r.get("direct_samples"), 0) for r in exact}) > 1
    return [dict(r, lighting=lighting_label(r["direct"], _number(r.get("gather"), 0),
                                            _number(r.get("direct_samples"), 0) if several else None)
                 if r.get("direct") == "exact" else "photons") for r in rows]


def _lightings(rows):
    return list(dict.fromkeys(_lighting(r) for r in rows))


def _lighting(row):
    return row.get("lighting", "photons")


def _spells_lighting(lightings):
    """Whether series names spell the lighting: not where every row has the paper's."""
    return lightings != ["photons"]


def _series_styles(samplers, lightings):
    """(sampler, lighting) -> (line style, marker): the line style is the sampler's; so is the
    marker where the rows have one lighting, else the marker is the lighting's."""
    styles = {}
    for sampler, (line, marker) in _sampler_styles(samplers).items():
        for j, lighting in enumerate(lightings):
            styles[(sampler, lighting)] = (line, marker if len(lightings) == 1 else
                                           LIGHTING_MARKERS[j % len(LIGHTING_MARKERS)])
    return styles


def _shade(colour, lighting, lightings):
    """The estimator's colour for a lighting: as it is for the first, darker for each after it."""
    if len(lightings) < 2:
        return colour
    factor = 1 - 0.55 * lightings.index(lighting) / (len(lightings) - 1)
    return tuple(factor * c for c in matplotlib.colors.to_rgb(colour))


def _series_name(name, sampler, lighting, lightings):
    return f"{name}, {sampler}" + (f", {lighting}" if _spells_lighting(lightings) else "")


def _legend(axis, **options):
    if axis.get_legend_handles_labels()[0]:
        axis.legend(**options)


def _finite(values):
    return [v for v in values if not math.isnan(v)]


def _save(figure, out, name, title_note):
    figure.suptitle(title_note, fontsize=9)
    figure.tight_layout()
    image = io.BytesIO()
    figure.savefig(image, dpi=110, format=os.path.splitext(name)[1][1:])
    plt.close(figure)
    folder_fd = open_folder(out)
    try:
        write_file(folder_fd, name, image.getvalue())
    finally:
        os.close(folder_fd)
    return name


def _colours(names):
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    return {n: cycle[i % len(cycle)] for i, n in enumerate(names)}


def error_vs_photons(rows, out, note):
    """One panel per estimator (columns) and sampler and lighting (rows)."""
    accuracy = [r for r in rows if r["family"] == "accuracy"]
    estimators, lightings = _estimators(accuracy), _lightings(accuracy)
    kinds = list(dict.fromkeys((r["sampler"], _lighting(r)) for r in accuracy))
    figure, axes = plt.subplots(len(kinds), len(estimators), figsize=(4.2 * len(estimators), 3.8 * len(kinds)),
                                squeeze=False, sharey=True)
    for row, (sampler, lighting) in zip(axes, kinds):
        for axis, name in zip(row, estimators):
            _error_vs_photons_panel(axis, [r for r in accuracy if r["estimator"] == name and r["sampler"] == sampler
                                           and _lighting(r) == lighting],
                                    name, f"{sampler} sampler" + (f", {lighting}" if _spells_lighting(lightings) else ""))
        row[0].set_ylabel(ERROR_AXIS)
    return _save(figure, out, "error_vs_photons.png", note)


def _error_vs_photons_panel(axis, mine, name, kind):
    ks = sorted({r["k"] for r in mine if not math.isnan(r["k"])})
    default_k = 50.0 if 50.0 in ks else (ks[0] if ks else math.nan)
    curves = {}
    for r in mine:
        if not math.isnan(r["k"]) and r["k"] != default_k:
            continue
        curves.setdefault(r["radius_fraction"], []).append(r)
    for fraction, points in sorted(curves.items()):
        points.sort(key=lambda r: r["photons"])
        label = f"r = {100 * fraction:g} % of diagonal" if fraction else "no radius"
        axis.plot([r["photons"] for r in points], [r["rms_all"] for r in points], "o-", label=label, ms=3)
    if len(ks) > 1:  # photon map: k at the middle radius, dashed
        radii = sorted({r["radius_fraction"] for r in mine})
        middle = radii[len(radii) // 2]
        for k in ks:
            if k == default_k:
                continue
            points = sorted((r for r in mine if r["k"] == k and r["radius_fraction"] == middle),
                            key=lambda r: r["photons"])
            axis.plot([r["photons"] for r in points], [r["rms_all"] for r in points], "x--", ms=4,
                      label=f"k = {k:g}, r = {100 * middle:g} %")
    title = f"{name}, {kind}" + (f" (k = {default_k:g})" if ks else "")
    axis.set(xscale="log", yscale="log", xlabel="photons per frame")
    axis.set_title(title, fontsize=None if len(title) <= 36 else 9)  # a lighting spelled: smaller, not overlapping
    axis.grid(True, which="both", alpha=0.3)
    _legend(axis, fontsize=7)


def _pareto_front(points):
    """The points no other point beats in both time and error, by increasing time."""
    front, best = [], math.inf
    for r in sorted(points, key=lambda r: (r["median_frame_s"], r["rms_all"])):
        if r["rms_all"] < best:
            front.append(r)
            best = r["rms_all"]
    return front


def pareto(rows, out, note):
    """A series per estimator, sampler and lighting: the front of its incremental points and its
    --full-recompute line (the full family has the paper's lighting alone)."""
    timed = [r for r in rows if r["family"] in ("accuracy", "full") and not math.isnan(r["median_frame_s"])]
    estimators, samplers, lightings = _estimators(timed), _samplers(timed), _lightings(timed)
    colours, styles = _colours(estimators), _series_styles(samplers, lightings)
    beside = len(samplers) > 1 or len(lightings) > 1
    figure, axis = plt.subplots(figsize=(10.5 if beside else 7.5, 5))
    for name in estimators:
        for sampler in samplers:
            for lighting in lightings:
                line, marker = styles[(sampler, lighting)]
                colour, series = _shade(colours[name], lighting, lightings), _series_name(name, sampler, lighting, lightings)
                mine = [r for r in timed if r["estimator"] == name and r["sampler"] == sampler and _lighting(r) == lighting]
                incremental = [r for r in mine if r["family"] == "accuracy"]
                full = sorted((r for r in mine if r["family"] == "full"), key=lambda r: r["median_frame_s"])
                if incremental:
                    axis.scatter([r["median_frame_s"] for r in incremental], [r["rms_all"] for r in incremental], s=9,
                                 marker=marker, color=colour, alpha=0.35)
                    front = _pareto_front(incremental)
                    axis.plot([r["median_frame_s"] for r in front], [r["rms_all"] for r in front], linestyle=line,
                              marker=marker, ms=3, color=colour, label=f"{series}: incremental (front)")
                if full:
                    axis.plot([r["median_frame_s"] for r in full], [r["rms_all"] for r in full], "--", marker="s", ms=3,
                              color=colour, label=f"{series}: --full-recompute")
    axis.set(xscale="log", yscale="log", xlabel="median time per frame after the first (s)", ylabel=ERROR_AXIS,
             title="The trade: error against time per frame (lower left is better)")
    axis.grid(True, which="both", alpha=0.3)
    if not beside:
        _legend(axis, fontsize=7)
    else:  # a series per estimator, sampler and lighting: beside the plot, not over it, as tall as it needs
        entries = len(axis.get_legend_handles_labels()[0])
        figure.set_size_inches(10.5, max(5.0, 1.0 + 0.13 * entries))
        _legend(axis, fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1),
                title="estimator, sampler" + (", lighting" if _spells_lighting(lightings) else "") + ": kind",
                title_fontsize=7)
    return _save(figure, out, "pareto.png", note)


def fitted_slope(photons, seconds):
    """Least-squares slope of log(time) against log(photons) over the counts where it is growth
    that shows, not the fixed cost; NaN with fewer than two such points."""
    pairs = [(n, t) for n, t in zip(photons, seconds) if n >= MIN_PHOTONS_FOR_SLOPE and t > 0]
    if len(pairs) < 2:
        return math.nan
    x, y = np.log10([p[0] for p in pairs]), np.log10([p[1] for p in pairs])
    return float(np.polyfit(x, y, 1)[0])


def time_vs_photons(rows, out, note):
    """Per estimator: the --full-recompute points and the incremental ones at their radius (k = 50),
    one line per sampler and lighting; the slopes are keyed (estimator, "full|incremental, SAMPLER"),
    with ", LIGHTING" after it where the rows have another lighting than the paper's."""
    full_rows = [r for r in rows if r["family"] == "full"]
    estimators = _estimators(full_rows)
    timed = [r for r in rows if r["family"] in ("full", "accuracy")]
    samplers, lightings = _samplers(timed), _lightings(timed)
    colours, styles = _colours(estimators), _series_styles(samplers, lightings)
    figure, axis = plt.subplots(figsize=(7.5, 5))
    slopes = {}
    for name in estimators:
        fraction = next((r["radius_fraction"] for r in full_rows if r["estimator"] == name), math.nan)
        for sampler in samplers:
            for lighting in lightings:
                line, marker = styles[(sampler, lighting)]
                colour, series = _shade(colours[name], lighting, lightings), _series_name(name, sampler, lighting, lightings)
                full = sorted((r for r in full_rows if r["estimator"] == name and r["sampler"] == sampler
                               and _lighting(r) == lighting), key=lambda r: r["photons"])
                incremental = sorted((r for r in rows if r["family"] == "accuracy" and r["estimator"] == name and
                                      r["sampler"] == sampler and _lighting(r) == lighting and
                                      (r["radius_fraction"] == fraction or (math.isnan(fraction) or not fraction))
                                      and (math.isnan(r["k"]) or r["k"] == 50)), key=lambda r: r["photons"])
                for points, style, kind in ((full, dict(linestyle="--", marker="s"), "full"),
                                            (incremental, dict(linestyle=line, marker=marker), "incremental")):
                    if not points:
                        continue
                    n, t = [r["photons"] for r in points], [r["median_frame_s"] for r in points]
                    slope = fitted_slope(n, t)
                    slopes[(name, f"{kind}, {sampler}" + (f", {lighting}" if _spells_lighting(lightings) else ""))] = slope
                    label = f"{series}: {kind}"
                    axis.plot(n, t, ms=3, color=colour, **style,
                              label=f"{label}, slope {slope:.2f}" if not math.isnan(slope) else label)
    axis.set(xscale="log", yscale="log", xlabel="photons per frame", ylabel="median time per frame (s)",
             title=f"Frame time against photons (slope fitted from {MIN_PHOTONS_FOR_SLOPE:.0e} photons up)")
    axis.grid(True, which="both", alpha=0.3)
    _legend(axis, fontsize=7)
    return _save(figure, out, "time_vs_photons.png", note), slopes


def bias_vs_radius(rows, out, note):
    accuracy = [r for r in rows if r["family"] == "accuracy" and r["radius_fraction"]
                and (math.isnan(r["k"]) or r["k"] == 50)]
    if not accuracy:
        return None
    most = max(r["photons"] for r in accuracy)
    estimators, samplers, lightings = _estimators(accuracy), _samplers(accuracy), _lightings(accuracy)
    colours, styles = _colours(estimators), _series_styles(samplers, lightings)
    figure, axes = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    for axis, region, title in ((axes[0], "near_edge", "within one radius of an edge"),
                                (axes[1], "interior", "interior")):
        for name in estimators:
            for sampler in samplers:
                for lighting in lightings:
                    points = sorted((r for r in accuracy if r["estimator"] == name and r["sampler"] == sampler
                                     and _lighting(r) == lighting and r["photons"] == most),
                                    key=lambda r: r["radius_fraction"])
                    if not points:
                        continue
                    line, marker = styles[(sampler, lighting)]
                    axis.plot([100 * r["radius_fraction"] for r in points], [r[f"bias_{region}"] for r in points],
                              linestyle=line, marker=marker, ms=3, color=_shade(colours[name], lighting, lightings),
                              label=_series_name(name, sampler, lighting, lightings))
        axis.axhline(0, color="black", lw=0.6)
        axis.set(xscale="log", xlabel="radius (% of the scene diagonal)", title=f"{title}, {most:.0e} photons")
        axis.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("relative bias at frame 0 (signed)")
    _legend(axes[0], fontsize=7)
    return _save(figure, out, "bias_vs_radius.png", note)


def extremes(rows, out, note):
    extreme = [r for r in rows if r["family"] == "extreme"]
    if not extreme:
        return None
    bad = int(sum(r["nan_count"] + r["inf_count"] for r in extreme))
    estimators = _estimators(extreme)
    colours = _colours(estimators)
    sampler = ", ".join(_samplers(extreme)) + " sampler"  # one: the grid's first
    figure, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    radius_photons = min((r["photons"] for r in extreme if r["radius_fraction"] != DEFAULT_RADIUS_FRACTION and r["radius_fraction"]),
                         default=math.nan)
    for name in estimators:
        mine = [r for r in extreme if r["estimator"] == name]
        by_radius = sorted((r for r in mine if r["photons"] == radius_photons and r["radius_fraction"]),
                           key=lambda r: r["radius_fraction"])
        x = [r["radius_fraction"] for r in by_radius]
        axes[0].plot(x, [r["rms_all"] for r in by_radius], "o-", ms=3, color=colours[name], label=f"{name}: RMS error")
        axes[0].plot(x, [r["noise"] for r in by_radius], "x:", ms=4, color=colours[name], label=f"{name}: noise")
        axes[0].plot(x, [abs(r["bias_all"]) for r in by_radius], "s--", ms=3, color=colours[name],
                     label=f"{name}: |bias|")
        by_photons = sorted((r for r in mine if r["radius_fraction"] in (DEFAULT_RADIUS_FRACTION, 0.0)), key=lambda r: r["photons"])
        axes[1].plot([r["photons"] for r in by_photons], [r["rms_all"] for r in by_photons], "o-", ms=3,
                     color=colours[name], label=f"{name}: RMS error")
        axes[1].plot([r["photons"] for r in by_photons], [r["noise"] for r in by_photons], "x:", ms=4,
                     color=colours[name], label=f"{name}: noise")
    axes[0].set(xscale="log", yscale="log", xlabel="radius (fraction of the scene diagonal)",
                ylabel="relative error at frame 0",
                title=f"Radius extremes, {radius_photons:.0e} photons, {sampler}\n(no photon in a disc: estimate 0, noise 0, bias -100 %)")
    axes[1].set(xscale="log", yscale="log", xlabel="photons per frame", ylabel=ERROR_AXIS,
                title=f"Photon extremes, default radius (1.5 % of the diagonal)\n{sampler}")
    for axis in axes:
        axis.grid(True, which="both", alpha=0.3)
        _legend(axis, fontsize=6)
    return _save(figure, out, "extremes.png", f"{note}   NaN/Inf values in every PLY: {bad}")


def draw_all(rows, out, note):
    """Draws every plot the rows allow; returns (file names, fitted slopes)."""
    rows = with_lighting(rows)
    names = [error_vs_photons(rows, out, note), pareto(rows, out, note)]
    name, slopes = time_vs_photons(rows, out, note)
    names += [name, bias_vs_radius(rows, out, note), extremes(rows, out, note)]
    return [n for n in names if n], slopes
