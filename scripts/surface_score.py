#!/usr/bin/env python3
"""Scores a frame's bake where the eye looks (issue 47): its vertex irradiance interpolated across
each triangle, as a viewer, Blender or an engine shows it, against a surface reference
(scripts/reference.py --surface N) at points spread uniformly by area.

    scripts/surface_score.py FRAME.ply SURFACE_REFERENCE.ply [--json]

The frame must be of the mesh the reference's points were drawn on (its triangles by index: an
unrefined frame of the same scene). Prints, over the points that are not hidden, the relative RMS
error sqrt(mean |E_interp - E_ref|^2) / mean |E_ref| (over points and RGB), the share the
reference's own noise explains (its mean squared standard error), and the error with that noise
taken out. Bands by contact, edge and interior are not scored yet.
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from qsgibatch import ply  # noqa: E402


def score(vertex_values, triangles, points):
    """The interpolated field's error at the points not hidden: a dict of figures."""
    kept = points[points["hidden"] == 0]
    tri = triangles[kept["triangle"]]
    b1, b2 = kept["b1"].astype(np.float64)[:, None], kept["b2"].astype(np.float64)[:, None]
    value = (1 - b1 - b2) * vertex_values[tri[:, 0]] + b1 * vertex_values[tri[:, 1]] + b2 * vertex_values[tri[:, 2]]
    reference = np.stack([kept["irradiance_" + c] for c in "rgb"], 1).astype(np.float64)
    error = np.stack([kept["stderr_" + c] for c in "rgb"], 1).astype(np.float64)
    scale = float(np.mean(np.abs(reference)))
    mse = float(np.mean((value - reference) ** 2))
    noise = float(np.mean(error ** 2))
    return {"points": int(len(kept)), "hidden": int(len(points) - len(kept)),
            "relative_rms": float(np.sqrt(mse)) / scale if scale > 0 else float("nan"),
            "reference_noise": float(np.sqrt(noise)) / scale if scale > 0 else float("nan"),
            "relative_rms_without_noise": float(np.sqrt(max(0.0, mse - noise))) / scale if scale > 0 else float("nan")}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("frame")
    ap.add_argument("reference")
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    try:
        frame = ply.read(args.frame)
        points = ply.read_points(args.reference)
        triangles = frame.triangles()
        values = frame.irradiance()
    except (OSError, ValueError) as e:
        print(f"surface_score: {e}", file=sys.stderr)
        return 2
    if len(points) and (points["triangle"].max() >= len(triangles) or points["triangle"].min() < 0):
        print(f"surface_score: {args.reference} names triangles beyond {args.frame}'s {len(triangles)}: another mesh",
              file=sys.stderr)
        return 2
    result = score(values, triangles, points)
    if args.json:
        print(json.dumps(result))
    else:
        print(f"over the surface ({result['points']} points, {result['hidden']} hidden): relative RMS "
              f"{100 * result['relative_rms']:.2f} %, of which the reference's noise {100 * result['reference_noise']:.2f} %; "
              f"without it {100 * result['relative_rms_without_noise']:.2f} %")
    return 0


if __name__ == "__main__":
    sys.exit(main())
