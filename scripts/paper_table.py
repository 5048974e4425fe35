#!/usr/bin/env python3
"""Prints our version of the paper's timing table (../shared/seed/paper-slides.txt) for a config
(default configs/paper.json: data/tree, 10^4 photons, r = 0.1, DETP).

It renders the config's animation in the paper's three configurations — no ray cache; ray cache
without sorted queries; ray cache with sorted queries — plus --full-recompute, each with the
paper's DETP rule (--detp-boundary paper, like for like) and with the default rule (clip), and
reads every run's timing.json: photon simulation initial / median per frame, density estimation
initial / median per frame, and frames per second of the update (1 / median(photon_update_s +
estimation_s)). Rendering and writing are not part of a frame (docs/design.md §7).

Usage: python3 scripts/paper_table.py [--config CONFIG] [--qsgi BUILD/cli/qsgi] [--frames A:B]
                                      [--photons N] [--out DIR] [--json FILE]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from qsgibatch.qsgi import clear_run  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

CONFIGURATIONS = [
    ("No ray cache", ["--no-ray-cache"]),
    ("Ray cache, unsorted queries", ["--no-sort-queries"]),
    ("Ray cache, sorted queries", []),
    ("Full recomputation (sorted)", ["--full-recompute"]),
]
RULES = [("paper", ["--detp-boundary", "paper"]), ("clip (default)", ["--detp-boundary", "clip"])]


def run(qsgi, config, extra, out):
    clear_run(out)
    cmd = [qsgi, "render", "--config", config, "--out", out, "--no-exr", "--quiet"] + extra
    subprocess.run(cmd, check=True)
    with open(os.path.join(out, "timing.json")) as f:
        return json.load(f)


def summarise(timing):
    frames = timing["frames"][1:]
    median = lambda key: statistics.median(f[key] for f in frames) if frames else float("nan")
    frame = statistics.median(f["photon_update_s"] + f["estimation_s"] for f in frames) if frames else float("nan")
    return {
        "photon_initial_s": timing["frames"][0]["photon_update_s"],
        "photon_frame_s": median("photon_update_s"),
        "estimation_initial_s": timing["frames"][0]["estimation_s"],
        "estimation_frame_s": median("estimation_s"),
        "disc_regions_frame_s": median("disc_regions_s"),
        "frame_s": frame,
        "fps": 1.0 / frame if frame > 0 else float("inf"),
        "paths_retraced": median("paths_retraced"),
        "segments_changed": statistics.median(f["segments_removed"] + f["segments_added"] for f in frames) if frames else 0,
        "frames": len(timing["frames"]),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default=os.path.join(ROOT, "configs", "paper.json"))
    ap.add_argument("--qsgi", default=os.path.join(ROOT, "build", "cli", "qsgi"))
    ap.add_argument("--frames", help="frame range A:B (default: the whole animation)")
    ap.add_argument("--photons", type=int, help="override the config's photon count")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "paper_table"))
    ap.add_argument("--json", help="also write the figures to this file")
    args = ap.parse_args()
    if not os.path.exists(args.qsgi):
        sys.exit(f"paper_table.py: {args.qsgi} not found; build first (scripts/test.sh) or pass --qsgi")
    extra = (["--frames", args.frames] if args.frames else []) + (["--photons", str(args.photons)] if args.photons else [])

    rows = []
    for rule, rule_args in RULES:
        for name, switch in CONFIGURATIONS:
            out = os.path.join(args.out, rule.split()[0] + "_" + name.split()[0].lower() + "_" + str(len(rows)))
            s = summarise(run(args.qsgi, args.config, rule_args + switch + extra, out))
            s.update(rule=rule, configuration=name)
            rows.append(s)

    with open(args.config) as f:
        photons = args.photons or json.load(f).get("photons")
    print(f"qsgi's version of the paper's table — {os.path.relpath(args.config, os.getcwd())}, {photons} photons, "
          f"{rows[0]['frames']} frames; seconds, medians over the frames after the first")
    header = (f"{'DETP rule':<15} {'configuration':<29} {'photons init':>12} {'per frame':>10} "
              f"{'density init':>12} {'per frame':>10} {'frames/s':>9}")
    print(header)
    print("-" * len(header))
    for r in rows:
        print(f"{r['rule']:<15} {r['configuration']:<29} {r['photon_initial_s']:>12.4f} {r['photon_frame_s']:>10.5f} "
              f"{r['estimation_initial_s']:>12.4f} {r['estimation_frame_s']:>10.5f} {r['fps']:>9.1f}")
    print("The paper (2006 hardware, ray cache with sorted queries): photons 0.09 s initial, density estimation "
          "2.56 s initial, 0.11 s per frame.")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
