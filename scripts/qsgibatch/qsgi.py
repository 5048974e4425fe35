"""Running the qsgi executable: renders (always with --resume, so a killed render continues) and
`qsgi compare`. A failure raises QsgiError with qsgi's own one-line message."""
import json
import os
import subprocess
import time

# qsgi's exit code when another run holds the output folder (sysexits' EX_TEMPFAIL).
FOLDER_BUSY = 75


class QsgiError(Exception):
    pass


def clear_run(out: str) -> None:
    """Unlinks the run a script left in its own folder `out` (frame_NNNN.* and timing.json, nothing
    else, never recursively), for scripts that render one setting after another into one folder
    and read back that render's frames alone: qsgi keeps the frames of the same run outside a new
    range and refuses another run's folder."""
    if not os.path.isdir(out):
        return
    for name in os.listdir(out):
        path = os.path.join(out, name)
        if (name == "timing.json" or (name.startswith("frame_") and "." in name)) and not os.path.isdir(path):
            os.remove(path)


class Qsgi:
    def __init__(self, executable: str, scene: str, animation: str):
        self.executable, self.scene, self.animation = executable, scene, animation

    def render(self, out: str, options: list, seed: int, threads: int) -> dict:
        """Renders into `out` (resuming what is there) and returns its timing.json. PLYs only: the
        sweep judges vertex radiosity, and camera views would only add time."""
        command = [self.executable, "render", self.scene, "--out", out, "--seed", str(seed),
                   "--threads", str(threads), "--no-exr", "--quiet", "--resume"] + options
        if self.animation:
            command += ["--animation", self.animation]
        # Exit 75: another render holds the folder (its lock). Array tasks all render the same
        # scene probe; the holder is rendering what this one wants, so wait and go on with
        # --resume, which then finds it done. Given up after ten minutes.
        for _ in range(1200):
            done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            if done.returncode != FOLDER_BUSY:
                break
            time.sleep(0.5)
        if done.returncode != 0:
            raise QsgiError(f"{' '.join(command)}\nexit {done.returncode}: {done.stdout.strip()}")
        with open(os.path.join(out, "timing.json")) as f:
            return json.load(f)

    def compare(self, solution: str, reference: str, radius: float) -> dict:
        command = [self.executable, "compare", solution, reference, "--radius", repr(radius), "--json"]
        done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        if done.returncode != 0:
            raise QsgiError(f"{' '.join(command)}\nexit {done.returncode}: {done.stderr.strip()}")
        return json.loads(done.stdout)

    def animation_diagonal(self, scratch: str) -> float:
        """The diagonal of the whole animation's bounds, from a one-photon impact-count probe (the
        radius grid is in fractions of it, as qsgi's default radius is). Direct light from the photons
        and no gather, explicitly: whatever qsgi's default lighting, the probe stays a moment's work."""
        timing = self.render(scratch, ["--estimator", "impact-count", "--photons", "1", "--frames", "0:0",
                                       "--direct", "photons", "--gather", "0"], 1, 1)
        return float(timing["scene"]["animation_diagonal"])
