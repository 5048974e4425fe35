#!/usr/bin/python3
"""A qsgi render as a Slurm job array of frame chunks, then a dependent job that merges them.

    scripts/slurm/render.py --out /shared/run --frames 0:599 --chunks 20 --cpus 4 -- \\
        data/cornell/cornell.gltf --animation data/cornell/animation.json --png

Everything after `--` is passed to `qsgi render` (not --out, --frames, --resume, --threads: this
script sets them). OUT must be on a file system every node sees. Submitting the same command
again submits only the chunks that are not finished (a killed chunk resumes from its last
complete frame, and a chunk whose files no longer match its timing.json runs again) and the merge.
`--task I` and `--merge` are what the jobs run. Exit codes: 0 done, 2 refused (one line naming the
folder, and for an unfinished or damaged chunk the chunk, frame, file and problem), 75 another
run or merge holds OUT/.qsgi-lock (try again later), 74 the machine failed (no space, I/O error)."""
import argparse
import os
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from qsgibatch import chunks, output_folder, slurm  # noqa: E402

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SET_HERE = ("--out", "--frames", "--resume", "--threads", "--frames-only")


def parse_arguments(argv):
    if "--" in argv:
        split = argv.index("--")
        argv, render_arguments = argv[:split], argv[split + 1:]
    else:
        render_arguments = []
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="the output folder, shared by every node")
    parser.add_argument("--frames", help="A:B, inclusive")
    parser.add_argument("--chunks", type=int, help="array tasks (contiguous frame ranges)")
    parser.add_argument("--cpus", type=int, default=1, help="cores per task (qsgi --threads)")
    parser.add_argument("--qsgi", default=os.path.join(REPOSITORY, "build", "cli", "qsgi"))
    parser.add_argument("--slurm-option", action="append", default=[], metavar="OPTION",
                        help="passed to every sbatch (e.g. --slurm-option=--partition=long); repeatable")
    parser.add_argument("--task", type=int, help="render chunk I (what array task I runs)")
    parser.add_argument("--merge", action="store_true", help="merge the finished chunks (the dependent job)")
    args = parser.parse_args(argv)
    args.render_arguments = render_arguments
    if args.task is None and not args.merge:
        if not args.frames or not args.chunks or not render_arguments:
            parser.error("submitting needs --frames A:B, --chunks N and the render's arguments after --")
        if args.chunks < 1 or args.cpus < 1:
            parser.error("--chunks and --cpus must be at least 1")
        clash = [a for a in render_arguments if a.split("=")[0] in SET_HERE]
        if clash:
            parser.error(f"{', '.join(clash)}: set by this script, not passed to qsgi render")
        try:
            first, last = (int(x) for x in args.frames.split(":"))
            assert 0 <= first <= last
        except (ValueError, AssertionError):
            parser.error(f"--frames {args.frames}: must be A:B with 0 <= A <= B")
        args.first, args.last = first, last
    return args


def submit(args) -> int:
    slurm.require_sbatch()  # before the plan or the log folder is written
    out = os.path.abspath(args.out)
    # Paths in the render's arguments are made absolute: tasks start in another folder.
    arguments = [os.path.abspath(a) if os.path.exists(a) else a for a in args.render_arguments]
    wanted = {"frames": f"{args.first}:{args.last}", "chunks": chunks.plan(args.first, args.last, args.chunks),
              "qsgi": os.path.abspath(args.qsgi), "arguments": arguments, "cpus": args.cpus}
    wanted["chunks"] = [list(c) for c in wanted["chunks"]]
    chunks.save_plan(out, wanted)
    missing = [i for i, (a, b) in enumerate(wanted["chunks"]) if not chunks.complete(out, i, a, b)]
    logs = output_folder.make_subfolder(out, "slurm")  # a real folder: Slurm writes the jobs' logs in it
    me = [slurm.python_executable(), os.path.abspath(__file__), "--out", out]
    dependency = None
    if missing:
        array = slurm.sbatch("qsgi-render-chunk", shlex.join(me) + " --task $SLURM_ARRAY_TASK_ID", logs,
                             args.slurm_option, array=slurm.array_spec(missing), cpus=args.cpus)
        dependency = f"afterok:{array}"
    merge = slurm.sbatch("qsgi-render-merge", shlex.join(me + ["--merge"]), logs, args.slurm_option,
                         dependency=dependency)
    slurm.replace_merge_job(os.path.join(logs, "merge-job"), merge)
    print(f"render: submitted {len(missing)} of {len(wanted['chunks'])} chunks"
          f"{' (array ' + array + ')' if missing else ''} and the merge (job {merge}); logs in {logs}")
    return 0


def main(argv):
    args = parse_arguments(argv)
    out = os.path.abspath(args.out)
    try:
        if args.task is not None:
            p = chunks.load_plan(out)
            if not 0 <= args.task < len(p["chunks"]):
                print(f"render: --task {args.task}: the plan has chunks 0..{len(p['chunks']) - 1}", file=sys.stderr)
                return 2
            command = chunks.task_command(out, args.task, p["cpus"])
            os.execv(command[0], command)
        if args.merge:
            print(f"render: merged {chunks.merge(out)} frames into {out}")
            # What is made from all the frames (--gltf-out's asset.glb, --usd-out's asset.usda), by qsgi itself.
            return subprocess.run(chunks.finish_command(out)).returncode
        return submit(args)
    except output_folder.FolderError as e:  # 2 a refusal, 75 another run holds the folder, 74 the machine failed
        print(f"render: {e}", file=sys.stderr)
        return e.exit_code
    except slurm.SlurmError as e:
        print(f"render: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"render: {out}: {e}", file=sys.stderr)
        return 74


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
