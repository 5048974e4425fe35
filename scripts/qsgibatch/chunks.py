"""A long render split into frame chunks (one Slurm array task each) and merged into one folder.

Each chunk renders into OUT/chunks/NNN/ with `qsgi render --frames A:B --resume`, so a killed task
continues where it stopped when it runs again. The merge links every chunk's frame files into OUT
(atomically: temporary name, then rename) and writes OUT/timing.json: the frames of all chunks in
order, and per chunk its range and the summaries qsgi wrote for it. The frame files equal one
sequential run's byte for byte: counter-based randomness rebuilds each chunk's first frame from
scratch exactly, and the PNG exposure is fixed at frame 0 whichever frame a run starts at."""
import json
import os
import shutil

PLAN = "chunks.json"


class ChunkError(Exception):
    pass


def plan(first: int, last: int, chunks: int) -> list:
    """Splits first..last into `chunks` contiguous ranges of near-equal length."""
    count = last - first + 1
    chunks = max(1, min(chunks, count))
    bounds = [first + count * i // chunks for i in range(chunks + 1)]
    return [(bounds[i], bounds[i + 1] - 1) for i in range(chunks)]


def folder(out: str, index: int) -> str:
    return os.path.join(out, "chunks", f"{index:03d}")


def load_plan(out: str) -> dict:
    try:
        with open(os.path.join(out, PLAN)) as f:
            return json.load(f)
    except OSError:
        raise ChunkError(f"{out}: no {PLAN} (submit the render first)")


def save_plan(out: str, wanted: dict) -> None:
    """Writes the plan, or checks that an earlier submission made the same one: a folder is
    finished by resubmitting the same render, never turned into another."""
    path = os.path.join(out, PLAN)
    if os.path.exists(path):
        existing = load_plan(out)
        if existing != wanted:
            raise ChunkError(f"{path}: this folder holds another render ({existing['frames']} in "
                             f"{len(existing['chunks'])} chunks of {' '.join(existing['arguments'])}); "
                             "use another --out")
        return
    os.makedirs(out, exist_ok=True)
    with open(path + ".tmp", "w") as f:
        json.dump(wanted, f, indent=1)
    os.replace(path + ".tmp", path)


def logged_frames(chunk_folder: str) -> list:
    try:
        with open(os.path.join(chunk_folder, "timing.json")) as f:
            return [frame["frame"] for frame in json.load(f)["frames"]]
    except (OSError, ValueError, KeyError):
        return []


def complete(out: str, index: int, first: int, last: int) -> bool:
    """timing.json lists exactly the frames whose files are complete (qsgi writes it after them)."""
    return logged_frames(folder(out, index)) == list(range(first, last + 1))


def task_command(out: str, index: int, threads: int) -> list:
    p = load_plan(out)
    first, last = p["chunks"][index]
    return [p["qsgi"], "render"] + p["arguments"] + [
        "--frames", f"{first}:{last}", "--out", folder(out, index), "--resume", "--threads", str(threads)]


def _place(source: str, target: str) -> None:
    temporary = target + ".qsgi-merge-tmp"
    if os.path.exists(temporary):
        os.remove(temporary)
    try:
        os.link(source, temporary)
    except OSError:  # another file system, or links not allowed
        shutil.copy2(source, temporary)
    os.replace(temporary, target)


def merge(out: str) -> int:
    """Links the chunks' frame files into `out` and writes the merged timing.json; returns the
    number of frames. Refuses while any chunk is unfinished."""
    p = load_plan(out)
    missing = [i for i, (a, b) in enumerate(p["chunks"]) if not complete(out, i, a, b)]
    if missing:
        raise ChunkError(f"{out}: chunks {', '.join(map(str, missing))} are not finished; submit again")
    logs = []
    for i in range(len(p["chunks"])):
        with open(os.path.join(folder(out, i), "timing.json")) as f:
            logs.append(json.load(f))
    fingerprints = {log["config"]["inputs_fingerprint"] for log in logs}
    if len(fingerprints) != 1:
        raise ChunkError(f"{out}: the chunks were rendered from different inputs ({', '.join(sorted(fingerprints))})")
    frames = 0
    for i in range(len(p["chunks"])):
        for name in sorted(os.listdir(folder(out, i))):
            if name.startswith("frame_") and ".qsgi-tmp" not in name:
                _place(os.path.join(folder(out, i), name), os.path.join(out, name))
                frames += name.endswith(".ply")
    merged = {key: value for key, value in logs[0].items()
              if key not in ("frames", "photon_simulation", "density_estimation")}
    merged["frames"] = [frame for log in logs for frame in log["frames"]]
    merged["chunks"] = [{"frames": f"{a}:{b}", "folder": os.path.relpath(folder(out, i), out),
                         "photon_simulation": log["photon_simulation"], "density_estimation": log["density_estimation"]}
                        for i, ((a, b), log) in enumerate(zip(p["chunks"], logs))]
    path = os.path.join(out, "timing.json")
    with open(path + ".tmp", "w") as f:
        json.dump(merged, f, indent=2)
    os.replace(path + ".tmp", path)
    return frames
