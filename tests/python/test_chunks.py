#!/usr/bin/python3
"""The Slurm merge of frame chunks (scripts/qsgibatch/chunks.py) trusts nothing in the folder and
writes through no link planted there (scripts/qsgibatch/output_folder.py). Fake chunk folders hold
small frame files and timing.json logs recording each file's size and XXH3, as qsgi render writes
them; no Slurm and no qsgi needed.

    python3 tests/python/test_chunks.py        (a second or so)"""
import contextlib
import errno
import fcntl
import importlib.util
import io
import json
import os
import subprocess
import sys
import tempfile
import unittest
from unittest import mock

try:
    import xxhash
except ImportError:  # another python3 first on PATH (pyenv); Debian's has python3-xxhash
    if sys.executable != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise

REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPOSITORY, "scripts"))

from qsgibatch import chunks, output_folder  # noqa: E402

_spec = importlib.util.spec_from_file_location("render", os.path.join(REPOSITORY, "scripts", "slurm", "render.py"))
render = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(render)

CHUNKS = [[0, 2], [3, 5]]
EXTENSIONS = ("ply", "png")
PLAN = {"frames": "0:5", "chunks": CHUNKS, "qsgi": "/nonexistent/qsgi", "arguments": ["scene.gltf"], "cpus": 1}


def frame_bytes(frame: int, extension: str) -> bytes:
    return f"{extension} of frame {frame}\n".encode() * (frame + 3)


def record(name: str, data: bytes) -> dict:
    return {"name": name, "bytes": len(data), "xxh3": xxhash.xxh3_64_hexdigest(data)}


def make_chunk(out: str, index: int, first: int, last: int, fingerprint: str = "f00d") -> None:
    """A finished chunk as qsgi render --frames first:last leaves it."""
    folder = chunks.folder(out, index)
    os.makedirs(folder)
    frames = []
    for frame in range(first, last + 1):
        files = []
        for extension in EXTENSIONS:
            name, data = f"frame_{frame:04d}.{extension}", frame_bytes(frame, extension)
            with open(os.path.join(folder, name), "wb") as f:
                f.write(data)
            files.append(record(name, data))
        frames.append({"frame": frame, "total_s": 0.5, "files": files})
    log = {"version": "test", "config": {"inputs_fingerprint": fingerprint, "photons": 1000},
           "photon_simulation": {"initial_s": index + 1.0}, "density_estimation": {"initial_s": index + 2.0},
           "frames": frames}
    with open(os.path.join(folder, "timing.json"), "w") as f:
        json.dump(log, f)


def read(path: str) -> bytes:
    with open(path, "rb") as f:
        return f.read()


def temporary(name: str) -> str:
    """The first temporary name the merge uses for `name` in this process."""
    return f".{name}{output_folder.TEMPORARY_MARKER}.{os.getpid()}"


class MergeTest(unittest.TestCase):
    def setUp(self):
        self.scratch = tempfile.TemporaryDirectory(prefix="qsgi-chunks-test.")
        self.out = os.path.join(self.scratch.name, "out")
        self.outside = os.path.join(self.scratch.name, "outside")  # what planted links point to
        os.makedirs(self.outside)
        chunks.save_plan(self.out, PLAN)
        for i, (a, b) in enumerate(CHUNKS):
            make_chunk(self.out, i, a, b)

    def tearDown(self):
        self.scratch.cleanup()

    def victim(self, name: str) -> str:
        path = os.path.join(self.outside, name)
        with open(path, "wb") as f:
            f.write(b"not qsgi's to touch\n")
        return path

    def plant(self, name: str, target: str) -> None:
        os.symlink(target, os.path.join(self.out, name))

    def assertMergedCorrectly(self):
        """Every frame file in OUT is a regular file whose size and XXH3 are the merged log's, with
        the bytes the chunk rendered; the log lists frames 0..5 in order; no temporary is left."""
        with open(os.path.join(self.out, "timing.json")) as f:
            log = json.load(f)
        self.assertEqual([entry["frame"] for entry in log["frames"]], list(range(6)))
        self.assertEqual([c["frames"] for c in log["chunks"]], ["0:2", "3:5"])
        self.assertEqual([c["photon_simulation"]["initial_s"] for c in log["chunks"]], [1.0, 2.0])
        for entry in log["frames"]:
            self.assertEqual([r["name"] for r in entry["files"]], [f"frame_{entry['frame']:04d}.{e}" for e in EXTENSIONS])
            for r in entry["files"]:
                path = os.path.join(self.out, r["name"])
                self.assertFalse(os.path.islink(path), path)
                data = read(path)
                self.assertEqual(r, record(r["name"], data))
                self.assertEqual(data, frame_bytes(entry["frame"], r["name"].rsplit(".")[1]))
        self.assertFalse(os.path.islink(os.path.join(self.out, "timing.json")))
        self.assertEqual([n for n in os.listdir(self.out) if output_folder.TEMPORARY_MARKER in n], [])

    def refusal(self, index: int) -> str:
        """The merge's refusal while chunk `index` is damaged; it placed nothing and complete()
        calls only that chunk unfinished."""
        self.assertEqual([chunks.complete(self.out, i, a, b) for i, (a, b) in enumerate(CHUNKS)],
                         [i != index for i in range(len(CHUNKS))])
        with self.assertRaises(chunks.ChunkError) as refused:
            chunks.merge(self.out)
        self.assertEqual(refused.exception.exit_code, 2)
        self.assertFalse([n for n in os.listdir(self.out) if n.startswith("frame_") or n == "timing.json"])
        message = str(refused.exception)
        self.assertIn(f"chunk {index} (frames {CHUNKS[index][0]}:{CHUNKS[index][1]})", message)
        return message

    def test_merge_places_the_verified_files_and_keeps_each_chunks_log(self):
        self.assertTrue(all(chunks.complete(self.out, i, a, b) for i, (a, b) in enumerate(CHUNKS)))
        self.assertEqual(chunks.merge(self.out), 6)
        self.assertMergedCorrectly()
        with open(os.path.join(self.out, output_folder.LOCK)) as f:
            self.assertRegex(f.read(), rf"^pid {os.getpid()} on host \S+ since \d{{4}}-\d\d-\d\dT\d\d:\d\d:\d\dZ \(qsgi merge\)\n$")
        self.assertEqual(chunks.merge(self.out), 6)  # again: the same folder
        self.assertMergedCorrectly()

    def test_links_planted_at_every_name_written_are_replaced_not_followed(self):
        names = ["timing.json", "frame_0001.ply", "frame_0004.png", output_folder.LOCK,
                 temporary("timing.json"), temporary("frame_0001.ply"), temporary("frame_0004.png")]
        victims = {name: self.victim(f"victim-{i}") for i, name in enumerate(names)}
        os.unlink(os.path.join(self.out, output_folder.LOCK))  # save_plan's
        for name, target in victims.items():
            self.plant(name, target)
        dangling = os.path.join(self.outside, "never-made")  # O_CREAT through the link would make it
        self.plant(temporary("frame_0002.ply"), dangling)
        self.assertEqual(chunks.merge(self.out), 6)
        for target in victims.values():
            self.assertEqual(read(target), b"not qsgi's to touch\n", target)
        self.assertFalse(os.path.exists(dangling))
        self.assertFalse(os.path.islink(os.path.join(self.out, output_folder.LOCK)))
        self.assertMergedCorrectly()

    def test_a_lock_file_hard_linked_to_a_file_elsewhere_is_not_written(self):
        victim = self.victim("lock-victim")
        os.unlink(os.path.join(self.out, output_folder.LOCK))
        os.link(victim, os.path.join(self.out, output_folder.LOCK))
        self.assertEqual(chunks.merge(self.out), 6)
        self.assertEqual(read(victim), b"not qsgi's to touch\n")

    def test_the_plan_is_saved_over_a_planted_link_not_through_it(self):
        out = os.path.join(self.scratch.name, "fresh")
        os.makedirs(out)
        plan_victim, temporary_victim = self.victim("plan"), self.victim("plan-temporary")
        os.symlink(plan_victim, os.path.join(out, chunks.PLAN))
        os.symlink(temporary_victim, os.path.join(out, temporary(chunks.PLAN)))
        chunks.save_plan(out, PLAN)
        self.assertEqual(read(plan_victim), b"not qsgi's to touch\n")
        self.assertEqual(read(temporary_victim), b"not qsgi's to touch\n")
        self.assertFalse(os.path.islink(os.path.join(out, chunks.PLAN)))
        self.assertEqual(chunks.load_plan(out), PLAN)
        for i, (a, b) in enumerate(CHUNKS):
            make_chunk(out, i, a, b)
        self.out = out
        self.assertEqual(chunks.merge(out), 6)
        self.assertMergedCorrectly()
        with self.assertRaisesRegex(chunks.ChunkError, "holds another render"):
            chunks.save_plan(out, dict(PLAN, cpus=2))

    def test_a_temporary_name_taken_by_a_link_is_skipped(self):
        """Without the lock's clean-up (write_file alone): the exclusive create passes over a link
        at the temporary name instead of opening it."""
        first, second = self.victim("first"), self.victim("second")
        self.plant(temporary("notes.txt"), first)
        self.plant(temporary("notes.txt") + ".1", second)
        fd = os.open(self.out, os.O_RDONLY | os.O_DIRECTORY)
        try:
            output_folder.write_file(fd, "notes.txt", b"written\n")
        finally:
            os.close(fd)
        self.assertEqual(read(first), b"not qsgi's to touch\n")
        self.assertEqual(read(second), b"not qsgi's to touch\n")
        self.assertEqual(read(os.path.join(self.out, "notes.txt")), b"written\n")

    def test_a_truncated_chunk_file_is_refused_naming_it(self):
        path = os.path.join(chunks.folder(self.out, 1), "frame_0004.ply")
        os.truncate(path, 5)
        message = self.refusal(1)
        self.assertIn("frame 4: frame_0004.ply holds 5 bytes, timing.json says", message)

    def test_a_chunk_file_of_garbage_is_refused_naming_it(self):
        path = os.path.join(chunks.folder(self.out, 0), "frame_0001.png")
        with open(path, "r+b") as f:
            f.write(b"garbage")  # the same size, other bytes
        message = self.refusal(0)
        self.assertIn("frame 1: frame_0001.png: its bytes differ from those qsgi logged", message)

    def test_a_chunk_file_replaced_by_a_link_is_refused_even_to_the_right_bytes(self):
        path = os.path.join(chunks.folder(self.out, 1), "frame_0005.png")
        copy = os.path.join(self.outside, "copy.png")
        os.rename(path, copy)
        os.symlink(copy, path)
        message = self.refusal(1)
        self.assertIn("frame 5: frame_0005.png is a symbolic link", message)

    def test_a_missing_chunk_file_is_refused_naming_it(self):
        os.unlink(os.path.join(chunks.folder(self.out, 0), "frame_0000.ply"))
        self.assertIn("frame 0: frame_0000.ply is missing", self.refusal(0))

    def test_a_log_without_file_records_is_unfinished(self):
        path = os.path.join(chunks.folder(self.out, 1), "timing.json")
        with open(path) as f:
            log = json.load(f)
        for entry in log["frames"]:
            del entry["files"]
        with open(path, "w") as f:
            json.dump(log, f)
        self.assertIn("frame 3: timing.json lists none of its files (an older qsgi wrote it)", self.refusal(1))

    def test_a_logged_name_outside_the_folder_is_refused(self):
        self.victim("escape.ply")
        path = os.path.join(chunks.folder(self.out, 0), "timing.json")
        with open(path) as f:
            log = json.load(f)
        log["frames"][2]["files"][0] = record("../../outside/escape.ply", b"not qsgi's to touch\n")
        with open(path, "w") as f:
            json.dump(log, f)
        self.assertIn("frame 2: timing.json lists '../../outside/escape.ply', not a file name of frame 2",
                      self.refusal(0))

    def test_an_unfinished_chunk_is_refused(self):
        path = os.path.join(chunks.folder(self.out, 1), "timing.json")
        with open(path) as f:
            log = json.load(f)
        log["frames"] = log["frames"][:1]
        with open(path, "w") as f:
            json.dump(log, f)
        self.assertIn("unfinished: 1 of 3 frames logged (frame 4 is the first missing)", self.refusal(1))

    def test_render_py_exits_2_naming_the_damaged_file(self):
        os.truncate(os.path.join(chunks.folder(self.out, 0), "frame_0002.png"), 0)
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            self.assertEqual(render.main(["--out", self.out, "--merge"]), 2)
        self.assertIn("frame_0002.png", stderr.getvalue())
        self.assertEqual(stderr.getvalue().count("\n"), 1)

    def test_a_held_lock_refuses_naming_the_holder(self):
        stale = os.path.join(self.out, ".frame_0001.ply.qsgi-merge-tmp.1")
        with open(stale, "w"):
            pass
        holder = "pid 4242 on host node07 since 2026-12-03T07:00:00Z (qsgi render)"
        fd = os.open(os.path.join(self.out, output_folder.LOCK), os.O_RDWR | os.O_CREAT, 0o644)
        try:
            os.write(fd, (holder + "\n").encode())
            fcntl.flock(fd, fcntl.LOCK_EX)  # another open file description: the merge's flock conflicts
            with self.assertRaises(output_folder.FolderBusy) as refused:
                chunks.merge(self.out)
            self.assertIn(holder, str(refused.exception))
            self.assertIn(self.out, str(refused.exception))
            stderr = io.StringIO()
            with contextlib.redirect_stderr(stderr):
                self.assertEqual(render.main(["--out", self.out, "--merge"]), 75)
            self.assertIn(holder, stderr.getvalue())
            with self.assertRaises(output_folder.FolderBusy):
                chunks.save_plan(self.out, PLAN)
        finally:
            os.close(fd)
        self.assertTrue(os.path.exists(stale), "a temporary was removed without the lock")
        self.assertFalse(os.path.exists(os.path.join(self.out, "timing.json")))
        self.assertEqual(chunks.merge(self.out), 6)  # released: the merge proceeds and cleans up
        self.assertFalse(os.path.exists(stale))
        self.assertMergedCorrectly()

    def test_a_lock_held_by_another_process_refuses(self):
        holder = subprocess.Popen(
            [sys.executable, "-c", "import fcntl, os, sys; fd = os.open(sys.argv[1], os.O_RDWR | os.O_CREAT, 0o644); "
             "fcntl.flock(fd, fcntl.LOCK_EX); os.write(fd, b'pid %d on host elsewhere since then (qsgi render)\\n' "
             "% os.getpid()); print('held', flush=True); sys.stdin.read()", os.path.join(self.out, output_folder.LOCK)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        try:
            self.assertEqual(holder.stdout.readline(), "held\n")
            with self.assertRaisesRegex(output_folder.FolderBusy, rf"pid {holder.pid} on host elsewhere"):
                chunks.merge(self.out)
        finally:
            holder.communicate()  # closes its stdin: it ends
        self.assertEqual(chunks.merge(self.out), 6)  # the holder died: its lock went with it

    def test_a_lock_file_left_by_a_dead_process_does_not_block(self):
        dead = subprocess.Popen([sys.executable, "-c", "pass"])
        dead.wait()
        with open(os.path.join(self.out, output_folder.LOCK), "w") as f:
            f.write(f"pid {dead.pid} on host {os.uname().nodename} since 2026-12-03T07:00:00Z (qsgi merge)\n")
        self.assertEqual(chunks.merge(self.out), 6)
        self.assertMergedCorrectly()
        with open(os.path.join(self.out, output_folder.LOCK)) as f:
            self.assertTrue(f.read().startswith(f"pid {os.getpid()} "))

    def test_a_file_system_that_cannot_lock_warns_and_leaves_temporaries(self):
        stale = os.path.join(self.out, ".timing.json.qsgi-merge-tmp.1")
        with open(stale, "w"):
            pass
        stderr = io.StringIO()
        with mock.patch.object(output_folder.fcntl, "flock", side_effect=OSError(errno.ENOLCK, "No locks available")), \
                contextlib.redirect_stderr(stderr):
            self.assertEqual(chunks.merge(self.out), 6)
        self.assertIn("not guarding against concurrent runs", stderr.getvalue())
        self.assertTrue(os.path.exists(stale))

    def test_a_link_planted_as_a_chunk_folder_is_refused(self):
        moved = os.path.join(self.outside, "001")
        os.rename(chunks.folder(self.out, 1), moved)
        os.symlink(moved, chunks.folder(self.out, 1))
        with self.assertRaisesRegex(output_folder.FolderError, "chunks/001: is not a folder"):
            chunks.merge(self.out)
        with self.assertRaisesRegex(output_folder.FolderError, "chunks/001: is not a folder"):
            chunks.task_command(self.out, 1, 1)


if __name__ == "__main__":
    unittest.main()
