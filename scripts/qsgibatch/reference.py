"""The reference a sweep's errors are measured against.

Either the committed PLY the config names (an independent renderer's), or one built once and
cached in OUT/reference/: the per-vertex mean of several seeds of DETP `linear` at the smallest
radius of the accuracy grid, each at the photon count the config states (reference_build), with
all light from the photons and no gather (the paper's method, given explicitly: a cached
reference keeps its meaning whatever qsgi's defaults become). The recipe is written beside it
(reference.json) and into every CSV row."""
import json
import os

import numpy as np

from . import output_folder, ply


def _describe_build(build: dict) -> str:
    return (f"built: mean of {len(build['seeds'])} seeds ({', '.join(map(str, build['seeds']))}) of detp:linear "
            f"at r = {build['radius_fraction']:g} of the diagonal, {build['photons']} photons each")


def prepare(config, qsgi, out: str, diagonal: float, threads: int) -> tuple:
    """Returns (reference PLY path, description). Builds the reference if the config names none."""
    if config.reference:
        return config.reference, f"committed: {os.path.relpath(config.reference, os.path.dirname(config.path))}"
    build = config.reference_build
    folder = os.path.join(out, "reference")
    recipe_path, reference_path = os.path.join(folder, "reference.json"), os.path.join(folder, "reference.ply")
    recipe = dict(build, scene=config.scene, animation=config.animation, diagonal=diagonal)
    if os.path.exists(reference_path) and os.path.exists(recipe_path):
        with open(recipe_path) as f:
            if json.load(f) == recipe:
                return reference_path, _describe_build(build)
    # A real folder, never a link planted at OUT/reference; its files written as every output is.
    output_folder.make_subfolder(out, "reference")
    options = ["--estimator", "detp", "--detp-boundary", "linear", "--photons", str(build["photons"]),
               "--radius", repr(build["radius_fraction"] * diagonal), "--frames", "0:0", "--direct", "photons",
               "--gather", "0"]
    runs = []
    for seed in build["seeds"]:
        run = os.path.join(folder, f"seed_{seed}")
        qsgi.render(run, options, seed, threads)
        runs.append(ply.read(os.path.join(run, "frame_0000.ply")))
    mean = np.mean([r.radiosity() for r in runs], axis=0)
    folder_fd = output_folder.open_folder(folder)
    try:
        output_folder.write_file(folder_fd, "reference.ply", ply.with_radiosity(runs[0], mean))
        output_folder.write_file(folder_fd, "reference.json", json.dumps(recipe, indent=1).encode())
    finally:
        os.close(folder_fd)
    return reference_path, _describe_build(build)
