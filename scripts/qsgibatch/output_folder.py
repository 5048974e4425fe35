"""Writing into an output folder that someone else may have touched, the way qsgi render does.

Nothing written here follows a symbolic link planted in the folder: every file is made under a
process-unique temporary name by exclusive create (or a hard link, which fails as well if the name
is taken) relative to the folder's handle, then renamed over its final name, which replaces a link
standing there instead of writing through it (lib/output/output_directory.h). Subfolders are opened
without following links, so a link planted as a folder is refused, not entered.

One writer per folder: OUT/.qsgi-lock is taken with flock as qsgi render takes it
(lib/output/folder_lock.h), so a Slurm merge, a submission and a render never write into one
folder at once, and a lock left by a dead process never blocks.

A file qsgi wrote is checked against its record in timing.json ("name", "bytes", XXH3 "xxh3";
lib/util/file_record.h) as lib/output/file_checksum.h checks it: a regular file, never a link, of
that size and hash.

Refusals are FolderError and its kinds, each one line naming the folder and the problem, with the
exit code a script returns for it."""
import contextlib
import errno
import fcntl
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

LOCK = ".qsgi-lock"
TEMPORARY_MARKER = ".qsgi-merge-tmp"
_XXH3 = re.compile(r"[0-9a-f]{16}")
_READ_SIZE = 1 << 20
# flock's answers on file systems that cannot lock (some NFS or Lustre mounts).
_CANNOT_LOCK = {errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EINVAL}


class FolderError(Exception):
    """A refusal with one line naming the folder and the problem; `exit_code` is the script's."""
    exit_code = 2


class FolderBusy(FolderError):
    """Another run holds the folder's lock: try again later (sysexits' EX_TEMPFAIL)."""
    exit_code = 75


class FolderFailure(FolderError):
    """The machine failed us (no space, an I/O error): qsgi's exit code for it (EX_IOERR)."""
    exit_code = 74


class FileMismatch(Exception):
    """Why a file is not the one its record describes; the message starts with the file's name."""


def failure(out: str, what: str, e: OSError) -> FolderError:
    """Permission problems are the user's to fix (another --out); the rest is the machine's."""
    if e.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return FolderError(f"{out}: {what}: {e.strerror}")
    return FolderFailure(f"{out}: {what}: {e.strerror}")


# Folders, never through a planted link -------------------------------------------------------------

def open_folder(out: str) -> int:
    try:
        return os.open(out, os.O_RDONLY | os.O_DIRECTORY | os.O_CLOEXEC)
    except FileNotFoundError:
        raise FolderError(f"{out}: no such folder (submit the render first)")
    except NotADirectoryError:
        raise FolderError(f"{out}: is not a folder")
    except OSError as e:
        raise failure(out, "cannot open the folder", e)


def open_subfolder(parent_fd: int, name: str, where: str, create: bool):
    """The folder `name` inside `parent_fd`, never through a link planted there; None when it does
    not exist and `create` is False. `where` is its path for the message."""
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
            raise FolderError(f"{where}: is not a folder (a link or a file stands there); remove it")
        raise


def make_subfolder(out: str, name: str) -> str:
    """OUT/name ("slurm", "chunks/003") made of real folders (a link or file planted at any part
    is refused); returns its path."""
    fds = [open_folder(out)]
    try:
        parts = name.split("/")
        for k, part in enumerate(parts):
            fds.append(open_subfolder(fds[-1], part, os.path.join(out, *parts[:k + 1]), create=True))
    finally:
        for fd in fds:
            os.close(fd)
    return os.path.join(out, name)


def sync_folder(folder_fd: int) -> None:
    try:
        os.fsync(folder_fd)
    except OSError as e:
        if e.errno != errno.EINVAL:  # file systems that cannot sync a folder
            raise


# Writing a file: exclusive temporary, then rename ----------------------------------------------------

def _temporary_names(name: str):
    """Names for `name`'s temporary that no other process makes (the pid); a further one for each
    entry already standing there (planted, or left by a dead process of the same pid)."""
    base = f".{name}{TEMPORARY_MARKER}.{os.getpid()}"
    yield base
    for n in range(1, 1000):
        yield f"{base}.{n}"


def make_temporary(name: str, make):
    """Calls make(temporary) with the first free temporary name and returns (temporary, what make
    returned); `make` raises FileExistsError rather than touch an entry standing there."""
    for temporary in _temporary_names(name):
        try:
            return temporary, make(temporary)
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "every temporary name is taken", name)


def create_exclusive(folder_fd: int, temporary: str) -> int:
    return os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644,
                   dir_fd=folder_fd)


def _write_all(fd: int, data) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def commit(folder_fd: int, temporary: str, name: str) -> None:
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
    temporary, fd = make_temporary(name, lambda t: create_exclusive(folder_fd, t))
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
    commit(folder_fd, temporary, name)
    sync_folder(folder_fd)


def _remove_stale_temporaries(folder_fd: int) -> None:
    """Temporaries of writers that died; only while holding the lock (they could be a live one's)."""
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
                raise FolderError(f"{where}: is not qsgi's lock file (a folder or a link stands there); remove it")
            raise failure(out, f"cannot make the lock file {LOCK}", e)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise FolderError(f"{where}: is not qsgi's lock file (not a regular file); remove it")
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise FolderBusy(f"{out}: another run is writing into this folder ({_read_holder(fd)}); "
                             "wait for it to end, then run this again")
        except OSError as e:
            if e.errno not in _CANNOT_LOCK:
                raise failure(out, f"cannot lock {LOCK}", e)
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
def locked(out: str, role: str, create: bool = False):
    """OUT opened and locked for `role` ("qsgi merge"); its stale temporaries removed. Yields the
    folder's fd."""
    if create:
        try:
            os.makedirs(out, exist_ok=True)
        except OSError as e:
            raise failure(out, "cannot create the folder", e)
    folder_fd = open_folder(out)
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


# A file against its record ------------------------------------------------------------------------

def has_size_and_xxh3(record: dict) -> bool:
    """Whether the record's "bytes" and "xxh3" are what qsgi writes: a count and 16 hex digits."""
    return type(record.get("bytes")) is int and record["bytes"] >= 0 and isinstance(record.get("xxh3"), str) \
        and bool(_XXH3.fullmatch(record["xxh3"]))


def xxh3(fd: int, copy_to: int = None) -> str:
    """XXH3-64 (seed 0) of the file open as `fd`, from its start, as 16 lowercase hex digits; the
    bytes are also written to `copy_to` when given."""
    if xxhash is None:
        raise FolderError("Python's xxhash module is missing (Debian: python3-xxhash; scripts/setup.sh --test "
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


def open_recorded(folder_fd: int, record: dict):
    """Opens the file `record` names and checks it is a regular file of the recorded size; returns
    the fd and its stat. Raises FileMismatch naming the file and the problem."""
    name = record["name"]
    try:
        # O_NONBLOCK: a FIFO planted at the name must not hang the open.
        fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, dir_fd=folder_fd)
    except FileNotFoundError:
        raise FileMismatch(f"{name} is missing")
    except OSError as e:
        if e.errno == errno.ELOOP:
            raise FileMismatch(f"{name} is a symbolic link, not the file qsgi wrote")
        raise
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise FileMismatch(f"{name} is not a regular file")
        if st.st_size != record["bytes"]:
            raise FileMismatch(f"{name} holds {st.st_size} bytes, timing.json says {record['bytes']}")
    except BaseException:
        os.close(fd)
        raise
    return fd, st


def verify_file(folder_fd: int, record: dict):
    """The identity (st_dev, st_ino) of the file `record` names once it is a regular file of the
    recorded size and XXH3; raises FileMismatch saying why not."""
    fd, st = open_recorded(folder_fd, record)
    try:
        digest = xxh3(fd)
    finally:
        os.close(fd)
    if digest != record["xxh3"]:
        raise FileMismatch(f"{record['name']}: its bytes differ from those qsgi logged "
                           f"(xxh3 {digest}, timing.json says {record['xxh3']})")
    return st.st_dev, st.st_ino
