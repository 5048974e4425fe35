#!/usr/bin/env python3
"""Scores a qsgi frame of an asset under a uniform sky against scripts/helmet_reference.py (issue 56).

  scripts/helmet_score.py REFERENCE.npz QSGI.ply QSGI_BLACK.ply [--json OUT.json] [--worst N] [--against LABEL=OTHER.ply ...]

REFERENCE.npz: scripts/helmet_reference.py's output for the scene's frame (its vertices, sky shares
s_v, contact flags, meshes, irradiance E_v and standard errors). QSGI.ply: qsgi's frame PLY of the
same scene (its irradiance_r/g/b columns are read). QSGI_BLACK.ply: qsgi's frame of the same scene
with every material black (scripts/make_helmet_ground.py --black), whose irradiance is direct light
D alone. Both PLYs must hold the reference's vertices in its order (checked).

Irradiance is the mean of the three channels (the sky is white; the albedo tints E a little).
Printed:

1. Irradiance against the reference, per group of vertices with E_ref > 0 ("lit") — every lit
   vertex; contact (the ray along +n meets a surface within 1 mm); open (s_v >= 5 %, no contact);
   the rest; dark (s_v = 0 but lit by interreflections); and per mesh: the count, the relative RMS
   sqrt(sum (q - r)^2 / sum r^2), the ratio of the means q/r, the share of all lit vertices'
   squared error the group holds, and the reference's own noise in the same units,
   sqrt(sum sigma^2 / sum r^2) (sigma: each vertex's standard error from its samples' spread), and
   the error split in two over the same sum r^2: "direct", the black scene's D against pi L s_v,
   and "rest", (q - D) against (r - pi L s_v), the interreflections (qsgi's direct light does not
   depend on the albedo, so D is the normal scene's direct light too).
   Vertices the reference leaves dark (E_ref = 0) are listed apart with qsgi's mean there.
2. Direct light against the sky share, per mesh and overall: sum D / sum pi L s_v over the vertices
   with s_v > 0, the mean of the per-vertex ratios D / (pi L s_v) over s_v >= 5 %, and over the dark
   vertices (s_v = 0: none of the reference's sky rays escaped) their count and mean D (W/m^2),
   which should be 0.
3. With --against LABEL=OTHER.ply (repeatable): another qsgi frame whose first vertices are the
   reference's — the scene grown by make_helmet_ground.py --far-plane DIST (its extra vertices
   come last), or the same scene under another --seed — and how far its E moves from QSGI.ply's:
   relative RMS of the difference sqrt(sum (o - q)^2 / sum q^2) and the ratio of the means, over
   every lit vertex and per mesh. Between two seeds that RMS is sqrt(2) x qsgi's own noise.

Standard library and numpy only.
"""
import argparse
import json
import sys

import numpy as np

TYPES = {"float": "<f4", "double": "<f8", "uchar": "u1", "char": "i1", "int": "<i4", "uint": "<u4",
         "short": "<i2", "ushort": "<u2"}


def read_ply_vertices(path):
    """A binary little-endian PLY's vertex records (every property its header lists)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in header:
        sys.exit(f"{path}: not a binary little-endian PLY")
    fields, element, count = [], None, None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            element = words[1]
            if element == "vertex":
                count = int(words[2])
            elif count is None:
                sys.exit(f"{path}: an element before the vertices")
        elif words[:1] == ["property"] and element == "vertex":
            if words[1] == "list":
                sys.exit(f"{path}: a list property on vertices")
            fields.append((words[2], TYPES[words[1]]))
    records = np.frombuffer(data, np.dtype(fields), count, end)
    names = records.dtype.names
    for k in ("irradiance_r", "irradiance_g", "irradiance_b"):
        if k not in names:
            sys.exit(f"{path}: no {k} column (a qsgi frame PLY has one)")
    return records


def irradiance(records):
    return np.stack([records["irradiance_r"], records["irradiance_g"], records["irradiance_b"]], 1).astype(np.float64).mean(1)


def check_same_vertices(records, ref, path):
    p = np.stack([records["x"], records["y"], records["z"]], 1).astype(np.float64)
    if len(p) != len(ref["positions"]):
        sys.exit(f"{path} has {len(p)} vertices, the reference {len(ref['positions'])}")
    off = float(np.abs(p - ref["positions"]).max())
    if off > 1e-6:
        sys.exit(f"{path}: its vertices are not the reference's (off by {off:.3g})")


def group_row(name, mask, q, r, sigma, total_sq, D, pis):
    n = int(mask.sum())
    if n == 0:
        return {"group": name, "vertices": 0}
    d2 = float(np.sum((q[mask] - r[mask]) ** 2))
    r2 = float(np.sum(r[mask] ** 2))
    return {"group": name, "vertices": n,
            "relative_rms": np.sqrt(d2 / r2) if r2 > 0 else float("nan"),
            "ratio_of_means": float(q[mask].mean() / r[mask].mean()) if r[mask].mean() > 0 else float("nan"),
            "error_share": d2 / total_sq if total_sq > 0 else float("nan"),
            "reference_noise": float(np.sqrt(np.sum(sigma[mask] ** 2) / r2)) if r2 > 0 else float("nan"),
            # The error split into direct light (the black scene's D against pi L s_v) and the rest
            # (q - D against r - pi L s_v), each over the same sum r^2: their squares add up to about
            # the total's when the two are uncorrelated.
            "direct_rms": float(np.sqrt(np.sum((D[mask] - pis[mask]) ** 2) / r2)) if r2 > 0 else float("nan"),
            "indirect_rms": float(np.sqrt(np.sum(((q - D)[mask] - (r - pis)[mask]) ** 2) / r2)) if r2 > 0 else float("nan"),
            "mean_reference": float(r[mask].mean()), "mean_qsgi": float(q[mask].mean())}


def direct_row(name, mask, D, pis, s):
    seen = mask & (s > 0)
    open_ = mask & (s >= 0.05)
    dark = mask & (s == 0)
    row = {"group": name, "vertices_with_sky": int(seen.sum()), "dark_vertices": int(dark.sum())}
    row["sum_ratio"] = float(D[seen].sum() / pis[seen].sum()) if seen.any() else float("nan")
    row["mean_ratio_open"] = float(np.mean(D[open_] / pis[open_])) if open_.any() else float("nan")
    row["dark_mean_D"] = float(D[dark].mean()) if dark.any() else float("nan")
    row["dark_max_D"] = float(D[dark].max()) if dark.any() else float("nan")
    row["dark_share_lit"] = float(np.mean(D[dark] > 0)) if dark.any() else float("nan")
    return row


def fmt(x, spec):
    return "—" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, spec)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("reference")
    ap.add_argument("qsgi_ply")
    ap.add_argument("qsgi_black_ply")
    ap.add_argument("--json", help="also write the figures to this JSON file")
    ap.add_argument("--against", action="append", default=[], metavar="LABEL=OTHER.ply",
                    help="another qsgi frame of the same vertices (a grown scene, another seed): how far E moves")
    ap.add_argument("--worst", type=int, default=8, help="list the N vertices with the largest squared error (default 8)")
    args = ap.parse_args()

    ref = dict(np.load(args.reference))
    normal = read_ply_vertices(args.qsgi_ply)
    black = read_ply_vertices(args.qsgi_black_ply)
    check_same_vertices(normal, ref, args.qsgi_ply)
    check_same_vertices(black, ref, args.qsgi_black_ply)
    q = irradiance(normal)
    D = irradiance(black)
    r = ref["E"].mean(1)
    # Channel-mean standard error: the channels share their rays, so (conservatively) their mean error.
    sigma = ref["E_stderr"].mean(1)
    s = ref["sky_share"]
    L = float(np.mean(ref["sky"]))
    pis = np.pi * L * s
    contact = ref["contact"].astype(bool)
    referenced = ref["referenced"].astype(bool)
    mesh_id = ref["mesh_id"]
    names = [str(n) for n in ref["mesh_names"]]

    lit = referenced & (r > 0)
    total_sq = float(np.sum((q[lit] - r[lit]) ** 2))
    open_ = lit & (s >= 0.05) & ~contact
    groups = [("every lit vertex", lit), ("contact (hit within 1 mm along +n)", lit & contact),
              ("open (s_v >= 5 %, no contact)", open_), ("the rest (s_v < 5 %, no contact)", lit & ~contact & (s < 0.05)),
              ("dark but lit (s_v = 0)", lit & (s == 0))]
    groups += [("mesh " + n, lit & (mesh_id == i)) for i, n in enumerate(names)]
    rows = [group_row(name, m, q, r, sigma, total_sq, D, pis) for name, m in groups]
    unlit = referenced & (r == 0)

    print(f"reference: {args.reference}\n  {str(ref['comment'])}")
    print(f"qsgi: {args.qsgi_ply}\nqsgi black: {args.qsgi_black_ply}\n")
    print("1. Irradiance E (channel mean, W/m^2) against the reference, over vertices the reference lights (E_ref > 0)")
    print(f"{'group':<40} {'vertices':>8} {'rel. RMS':>9} {'q/ref means':>11} {'err share':>9} {'ref noise':>9} "
          f"{'mean ref':>9} {'mean q':>9} {'direct':>7} {'rest':>7}")
    for row in rows:
        if row["vertices"] == 0:
            print(f"{row['group']:<40} {0:>8}")
            continue
        print(f"{row['group']:<40} {row['vertices']:>8} {100 * row['relative_rms']:>8.1f}% {row['ratio_of_means']:>11.3f} "
              f"{100 * row['error_share']:>8.1f}% {100 * row['reference_noise']:>8.2f}% {row['mean_reference']:>9.4f} "
              f"{row['mean_qsgi']:>9.4f} {100 * row['direct_rms']:>6.1f}% {100 * row['indirect_rms']:>6.1f}%")
    print(f"vertices the reference leaves dark (E_ref = 0): {int(unlit.sum())}, qsgi's mean E there "
          f"{fmt(float(q[unlit].mean()) if unlit.any() else float('nan'), '.4f')} W/m^2 "
          f"(max {fmt(float(q[unlit].max()) if unlit.any() else float('nan'), '.3f')})")
    if args.worst > 0:
        err = np.where(lit, (q - r) ** 2, -1.0)
        worst = np.argsort(-err)[:args.worst]
        print(f"the {args.worst} largest squared errors:")
        for v in worst:
            print(f"  vertex {v:>6} ({names[mesh_id[v]]}): qsgi {q[v]:.4f}, reference {r[v]:.4f} ± {sigma[v]:.4f}, "
                  f"s_v {s[v]:.3f}, contact {'yes' if contact[v] else 'no'}")

    print("\n2. Direct light D (the black scene's E) against pi L s_v (s_v: the reference's sky share from the vertex)")
    d_groups = [("every vertex", np.ones(len(s), bool))] + [("mesh " + n, mesh_id == i) for i, n in enumerate(names)]
    d_rows = [direct_row(name, m, D, pis, s) for name, m in d_groups]
    print(f"{'group':<40} {'s_v > 0':>8} {'ΣD/Σπs':>8} {'mean D/πs':>10} {'dark':>6} {'dark mean D':>12} {'dark max D':>11} "
          f"{'dark D>0':>9}")
    for row in d_rows:
        print(f"{row['group']:<40} {row['vertices_with_sky']:>8} {fmt(row['sum_ratio'], '8.4f')} "
              f"{fmt(row['mean_ratio_open'], '10.4f')} {row['dark_vertices']:>6} {fmt(row['dark_mean_D'], '12.4f')} "
              f"{fmt(row['dark_max_D'], '11.3f')} {fmt(100 * row['dark_share_lit'] if np.isfinite(row['dark_share_lit']) else float('nan'), '8.1f')}%")
    print("(mean D/πs over s_v >= 5 %; dark: s_v = 0, mean and max D in W/m^2, and the share of them with D > 0)")
    # The sky share's own noise in the overall sum.
    seen = s > 0
    noise = float(np.sqrt(np.sum(ref["sky_share_var"][seen])) / np.sum(s[seen]))
    print(f"the reference's noise on Σ πs (from its two passes): {100 * noise:.3f} %")
    against_rows = {}
    for item in args.against:
        label, _, path = item.partition("=")
        if not path:
            sys.exit("--against wants LABEL=OTHER.ply")
        other = read_ply_vertices(path)
        n = len(r)
        if len(other) < n:
            sys.exit(f"{path} has fewer vertices than the reference")
        p = np.stack([other["x"], other["y"], other["z"]], 1).astype(np.float64)[:n]
        if float(np.abs(p - ref["positions"]).max()) > 1e-6:
            sys.exit(f"{path}: its first vertices are not the reference's")
        o = irradiance(other)[:n]
        print(f"\n3. {label}: {path} against {args.qsgi_ply}, how far E moves")
        print(f"{'group':<40} {'vertices':>8} {'rel. RMS':>9} {'other/q means':>13}")
        rows_here = []
        for name, m in [("every lit vertex", lit), ("open (s_v >= 5 %, no contact)", open_)] + \
                [("mesh " + nm, lit & (mesh_id == i)) for i, nm in enumerate(names)]:
            if not m.any():
                continue
            row = {"group": name, "vertices": int(m.sum()),
                   "relative_rms": float(np.sqrt(np.sum((o[m] - q[m]) ** 2) / np.sum(q[m] ** 2))),
                   "ratio_of_means": float(o[m].mean() / q[m].mean())}
            rows_here.append(row)
            print(f"{name:<40} {row['vertices']:>8} {100 * row['relative_rms']:>8.2f}% {row['ratio_of_means']:>13.4f}")
        against_rows[label] = rows_here
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            json.dump({"reference": args.reference, "qsgi": args.qsgi_ply, "qsgi_black": args.qsgi_black_ply,
                       "irradiance": rows, "unlit_vertices": int(unlit.sum()),
                       "unlit_mean_qsgi": float(q[unlit].mean()) if unlit.any() else None,
                       "direct": d_rows, "sky_share_noise": noise, "against": against_rows}, f, indent=1)
            f.write("\n")


if __name__ == "__main__":
    main()
