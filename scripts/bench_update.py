#!/usr/bin/env python3
"""What a frame after the first costs, incremental against --full-recompute, measured side by side
in one run on each benchmark scene (medians of the frames after the first; the machine's cores).

For every case it renders the same frames twice (incremental, then --full-recompute; PLY only)
and reports from the two timing.json files:
- the median and slowest frame after the first, each way, and their ratio;
- where an incremental frame's time goes (find, retrace, estimator update, disc regions,
  recompute, exact direct light, the gather; writing the PLY apart, outside the frame's time), the
  paths and segments changed, the vertices recomputed, the shadow and gather rays re-cast against
  those a full frame casts;
- the price of the frame's changed work at the full frame's own rates: the added segments at the
  full frame's seconds per segment (tracing plus estimation) and the recomputed vertices at its
  estimation seconds per vertex; overhead = frame time / price - 1;
- peak RSS of each run and the incremental state's bytes (tracked paths, estimator state) per
  tracked segment;
- the frames computed from scratch and why (timing.json's from_scratch_reason).
Writes out/bench/update.json and prints a Markdown table.

Usage: python3 scripts/bench_update.py [--quick] [--only NAME] [--qsgi build/cli/qsgi]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from qsgibatch.qsgi import clear_run  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SCENES = os.path.join(ROOT, "out", "bench", "scenes")


PHOTONS_ONLY = ["--direct", "photons", "--gather", "0"]  # the photon update alone (the paper's method)


def cases(quick):
    cornell = ["data/cornell/cornell.gltf", "--animation", "data/cornell/animation.json"]
    tree = ["data/tree/tree.gltf", "--animation", "data/tree/animation.json"]
    photons = "200000" if quick else "1000000"
    frames = "0:4" if quick else "0:10"
    photon_cases = [
        ("cornell detp clip", cornell + ["--estimator", "detp", "--radius", "0.05", "--photons", photons, "--frames", frames]),
        ("cornell impact count", cornell + ["--estimator", "impact-count", "--photons", photons, "--frames", frames]),
        ("cornell photon map k=50", cornell + ["--estimator", "photon-map", "--k", "50", "--radius", "0.05",
                                               "--photons", photons, "--frames", frames]),
        ("walker (configs/walker.json)", ["--config", "configs/walker.json", "--frames", "0:6" if quick else "0:16"]),
        ("tree detp clip", ["data/tree/tree.gltf", "--animation", "data/tree/animation.json", "--estimator", "detp",
                            "--photons", photons, "--frames", frames]),
        ("tree detp paper", ["data/tree/tree.gltf", "--animation", "data/tree/animation.json", "--estimator", "detp",
                             "--detp-boundary", "paper", "--photons", photons, "--frames", frames]),
        ("sheet morphing all of itself", [os.path.join(SCENES, "sheet", "sheet.gltf"), "--animation", "gltf", "--fps", "4",
                                          "--estimator", "detp", "--photons", "200000" if quick else "500000",
                                          "--frames", "0:8"]),
        ("cornell, block flies, turns, pauses", cornell[:1] + ["--animation", os.path.join(SCENES, "flying-block.json"),
                                                                "--estimator", "detp", "--radius", "0.05",
                                                                "--photons", photons, "--frames", "0:4" if quick else "0:24"]),
        ("sweeping panel (fallback)", [os.path.join(SCENES, "sweeping-panel", "panel.gltf"), "--animation",
                                       os.path.join(SCENES, "sweeping-panel", "animation.json"), "--estimator", "detp",
                                       "--radius", "0.05", "--photons", photons, "--frames", "0:4" if quick else "0:12"]),
    ]
    # The renderer's defaults: exact direct light and the final gather over the photon solution
    # (docs/design.md §5.1), whose update re-casts only the rays a move can change.
    gather_cases = [
        ("cornell impact count, exact direct + gather (defaults)", cornell + ["--photons", photons, "--frames", frames]),
        ("cornell detp clip, exact direct + gather", cornell + ["--estimator", "detp", "--radius", "0.05",
                                                                "--photons", photons, "--frames", frames]),
        ("tree impact count, exact direct + gather (defaults)", tree + ["--photons", photons, "--frames", frames]),
        ("tree detp clip, exact direct + gather", tree + ["--estimator", "detp", "--photons", photons, "--frames", frames]),
    ]
    return [(name, args + PHOTONS_ONLY) for name, args in photon_cases] + gather_cases


def run(qsgi, args, out):
    clear_run(out)
    cmd = ["/usr/bin/time", "-f", "%M", qsgi, "render"] + args + ["--no-exr", "--quiet", "--out", out]
    done = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"bench_update: {' '.join(cmd)} failed:\n{done.stderr}")
    peak_kb = int(done.stderr.strip().splitlines()[-1])
    with open(os.path.join(out, "timing.json")) as f:
        return json.load(f), peak_kb * 1024


def frame_time(f):
    # The second pass's shadow and gather rays (zero under --direct photons) count too.
    return f["photon_update_s"] + f["estimation_s"] + f.get("direct_s", 0) + f.get("gather_s", 0)


def measure(name, args, qsgi):
    slug = name.split(" (")[0].replace(" ", "-").replace(",", "").replace("=", "")
    base = os.path.join(ROOT, "out", "bench", "update", slug)
    inc, inc_rss = run(qsgi, args, base + "-incremental")
    full, full_rss = run(qsgi, args + ["--full-recompute"], base + "-full")
    fi, ff = inc["frames"][1:], full["frames"][1:]
    full_median = statistics.median(frame_time(f) for f in ff)
    # The full frame's own rates, from its median frame.
    mid = sorted(ff, key=frame_time)[len(ff) // 2]
    per_segment = frame_time(mid) / max(mid["segments"], 1)
    per_vertex = mid["estimation_s"] / max(inc["scene"]["vertices"], 1)
    updated = [f for f in fi if not f["from_scratch"]]
    prices = [f["segments_added"] * per_segment + f["vertices_recomputed"] * per_vertex for f in updated]
    overheads = [frame_time(f) / p - 1 for f, p in zip(updated, prices) if p > 0]
    med = lambda key, frames=updated: statistics.median(f[key] for f in frames) if frames else 0
    tracked = [f for f in updated if f["tracked_segments"]]
    state = statistics.median((f["tracked_bytes"] + f["estimator_state_bytes"]) / f["tracked_segments"] for f in tracked) if tracked else 0
    return {
        "case": name, "args": args,
        "incremental_median_s": statistics.median(frame_time(f) for f in fi),
        "incremental_max_s": max(frame_time(f) for f in fi),
        "full_median_s": full_median,
        "full_frame0_s": frame_time(full["frames"][0]), "incremental_frame0_s": frame_time(inc["frames"][0]),
        "ratio": full_median / statistics.median(frame_time(f) for f in fi),
        "from_scratch": {str(f["frame"]): f["from_scratch_reason"] for f in fi if f["from_scratch"]},
        "find_s": med("find_affected_s"), "retrace_s": med("retrace_s"), "update_s": med("estimator_update_s"),
        "regions_s": med("disc_regions_s"), "recompute_s": med("recompute_s"), "write_s": med("write_s", fi),
        "direct_s": med("direct_s"), "gather_s": med("gather_s"), "shadow_rays": med("shadow_rays"),
        "gather_rays": med("gather_rays"), "full_gather_rays": statistics.median(f.get("gather_rays", 0) for f in ff),
        "paths_retraced": med("paths_retraced"), "segments_removed": med("segments_removed"),
        "segments_added": med("segments_added"), "segments": mid["segments"],
        "vertices_recomputed": med("vertices_recomputed"), "vertices_updated": med("vertices_updated"),
        "vertices": inc["scene"]["vertices"],
        "regions_us_per_vertex": 1e6 * med("disc_regions_s") / max(med("disc_regions_updated"), 1),
        "price_s": statistics.median(prices) if prices else 0,
        "overhead": statistics.median(overheads) if overheads else 0,
        "state_bytes_per_tracked_segment": state,
        "peak_rss_incremental": inc_rss, "peak_rss_full": full_rss,
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer photons and frames (a smoke run)")
    parser.add_argument("--only", help="run the cases whose name contains this")
    parser.add_argument("--qsgi", default=os.path.join(ROOT, "build", "cli", "qsgi"))
    a = parser.parse_args()
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "make_bench_scenes.py"), SCENES], check=True)
    results = []
    for name, args in cases(a.quick):
        if a.only and a.only not in name:
            continue
        r = measure(name, args, a.qsgi)
        results.append(r)
        print(f"| {r['case']} | {r['ratio']:.2f}x | {r['incremental_median_s']:.3f} / {r['incremental_max_s']:.3f} s | "
              f"{r['full_median_s']:.3f} s | find {r['find_s']:.3f}, retrace {r['retrace_s']:.3f}, update {r['update_s']:.3f}, "
              f"regions {r['regions_s']:.3f}, recompute {r['recompute_s']:.3f}, direct {r['direct_s']:.3f}, "
              f"gather {r['gather_s']:.3f}, writing {r['write_s']:.3f} apart | "
              f"rays re-cast {r['gather_rays']:.0f}/{r['full_gather_rays']:.0f} gather, {r['shadow_rays']:.0f} shadow | "
              f"{r['paths_retraced']:.0f} paths, {r['segments_added']:.0f}/{r['segments']} segments, "
              f"{r['vertices_recomputed']:.0f}/{r['vertices']} vertices | price {r['price_s']:.3f} s, overhead {100 * r['overhead']:.0f} % | "
              f"{r['state_bytes_per_tracked_segment']:.0f} B/seg, RSS {r['peak_rss_incremental'] / 2**20:.0f}/{r['peak_rss_full'] / 2**20:.0f} MiB | "
              f"scratch {r['from_scratch'] or '-'} |", flush=True)
    os.makedirs(os.path.join(ROOT, "out", "bench"), exist_ok=True)
    with open(os.path.join(ROOT, "out", "bench", "update.json"), "w") as f:
        json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
