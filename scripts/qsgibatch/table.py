"""sweep.csv: one row per grid point with every parameter and figure, in a fixed column order."""
import csv
import io
import math
import os

from .output_folder import open_folder, write_file

COLUMNS = [
    # parameters
    "family", "estimator", "sampler", "qmc_bounces", "direct", "gather", "direct_samples", "photons", "radius_fraction",
    "radius", "k", "full_recompute", "frames", "seed", "noise_seed",
    # error against the reference at frame 0 (relative to the reference's mean; bias signed)
    "rms_all", "bias_all", "rms_edge", "bias_edge", "rms_near_edge", "bias_near_edge", "rms_interior",
    "bias_interior", "noise", "edge_radius", "vertices_all", "vertices_edge", "vertices_near_edge",
    "vertices_interior",
    # over the surface (with "surface_reference"): frame 0's irradiance interpolated across its
    # triangles at the reference's points, by band, and the reference's own noise
    "surface_rms_all", "surface_rms_all_without_noise", "surface_reference_noise", "surface_rms_contact",
    "surface_rms_edge", "surface_rms_interior", "surface_points_all", "surface_points_contact", "surface_points_edge",
    "surface_points_interior",
    # stability
    "nan_count", "inf_count",
    # time (seconds, from timing.json; frame = photon update + density estimation + the second pass:
    # exact direct light and the gather, 0 under direct light from the photons)
    "initial_s", "initial_photon_s", "initial_estimation_s", "initial_direct_s", "initial_gather_s",
    "median_frame_s", "median_photon_update_s", "median_estimation_s", "median_direct_s", "median_gather_s",
    "wall_s",
    # work
    "segments", "photons_missing_scene", "tracked_bytes_per_segment",
    # how the figures were taken
    "threads", "jobs", "shared_cores", "other_cores", "reference", "qsgi_version",
]


def _cell(value):
    if isinstance(value, float):
        return "" if math.isnan(value) else repr(value)
    return value


def write(path: str, results: list) -> None:
    """Writes the rows atomically (a reader never sees half a table) and through no link planted at
    the name or its temporary (output_folder.write_file replaces it)."""
    text = io.StringIO(newline="")
    writer = csv.DictWriter(text, fieldnames=COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for r in results:
        writer.writerow({c: _cell(r.get(c, math.nan)) for c in COLUMNS})
    folder_fd = open_folder(os.path.dirname(path) or ".")
    try:
        write_file(folder_fd, os.path.basename(path), text.getvalue().encode())
    finally:
        os.close(folder_fd)


def read(path: str) -> list:
    """Rows with numbers as floats (empty cells as NaN) and booleans as bool."""
    rows = []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            parsed = {}
            for key, value in row.items():
                if value in ("True", "False"):
                    parsed[key] = value == "True"
                else:
                    try:
                        parsed[key] = float(value) if value != "" else math.nan
                    except ValueError:
                        parsed[key] = value
            rows.append(parsed)
    return rows
