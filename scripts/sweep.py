#!/usr/bin/python3
"""Speed/accuracy sweeps: qsgi renders over a grid of photon counts, radii, k, estimators, photon
samplers (random, sobol) and lightings (direct light from the photons or exact, final gather),
judged against a reference, tabulated in OUT/sweep.csv and plotted in OUT/*.png.

    scripts/sweep.py configs/sweep-cornell.json --quick --out out/sweep-quick
    scripts/sweep.py configs/sweep-tree.json --out out/sweep-tree --jobs 2
    scripts/sweep.py configs/sweep-cornell.json --out /shared/sweep --slurm   # a job array

A script rather than a `qsgi sweep` subcommand: a sweep is orchestration of the executable users
run (each point is exactly a `qsgi render` a user could repeat by hand), its plots need matplotlib,
and its Slurm submission is process-level work; none of it belongs in the renderer's library.

Finished points are kept (OUT/points/NAME/result.json) and never recomputed; an interrupted point
resumes its renders. The sweep writes nothing through a link planted in OUT
(scripts/qsgibatch/output_folder.py). Exit codes: 0 done, 2 bad config or command line, or a link
or file planted where OUT needs a folder, 1 a render failed, 74 the machine failed opening a folder
of OUT (an I/O error)."""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

# numpy and matplotlib are the test set's (scripts/setup.sh --test), not the renderer's: name them
# rather than fail with a traceback on a machine set up by scripts/run.sh.
for module, package in (("numpy", "python3-numpy"), ("matplotlib", "python3-matplotlib")):
    try:
        __import__(module)
    except ImportError:
        sys.exit(f"sweep: needs the Python module {module} (Debian package {package}); "
                 "scripts/setup.sh --test installs it")

from qsgibatch import grid, output_folder, plots, reference, runner, table  # noqa: E402
from qsgibatch.qsgi import Qsgi, QsgiError  # noqa: E402

REPOSITORY = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse_arguments(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("config", help="sweep config (configs/sweep-*.json)")
    parser.add_argument("--out", required=True, help="output folder: sweep.csv, plots, points/, reference/")
    parser.add_argument("--quick", action="store_true", help="the config's small grid (its \"quick\" section)")
    parser.add_argument("--jobs", type=int, help="points run at once (default: the config's, else 1); "
                        "timings of points that overlapped are marked shared_cores in the CSV")
    parser.add_argument("--cores", type=int, default=os.cpu_count(), help="cores shared by the jobs (default: all)")
    parser.add_argument("--qsgi", default=os.path.join(REPOSITORY, "build", "cli", "qsgi"),
                        help="the qsgi executable (default: build/cli/qsgi)")
    parser.add_argument("--max-photons", type=float, help="only the points with at most this many photons "
                        "(the cheap part of a grid first; the rest is added by a later run without it)")
    parser.add_argument("--list", action="store_true", help="print the grid points and exit")
    parser.add_argument("--point", type=int, help="compute only point I (0-based; a Slurm array task)")
    parser.add_argument("--prepare", action="store_true", help="only measure the scene and build the reference")
    parser.add_argument("--merge", action="store_true",
                        help="only tabulate and plot the points already computed (the Slurm merge job)")
    parser.add_argument("--slurm", action="store_true",
                        help="submit to Slurm: reference job, array of missing points, dependent merge job")
    parser.add_argument("--slurm-option", action="append", default=[], metavar="OPTION",
                        help="passed to every sbatch (e.g. --slurm-option=--partition=long); repeatable")
    parser.add_argument("--slurm-cpus", type=int, default=1, help="cores per Slurm task (default 1)")
    args = parser.parse_args(argv)
    if args.jobs is not None and not 1 <= args.jobs <= 256:
        parser.error(f"--jobs must be in 1..256, not {args.jobs}")
    if not args.cores or args.cores < 1:
        parser.error("--cores must be at least 1")
    return args


def progress(done, total, point, result):
    print(f"[{done}/{total}] {point.name}: rms {result['rms_all']:.4f}, "
          f"frame {result['median_frame_s']:.3f} s", flush=True)


def main(argv):
    try:
        return run(parse_arguments(argv))
    except output_folder.FolderError as e:  # a link planted in OUT: refused, not followed
        print(f"sweep: {e}", file=sys.stderr)
        return e.exit_code


def run(args):
    try:
        config = grid.load(args.config, args.quick)
    except grid.ConfigError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return 2
    if args.max_photons is not None:
        config.points = [p for p in config.points if p.photons <= args.max_photons]
    if args.list:
        for i, p in enumerate(config.points):
            print(i, p.name)
        return 0
    if args.point is not None and not 0 <= args.point < len(config.points):
        print(f"sweep: --point {args.point}: the grid has points 0..{len(config.points) - 1}", file=sys.stderr)
        return 2
    if not os.access(args.qsgi, os.X_OK):
        print(f"sweep: {args.qsgi}: no qsgi executable (build it, or name it with --qsgi)", file=sys.stderr)
        return 2
    if args.slurm:
        from qsgibatch import slurm
        return slurm.submit_sweep(args, config, os.path.abspath(__file__))
    os.makedirs(args.out, exist_ok=True)
    jobs = args.jobs or config.jobs
    qsgi = Qsgi(os.path.abspath(args.qsgi), config.scene, config.animation)
    try:
        probe = output_folder.make_subfolder(args.out, "probe")  # a real folder before qsgi renders into it
        diagonal = qsgi.animation_diagonal(probe)
        reference_path, description = reference.prepare(config, qsgi, args.out, diagonal, args.cores)
        if args.prepare:
            return 0
        sweep = runner.Sweep(config, qsgi, args.out, diagonal, reference_path, description, jobs, args.cores)
        if args.point is not None:
            point = config.points[args.point]
            progress(1, 1, point, sweep.run(point))
            return 0
        if args.merge:
            missing = [p.name for p in config.points if sweep.cached(p) is None]
            if missing:
                print(f"sweep: {len(missing)} points not computed yet (first: {missing[0]}); "
                      "run the sweep again to finish them", file=sys.stderr)
                return 1
        results = sweep.run_all(config.points, progress)
    except QsgiError as e:
        print(f"sweep: a render failed:\n{e}", file=sys.stderr)
        return 1
    csv_path = os.path.join(args.out, "sweep.csv")
    table.write(csv_path, results)
    note = f"{os.path.basename(config.scene)} — reference {description}"
    names, slopes = plots.draw_all(table.read(csv_path), args.out, note)
    bad = sum(r["nan_count"] + r["inf_count"] for r in results)
    print(f"sweep: {len(results)} points in {csv_path} ({sweep.computed} computed now, "
          f"{len(results) - sweep.computed} finished earlier); plots: {', '.join(names)}; NaN/Inf values: {bad}")
    for (name, kind), slope in slopes.items():
        print(f"  frame time ∝ photons^{slope:.2f}  ({name}, {kind})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
