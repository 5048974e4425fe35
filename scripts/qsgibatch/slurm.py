"""Slurm submission: sbatch job arrays with a dependent merge job.

Both kinds of work split cleanly. A sweep's points are independent renders. A render's frames
split into chunks: randomness is counter-based, so a chunk starting at frame A rebuilds frame A's
state from scratch and writes the bytes one sequential run would (the PNG exposure, fixed at frame
0, is computed for it). Each submission covers only what is missing, so submitting again after a
killed or failed task finishes the work without redoing any."""
import os
import re
import shlex
import shutil
import subprocess
import sys

from .output_folder import FolderError, make_subfolder, open_folder, open_subfolder, write_file
from .runner import finished


class SlurmError(Exception):
    pass


def require_sbatch() -> None:
    """Raises SlurmError, before anything is written, on a machine without Slurm's sbatch."""
    if shutil.which("sbatch") is None:
        raise SlurmError("sbatch is not on PATH: this machine has no Slurm client. Submit from a machine of the "
                         "cluster (its login node), or run the work here without Slurm")


def sbatch(name, command, log_folder, options, array=None, dependency=None, cpus=1) -> str:
    """Submits `command` (a shell command line) and returns the job id."""
    arguments = ["sbatch", "--parsable", f"--job-name={name}", f"--cpus-per-task={cpus}",
                 f"--output={os.path.join(log_folder, name + '-%A_%a.out' if array else name + '-%j.out')}"]
    if array:
        arguments.append(f"--array={array}")
    if dependency:
        arguments.append(f"--dependency={dependency}")
    arguments += list(options) + ["--wrap", command]
    done = subprocess.run(arguments, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        raise SlurmError(f"{shlex.join(arguments)}: {done.stderr.strip()}")
    return done.stdout.strip().split(";")[0]


def replace_merge_job(record: str, new_job: str) -> None:
    """Cancels the merge job an earlier submission left (recorded in `record`) and records the new
    one. A merge whose array had a failed or killed task waits forever on a dependency that can
    never be met, unless the cluster sets kill_invalid_depend; the resubmission supersedes it. The
    record is read and written without following a link planted at its name, a link planted as its
    folder is refused (FolderError), and only a job id read from it reaches scancel."""
    folder = os.path.dirname(record) or "."
    parent, base = os.path.split(folder)
    parent_fd = open_folder(parent or ".")
    try:
        folder_fd = open_subfolder(parent_fd, base, folder, create=False)
    finally:
        os.close(parent_fd)
    if folder_fd is None:
        raise FolderError(f"{folder}: no such folder")
    try:
        name = os.path.basename(record)
        old = ""
        try:
            fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, dir_fd=folder_fd)
            with os.fdopen(fd, "rb") as f:
                old = f.read(64).decode("ascii", "replace").strip()
        except OSError:  # none yet, or not a file this script wrote
            pass
        if re.fullmatch(r"[0-9]+", old) and old != new_job:
            subprocess.run(["scancel", "--state=PENDING", old], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        write_file(folder_fd, name, (new_job + "\n").encode())
    finally:
        os.close(folder_fd)


def array_spec(indices) -> str:
    """Slurm's compact array syntax: [0, 1, 2, 5] -> "0-2,5"."""
    parts, start = [], None
    for i, value in enumerate(indices):
        if start is None:
            start = value
        if i + 1 == len(indices) or indices[i + 1] != value + 1:
            parts.append(str(start) if start == value else f"{start}-{value}")
            start = None
    return ",".join(parts)


def python_executable():
    """The interpreter running us, for the jobs to run the same one (Debian's, with matplotlib)."""
    return sys.executable or "/usr/bin/python3"


def submit_sweep(args, config, script) -> int:
    """A preparation job (scene probe and reference), an array of the points not yet computed, and
    a merge job that writes sweep.csv and the plots once every point has succeeded."""
    try:
        require_sbatch()
    except SlurmError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return 2
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    try:
        logs = make_subfolder(out, "slurm")  # a real folder: Slurm writes the jobs' logs in it
    except FolderError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return e.exit_code
    cpus = args.slurm_cpus
    command = [python_executable(), script, os.path.abspath(config.path), "--out", out, "--qsgi", os.path.abspath(args.qsgi),
               "--cores", str(cpus)] + (["--quick"] if args.quick else []) + \
        (["--max-photons", repr(args.max_photons)] if args.max_photons is not None else [])  # the same point indices
    missing = [i for i, p in enumerate(config.points) if finished(out, p) is None]
    try:
        prepare = sbatch("qsgi-sweep-prepare", shlex.join(command + ["--prepare"]), logs, args.slurm_option,
                         cpus=cpus)
        dependency = f"afterok:{prepare}"
        if missing:
            points = sbatch("qsgi-sweep-point", shlex.join(command) + " --point $SLURM_ARRAY_TASK_ID", logs,
                            args.slurm_option, array=array_spec(missing), dependency=dependency, cpus=cpus)
            dependency = f"afterok:{points}"
        merge = sbatch("qsgi-sweep-merge", shlex.join(command + ["--merge"]), logs, args.slurm_option,
                       dependency=dependency, cpus=cpus)
        replace_merge_job(os.path.join(logs, "merge-job"), merge)
    except SlurmError as e:
        print(f"sweep: {e}", file=sys.stderr)
        return 2
    except FolderError as e:  # a link planted as OUT/slurm since it was made: refused
        print(f"sweep: {e}", file=sys.stderr)
        return e.exit_code
    print(f"sweep: submitted {len(missing)} of {len(config.points)} points (jobs {prepare}, "
          f"{points if missing else '-'}, merge {merge}); logs in {logs}")
    return 0
