"""A long render split into frame chunks (one Slurm array task each) and merged into one folder.

Each chunk renders into OUT/chunks/NNN/ with `qsgi render --frames A:B --resume`, so a killed task
continues where it stopped when it runs again. The merge verifies every chunk's frame files against
the chunk's timing.json (each frame's "files": name, size and XXH3 of the bytes), links them into
OUT and writes OUT/timing.json: the frames of all chunks in order, and per chunk its range and the
summaries qsgi wrote for it. The frame files equal one sequential run's byte for byte: counter-based
randomness rebuilds each chunk's first frame from scratch exactly, and the PNG exposure is fixed at
frame 0 whichever frame a run starts at.

What is written into OUT never follows a symbolic link planted there: every file is made under a
process-unique temporary name by exclusive create (or a hard link, which fails as well if the name
is taken), then renamed over its final name, which replaces a link standing there instead of
writing through it. The merge and the submission hold OUT/.qsgi-lock (flock, as qsgi render holds
its folder's), so two of them never write into one folder at once."""
import contextlib
import errno
import fcntl
import json
import os
import re
import socket
import stat
import sys
import time

try:
    import xxhash  # Debian's python3-xxhash
except ImportError:
    xxhash = None

PLAN = "chunks.json"
LOCK = ".qsgi-lock"
TEMPORARY_MARKER = ".qsgi-merge-tmp"
_FRAME_FILE = re.compile(r"frame_([0-9]{4,})\.[A-Za-z0-9]+")  # qsgi's frame file names (isFrameFileName)
_XXH3 = re.compile(r"[0-9a-f]{16}")
_READ_SIZE = 1 << 20
# flock's answers on file systems that cannot lock (some NFS or Lustre mounts).
_CANNOT_LOCK = {errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EINVAL}


class ChunkError(Exception):
    """A refusal with one line naming the folder and the problem; `exit_code` is render.py's."""
    exit_code = 2


class FolderBusy(ChunkError):
    """Another run holds the folder's lock: try again later (sysexits' EX_TEMPFAIL)."""
    exit_code = 75


class FolderFailure(ChunkError):
    """The machine failed us (no space, an I/O error): qsgi's exit code for it (EX_IOERR)."""
    exit_code = 74


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


# Files in the output folder ------------------------------------------------------------------------

def _failure(out: str, what: str, e: OSError) -> ChunkError:
    """Permission problems are the user's to fix (another --out); the rest is the machine's."""
    if e.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return ChunkError(f"{out}: {what}: {e.strerror}")
    return FolderFailure(f"{out}: {what}: {e.strerror}")


def _open_folder(out: str) -> int:
    try:
        return os.open(out, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except FileNotFoundError:
        raise ChunkError(f"{out}: no such folder (submit the render first)")
    except NotADirectoryError:
        raise ChunkError(f"{out}: is not a folder")
    except OSError as e:
        raise _failure(out, "cannot open the folder", e)


def _subfolder(parent_fd: int, name: str, where: str, create: bool):
    """The folder `name` inside `parent_fd`, never through a link planted there; None when it does
    not exist and `create` is False."""
    if create:
        with contextlib.suppress(FileExistsError):
            os.mkdir(name, 0o755, dir_fd=parent_fd)
    try:
        return os.open(name, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | os.O_CLOEXEC, dir_fd=parent_fd)
    except FileNotFoundError:
        if create:
            raise
        return None
    except OSError as e:
        if e.errno in (errno.ELOOP, errno.ENOTDIR):
            raise ChunkError(f"{where}: is not a folder (a link or a file stands there); remove it")
        raise


def _sync_folder(folder_fd: int) -> None:
    try:
        os.fsync(folder_fd)
    except OSError as e:
        if e.errno != errno.EINVAL:  # file systems that cannot sync a folder
            raise


def _temporary_names(name: str):
    """Names for `name`'s temporary that no other process makes (the pid); a further one for each
    entry already standing there (planted, or left by a dead process of the same pid)."""
    base = f".{name}{TEMPORARY_MARKER}.{os.getpid()}"
    yield base
    for n in range(1, 1000):
        yield f"{base}.{n}"


def _make_temporary(name: str, make):
    """Calls make(temporary) with the first free temporary name and returns (temporary, what make
    returned); `make` raises FileExistsError rather than touch an entry standing there."""
    for temporary in _temporary_names(name):
        try:
            return temporary, make(temporary)
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "every temporary name is taken", name)


def _create_exclusive(folder_fd: int, temporary: str) -> int:
    return os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644,
                   dir_fd=folder_fd)


def _write_all(fd: int, data) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _commit(folder_fd: int, temporary: str, name: str) -> None:
    """Renames the temporary over `name` (a link there is replaced, not followed); on failure the
    temporary goes. Where both are hard links of one file rename(2) does nothing and succeeds, so
    the temporary is unlinked after it as well."""
    try:
        os.replace(temporary, name, src_dir_fd=folder_fd, dst_dir_fd=folder_fd)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(temporary, dir_fd=folder_fd)


def write_file(folder_fd: int, name: str, data: bytes) -> None:
    """Writes `data` as `name` in the folder: exclusive temporary, fsync, rename, fsync the folder."""
    temporary, fd = _make_temporary(name, lambda t: _create_exclusive(folder_fd, t))
    try:
        try:
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temporary, dir_fd=folder_fd)
        raise
    _commit(folder_fd, temporary, name)
    _sync_folder(folder_fd)


def _remove_stale_temporaries(folder_fd: int) -> None:
    """Temporaries of merges that died; only while holding the lock (they could be a live one's)."""
    for name in os.listdir(folder_fd):
        if TEMPORARY_MARKER not in name:
            continue
        with contextlib.suppress(FileNotFoundError):
            if not stat.S_ISDIR(os.stat(name, dir_fd=folder_fd, follow_symlinks=False).st_mode):
                os.unlink(name, dir_fd=folder_fd)


# The folder's lock --------------------------------------------------------------------------------

def _holder_line(role: str) -> str:
    since = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    return f"pid {os.getpid()} on host {socket.gethostname()} since {since} ({role})\n"


def _read_holder(fd: int) -> str:
    """The holder's line for the message: its first line, printable characters only, at most 200."""
    text = os.pread(fd, 255, 0).decode("ascii", "replace").split("\n")[0]
    line = "".join(c for c in text if " " <= c <= "~")[:200]
    return line or "a process that has not written its name yet"


def _take_lock(folder_fd: int, out: str, role: str):
    """Takes OUT/.qsgi-lock the way qsgi render does (lib/output/folder_lock.cpp): flock on a file
    that stays, so a lock left by a dead process never blocks. Returns the open lock file, or None
    where the file system cannot lock (the run goes on unguarded, with a warning)."""
    where = os.path.join(out, LOCK)
    flags = os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK
    for attempt in (0, 1):
        try:
            fd = os.open(LOCK, flags, 0o644, dir_fd=folder_fd)
            break
        except OSError as e:
            if e.errno == errno.ELOOP and attempt == 0:
                os.unlink(LOCK, dir_fd=folder_fd)  # a link is not ours: the link goes, not its target
                continue
            if e.errno in (errno.EISDIR, errno.ELOOP):
                raise ChunkError(f"{where}: is not qsgi's lock file (a folder or a link stands there); remove it")
            raise _failure(out, f"cannot make the lock file {LOCK}", e)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ChunkError(f"{where}: is not qsgi's lock file (not a regular file); remove it")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusy(f"{out}: another run is writing into this folder ({_read_holder(fd)}); "
                             "wait for it to end, then run this again")
        except OSError as e:
            if e.errno not in _CANNOT_LOCK:
                raise _failure(out, f"cannot lock {LOCK}", e)
            print(f"warning: cannot lock {where} ({e.strerror}); not guarding against concurrent runs, "
                  "and stale temporaries are left in place", file=sys.stderr)
            os.close(fd)
            return None
    except BaseException:
        os.close(fd)
        raise
    # The line only names the holder in another run's message; a file with other hard links may
    # be someone's file elsewhere, so it is locked but not written.
    if st.st_nlink == 1:
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
            os.pwrite(fd, _holder_line(role).encode(), 0)
    return fd


@contextlib.contextmanager
def _locked(out: str, role: str, create: bool = False):
    """OUT opened and locked for `role`; its stale temporaries removed. Yields the folder's fd."""
    if create:
        try:
            os.makedirs(out, exist_ok=True)
        except OSError as e:
            raise _failure(out, "cannot create the folder", e)
    folder_fd = _open_folder(out)
    try:
        lock_fd = _take_lock(folder_fd, out, role)
        try:
            if lock_fd is not None:
                _remove_stale_temporaries(folder_fd)
            yield folder_fd
        finally:
            if lock_fd is not None:
                os.close(lock_fd)
    finally:
        os.close(folder_fd)


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
    folder_fd = _open_folder(out)
    try:
        return _read_plan(folder_fd, out)
    finally:
        os.close(folder_fd)


def save_plan(out: str, wanted: dict) -> None:
    """Writes the plan, or checks that an earlier submission made the same one: a folder is
    finished by resubmitting the same render, never turned into another."""
    try:
        with _locked(out, "qsgi submit", create=True) as folder_fd:
            existing = _read_plan(folder_fd, out, missing_ok=True)
            if existing is None:
                write_file(folder_fd, PLAN, json.dumps(wanted, indent=1).encode())
            elif existing != wanted:
                raise ChunkError(f"{os.path.join(out, PLAN)}: this folder holds another render ({existing['frames']} "
                                 f"in {len(existing['chunks'])} chunks of {' '.join(existing['arguments'])}); "
                                 "use another --out")
    except OSError as e:
        raise _failure(out, f"writing {PLAN}", e)


def subfolder(out: str, name: str) -> str:
    """OUT/name ("slurm", "chunks/003") made of real folders (a link or file planted at any part
    is refused); returns its path."""
    fds = [_open_folder(out)]
    try:
        parts = name.split("/")
        for k, part in enumerate(parts):
            fds.append(_subfolder(fds[-1], part, os.path.join(out, *parts[:k + 1]), create=True))
    finally:
        for fd in fds:
            os.close(fd)
    return os.path.join(out, name)


def task_command(out: str, index: int, threads: int) -> list:
    """Array task `index`'s qsgi command; its folder made a real one first, so qsgi never renders
    through a link planted at OUT/chunks or OUT/chunks/NNN."""
    p = load_plan(out)
    first, last = p["chunks"][index]
    chunk = subfolder(out, os.path.relpath(folder(out, index), out))
    return [p["qsgi"], "render"] + p["arguments"] + [
        "--frames", f"{first}:{last}", "--out", chunk, "--resume", "--threads", str(threads)]


# Verifying a chunk --------------------------------------------------------------------------------

def _xxh3(fd: int, copy_to: int = None) -> str:
    """XXH3-64 (seed 0) of the file open as `fd`, from its start, as 16 lowercase hex digits; the
    bytes are also written to `copy_to` when given."""
    if xxhash is None:
        raise ChunkError("Python's xxhash module is missing (Debian: python3-xxhash; scripts/setup.sh --test "
                         "installs it): the chunks' files cannot be verified without it")
    h = xxhash.xxh3_64()
    offset = 0
    while True:
        block = os.pread(fd, _READ_SIZE, offset)
        if not block:
            return h.hexdigest()
        h.update(block)
        if copy_to is not None:
            _write_all(copy_to, block)
        offset += len(block)


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
            if type(r.get("bytes")) is not int or r["bytes"] < 0 or not isinstance(r.get("xxh3"), str) \
                    or not _XXH3.fullmatch(r["xxh3"]):
                raise _Unverified(f"frame {frame}: {name}: timing.json's record has no valid \"bytes\" and \"xxh3\"")
            if name in names:
                raise _Unverified(f"frame {frame}: {name}: listed twice in timing.json")
            names.add(name)
            records.append((frame, r))
    return records


def _open_verified(chunk_fd: int, frame: int, record: dict):
    """Opens the file `record` names and checks it is a regular file of the logged size; returns
    the fd and its stat. Raises _Unverified naming the frame, the file and the problem."""
    name = record["name"]
    try:
        # O_NONBLOCK: a FIFO planted at the name must not hang the open.
        fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, dir_fd=chunk_fd)
    except FileNotFoundError:
        raise _Unverified(f"frame {frame}: {name} is missing")
    except OSError as e:
        if e.errno == errno.ELOOP:
            raise _Unverified(f"frame {frame}: {name} is a symbolic link, not the file qsgi wrote")
        raise
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise _Unverified(f"frame {frame}: {name} is not a regular file")
        if st.st_size != record["bytes"]:
            raise _Unverified(f"frame {frame}: {name} holds {st.st_size} bytes, timing.json says {record['bytes']}")
    except BaseException:
        os.close(fd)
        raise
    return fd, st


def _check_chunk(out: str, chunks_fd, index: int, first: int, last: int):
    """The chunk's log and its verified files [(frame, record, (st_dev, st_ino))] when timing.json
    lists frames first..last and every file it records is there: a regular file of the logged size
    and XXH3. Raises _Unverified saying why not; ChunkError for a link planted as the folder."""
    name = f"{index:03d}"
    chunk_fd = None
    if chunks_fd is not None:
        chunk_fd = _subfolder(chunks_fd, name, os.path.join(out, "chunks", name), create=False)
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
            fd, st = _open_verified(chunk_fd, frame, record)
            try:
                digest = _xxh3(fd)
            finally:
                os.close(fd)
            if digest != record["xxh3"]:
                raise _Unverified(f"frame {frame}: {record['name']}: its bytes differ from those qsgi logged "
                                  f"(xxh3 {digest}, timing.json says {record['xxh3']})")
            verified.append((frame, record, (st.st_dev, st.st_ino)))
        return log, verified
    finally:
        os.close(chunk_fd)


def complete(out: str, index: int, first: int, last: int) -> bool:
    """Whether the chunk's timing.json lists frames first..last and every file it records is
    there intact: what the merge accepts. A chunk whose files were damaged counts as unfinished,
    so a resubmission runs it again (qsgi --resume redoes the frames that fail)."""
    folder_fd = _open_folder(out)
    try:
        chunks_fd = _subfolder(folder_fd, "chunks", os.path.join(out, "chunks"), create=False)
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
        temporary, _ = _make_temporary(name, link)
    except FileExistsError:
        raise
    except OSError:  # another file system, or links not allowed here: a copy
        temporary = _copy(out, folder_fd, chunk_fd, frame, record, identity)
    else:
        st = os.stat(temporary, dir_fd=folder_fd, follow_symlinks=False)
        if (st.st_dev, st.st_ino) != identity:
            os.unlink(temporary, dir_fd=folder_fd)
            raise _changed(out, name)
    _commit(folder_fd, temporary, name)


def _copy(out: str, folder_fd: int, chunk_fd: int, frame: int, record: dict, identity) -> str:
    """A copy of the verified file at an exclusively created temporary, hashed as it is copied;
    returns the temporary's name."""
    name = record["name"]
    try:
        source, st = _open_verified(chunk_fd, frame, record)
    except _Unverified as e:
        raise _changed(out, name, f" ({e})")
    try:
        if (st.st_dev, st.st_ino) != identity:
            raise _changed(out, name)
        temporary, target = _make_temporary(name, lambda t: _create_exclusive(folder_fd, t))
        try:
            try:
                digest = _xxh3(source, copy_to=target)
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
        with _locked(out, "qsgi merge") as folder_fd:
            return _merge(out, folder_fd)
    except OSError as e:
        raise _failure(out, f"merging ({e.filename})" if e.filename else "merging", e)


def _merge(out: str, folder_fd: int) -> int:
    p = _read_plan(folder_fd, out)
    chunks_fd = _subfolder(folder_fd, "chunks", os.path.join(out, "chunks"), create=False)
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
            chunk_fd = _subfolder(chunks_fd, f"{i:03d}", os.path.join(out, "chunks", f"{i:03d}"), create=False)
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
    _sync_folder(folder_fd)  # the frame files are in place before a log lists them
    merged = {key: value for key, value in logs[0].items()
              if key not in ("frames", "photon_simulation", "density_estimation")}
    merged["frames"] = [frame for log in logs for frame in log["frames"]]
    merged["chunks"] = [{"frames": f"{a}:{b}", "folder": os.path.relpath(folder(out, i), out),
                         "photon_simulation": log.get("photon_simulation"),
                         "density_estimation": log.get("density_estimation")}
                        for i, ((a, b), log) in enumerate(zip(p["chunks"], logs))]
    write_file(folder_fd, "timing.json", (json.dumps(merged, indent=2) + "\n").encode())
    return len(merged["frames"])
