"""A long render split into frame chunks (one Slurm array task each) and merged into one folder.

Each chunk renders into OUT/chunks/NNN/ with `qsgi render --frames A:B --resume`, so a killed task
continues where it stopped when it runs again. The merge verifies every chunk's frame files against
the chunk's timing.json (each frame's "files": name, size and XXH3 of the bytes), links them into
OUT and writes OUT/timing.json: the frames of all chunks in order, and per chunk its range and the
summaries qsgi wrote for it. The frame files equal one sequential run's byte for byte: counter-based
randomness rebuilds each chunk's first frame from scratch exactly, and the PNG exposure is fixed at
frame 0 whichever frame a run starts at.

The merge and the submission write into OUT only through output_folder: holding OUT/.qsgi-lock,
under exclusive temporaries renamed into place, through no link planted there."""
import contextlib
import errno
import json
import os
import re

from .output_folder import (FileMismatch, FolderError, commit, create_exclusive, failure, has_size_and_xxh3, locked,
                            make_subfolder, make_temporary, open_folder, open_recorded, open_subfolder, sync_folder,
                            verify_file, write_file, xxh3)

PLAN = "chunks.json"
_FRAME_FILE = re.compile(r"frame_([0-9]{4,})\.[A-Za-z0-9]+")  # qsgi's frame file names (isFrameFileName)


class ChunkError(FolderError):
    """A refusal of the plan or the chunks, one line naming the folder and the problem (exit 2)."""


class _Unverified(Exception):
    """Why a chunk is not (yet) a finished, intact chunk."""


def plan(first: int, last: int, chunks: int) -> list:
    """Splits first..last into `chunks` contiguous ranges of near-equal length."""
    count = last - first + 1
    chunks = max(1, min(chunks, count))
    bounds = [first + count * i // chunks for i in range(chunks + 1)]
    return [(bounds[i], bounds[i + 1] - 1) for i in range(chunks)]


def folder(out: str, index: int) -> str:
    return os.path.join(out, "chunks", f"{index:03d}")


# The plan -----------------------------------------------------------------------------------------

def _read_plan(folder_fd: int, out: str, missing_ok: bool = False):
    path = os.path.join(out, PLAN)
    try:
        fd = os.open(PLAN, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=folder_fd)
    except FileNotFoundError:
        if missing_ok:
            return None
        raise ChunkError(f"{out}: no {PLAN} (submit the render first)")
    except OSError as e:
        if e.errno != errno.ELOOP:
            raise
        if missing_ok:  # saving replaces the link
            return None
        raise ChunkError(f"{path}: is a symbolic link, not a plan this script wrote; remove it and submit again")
    with os.fdopen(fd, "rb") as f:
        text = f.read()
    try:
        p = json.loads(text)
        chunks = p["chunks"]
        assert isinstance(p["frames"], str) and isinstance(p["qsgi"], str) and isinstance(p["cpus"], int)
        assert isinstance(p["arguments"], list) and all(isinstance(a, str) for a in p["arguments"])
        assert isinstance(chunks, list) and chunks
        assert all(isinstance(c, list) and len(c) == 2 and all(type(x) is int for x in c) and c[0] <= c[1]
                   for c in chunks)
    except (ValueError, KeyError, TypeError, AssertionError) as e:
        raise ChunkError(f"{path}: not a plan this script wrote ({type(e).__name__}{': ' + str(e) if str(e) else ''})")
    return p


def load_plan(out: str) -> dict:
    folder_fd = open_folder(out)
    try:
        return _read_plan(folder_fd, out)
    finally:
        os.close(folder_fd)


def save_plan(out: str, wanted: dict) -> None:
    """Writes the plan, or checks that an earlier submission made the same one: a folder is
    finished by resubmitting the same render, never turned into another."""
    try:
        with locked(out, "qsgi submit", create=True) as folder_fd:
            existing = _read_plan(folder_fd, out, missing_ok=True)
            if existing is None:
                write_file(folder_fd, PLAN, json.dumps(wanted, indent=1).encode())
            elif existing != wanted:
                raise ChunkError(f"{os.path.join(out, PLAN)}: this folder holds another render ({existing['frames']} "
                                 f"in {len(existing['chunks'])} chunks of {' '.join(existing['arguments'])}); "
                                 "use another --out")
    except OSError as e:
        raise failure(out, f"writing {PLAN}", e)


def task_command(out: str, index: int, threads: int) -> list:
    """Array task `index`'s qsgi command; its folder made a real one first, so qsgi never renders
    through a link planted at OUT/chunks or OUT/chunks/NNN. --frames-only: a chunk writes its
    frames, never an asset of its part of the animation (finish_command makes the one asset)."""
    p = load_plan(out)
    first, last = p["chunks"][index]
    chunk = make_subfolder(out, os.path.relpath(folder(out, index), out))
    return [p["qsgi"], "render"] + p["arguments"] + [
        "--frames", f"{first}:{last}", "--out", chunk, "--resume", "--threads", str(threads), "--frames-only"]


def finish_command(out: str) -> list:
    """After the merge: the render again over the plan's whole range with --resume. It finds every
    frame complete (verifying each against the merged timing.json) and computes nothing, but writes
    what qsgi makes from all the frames at once: with --gltf-out, OUT/asset.glb, and with --usd-out,
    OUT/asset.usda, each one file of the whole animation."""
    p = load_plan(out)
    first, last = p["chunks"][0][0], p["chunks"][-1][1]
    return [p["qsgi"], "render"] + p["arguments"] + [
        "--frames", f"{first}:{last}", "--out", out, "--resume", "--threads", str(p["cpus"]), "--quiet"]


# Verifying a chunk --------------------------------------------------------------------------------

def _frame_records(log: dict, first: int, last: int) -> list:
    """The log's file records, each with its frame, after checking their shape; raises _Unverified."""
    frames = log.get("frames") if isinstance(log, dict) else None
    if not isinstance(frames, list) or not all(isinstance(f, dict) and type(f.get("frame")) is int for f in frames):
        raise _Unverified("timing.json has no list of frames")
    logged = [f["frame"] for f in frames]
    wanted = list(range(first, last + 1))
    if logged != wanted:
        missing = [n for n in wanted if n not in logged]
        if missing and set(logged) <= set(wanted):
            raise _Unverified(f"unfinished: {len(wanted) - len(missing)} of {len(wanted)} frames logged "
                              f"(frame {missing[0]} is the first missing)")
        raise _Unverified(f"timing.json logs frames {logged[:5]}{'…' if len(logged) > 5 else ''}, not {first}..{last}")
    records, names = [], set()
    for entry in frames:
        frame, files = entry["frame"], entry.get("files")
        if not isinstance(files, list) or not files:
            raise _Unverified(f"frame {frame}: timing.json lists none of its files (an older qsgi wrote it)")
        for r in files:
            name = r.get("name") if isinstance(r, dict) else None
            match = _FRAME_FILE.fullmatch(name) if isinstance(name, str) else None
            if not match or int(match.group(1)) != frame:
                raise _Unverified(f"frame {frame}: timing.json lists {name!r}, not a file name of frame {frame}")
            if not has_size_and_xxh3(r):
                raise _Unverified(f"frame {frame}: {name}: timing.json's record has no valid \"bytes\" and \"xxh3\"")
            if name in names:
                raise _Unverified(f"frame {frame}: {name}: listed twice in timing.json")
            names.add(name)
            records.append((frame, r))
    return records


def _check_chunk(out: str, chunks_fd, index: int, first: int, last: int):
    """The chunk's log and its verified files [(frame, record, (st_dev, st_ino))] when timing.json
    lists frames first..last and every file it records is there: a regular file of the logged size
    and XXH3. Raises _Unverified saying why not; FolderError for a link planted as the folder."""
    name = f"{index:03d}"
    chunk_fd = None
    if chunks_fd is not None:
        chunk_fd = open_subfolder(chunks_fd, name, os.path.join(out, "chunks", name), create=False)
    if chunk_fd is None:
        raise _Unverified("not started (no folder)")
    try:
        try:
            fd = os.open("timing.json", os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=chunk_fd)
        except FileNotFoundError:
            raise _Unverified("unfinished: no timing.json yet")
        except OSError as e:
            if e.errno == errno.ELOOP:
                raise _Unverified("timing.json is a symbolic link, not the log qsgi wrote")
            raise
        with os.fdopen(fd, "rb") as f:
            try:
                log = json.loads(f.read())
            except ValueError as e:
                raise _Unverified(f"timing.json is not JSON ({e})")
        verified = []
        for frame, record in _frame_records(log, first, last):
            try:
                verified.append((frame, record, verify_file(chunk_fd, record)))
            except FileMismatch as e:
                raise _Unverified(f"frame {frame}: {e}")
        return log, verified
    finally:
        os.close(chunk_fd)


def complete(out: str, index: int, first: int, last: int) -> bool:
    """Whether the chunk's timing.json lists frames first..last and every file it records is
    there intact: what the merge accepts. A chunk whose files were damaged counts as unfinished,
    so a resubmission runs it again (qsgi --resume redoes the frames that fail)."""
    folder_fd = open_folder(out)
    try:
        chunks_fd = open_subfolder(folder_fd, "chunks", os.path.join(out, "chunks"), create=False)
        try:
            _check_chunk(out, chunks_fd, index, first, last)
            return True
        except _Unverified:
            return False
        finally:
            if chunks_fd is not None:
                os.close(chunks_fd)
    finally:
        os.close(folder_fd)


# The merge ----------------------------------------------------------------------------------------

def _changed(out: str, name: str, why: str = "") -> ChunkError:
    return ChunkError(f"{out}: {name} changed in its chunk folder during the merge{why}; run the merge again")


def _place(out: str, folder_fd: int, chunk_fd: int, frame: int, record: dict, identity) -> None:
    """Puts the verified chunk file `record` names into OUT under the same name: a hard link (or,
    where links fail, a copy checked against the record) at a temporary name, renamed into place.
    What is placed is the very file verified, not one swapped in since."""
    name = record["name"]
    with contextlib.suppress(FileNotFoundError):
        st = os.stat(name, dir_fd=folder_fd, follow_symlinks=False)
        if (st.st_dev, st.st_ino) == identity:
            return  # placed by an earlier merge

    def link(temporary):
        os.link(name, temporary, src_dir_fd=chunk_fd, dst_dir_fd=folder_fd, follow_symlinks=False)

    try:
        temporary, _ = make_temporary(name, link)
    except FileExistsError:
        raise
    except OSError:  # another file system, or links not allowed here: a copy
        temporary = _copy(out, folder_fd, chunk_fd, frame, record, identity)
    else:
        st = os.stat(temporary, dir_fd=folder_fd, follow_symlinks=False)
        if (st.st_dev, st.st_ino) != identity:
            os.unlink(temporary, dir_fd=folder_fd)
            raise _changed(out, name)
    commit(folder_fd, temporary, name)


def _copy(out: str, folder_fd: int, chunk_fd: int, frame: int, record: dict, identity) -> str:
    """A copy of the verified file at an exclusively created temporary, hashed as it is copied;
    returns the temporary's name."""
    name = record["name"]
    try:
        source, st = open_recorded(chunk_fd, record)
    except FileMismatch as e:
        raise _changed(out, name, f" (frame {frame}: {e})")
    try:
        if (st.st_dev, st.st_ino) != identity:
            raise _changed(out, name)
        temporary, target = make_temporary(name, lambda t: create_exclusive(folder_fd, t))
        try:
            try:
                digest = xxh3(source, copy_to=target)
                os.fsync(target)
            finally:
                os.close(target)
            if digest != record["xxh3"]:
                raise _changed(out, name)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(temporary, dir_fd=folder_fd)
            raise
        return temporary
    finally:
        os.close(source)


def merge(out: str) -> int:
    """Verifies every chunk, links the chunks' frame files into `out` and writes the merged
    timing.json; returns the number of frames. Refuses, placing nothing, while any chunk is
    unfinished or damaged, naming each such chunk, the frame, the file and the problem."""
    try:
        with locked(out, "qsgi merge") as folder_fd:
            return _merge(out, folder_fd)
    except OSError as e:
        raise failure(out, f"merging ({e.filename})" if e.filename else "merging", e)


def _merge(out: str, folder_fd: int) -> int:
    p = _read_plan(folder_fd, out)
    chunks_fd = open_subfolder(folder_fd, "chunks", os.path.join(out, "chunks"), create=False)
    try:
        logs, verified, problems = [], [], []
        for i, (a, b) in enumerate(p["chunks"]):
            try:
                log, files = _check_chunk(out, chunks_fd, i, a, b)
                logs.append(log)
                verified.append(files)
            except _Unverified as e:
                problems.append(f"chunk {i} (frames {a}:{b}): {e}")
        if problems:
            shown = "; ".join(problems[:3]) + (f"; and {len(problems) - 3} more chunks" if len(problems) > 3 else "")
            raise ChunkError(f"{out}: {shown}; submit again")
        fingerprints = {str(log.get("config", {}).get("inputs_fingerprint")) for log in logs}
        if len(fingerprints) != 1:
            raise ChunkError(f"{out}: the chunks were rendered from different inputs ({', '.join(sorted(fingerprints))})")
        for i, files in enumerate(verified):
            chunk_fd = open_subfolder(chunks_fd, f"{i:03d}", os.path.join(out, "chunks", f"{i:03d}"), create=False)
            if chunk_fd is None:
                raise ChunkError(f"{out}: chunk {i}'s folder went away during the merge; submit again")
            try:
                for frame, record, identity in files:
                    _place(out, folder_fd, chunk_fd, frame, record, identity)
            finally:
                os.close(chunk_fd)
    finally:
        if chunks_fd is not None:
            os.close(chunks_fd)
    sync_folder(folder_fd)  # the frame files are in place before a log lists them
    merged = {key: value for key, value in logs[0].items()
              if key not in ("frames", "photon_simulation", "density_estimation")}
    merged["frames"] = [frame for log in logs for frame in log["frames"]]
    merged["chunks"] = [{"frames": f"{a}:{b}", "folder": os.path.relpath(folder(out, i), out),
                         "photon_simulation": log.get("photon_simulation"),
                         "density_estimation": log.get("density_estimation")}
                        for i, ((a, b), log) in enumerate(zip(p["chunks"], logs))]
    write_file(folder_fd, "timing.json", (json.dumps(merged, indent=2) + "\n").encode())
    return len(merged["frames"])
