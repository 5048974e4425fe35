"""Reads and writes the vertex-radiosity PLY files qsgi writes (binary little-endian; docs/design.md §7).

Only what sweeps need: the vertex table as a numpy record array, and a copy of a file with other
radiosity values (the averaged reference). The header and the face list are kept as bytes, so a
written file differs from its template only in the radiosity columns."""
import os

import numpy as np

_PLY_TYPES = {"char": "i1", "uchar": "u1", "short": "<i2", "ushort": "<u2", "int": "<i4", "uint": "<u4",
              "float": "<f4", "double": "<f8"}


class VertexPly:
    def __init__(self, header: bytes, vertices: np.ndarray, rest: bytes):
        self.header, self.vertices, self.rest = header, vertices, rest

    def radiosity(self) -> np.ndarray:
        """(n, 3) float64 radiosity B in W/m²."""
        v = self.vertices
        return np.stack([v["radiosity_r"], v["radiosity_g"], v["radiosity_b"]], axis=1).astype(np.float64)

    def irradiance(self) -> np.ndarray:
        """(n, 3) float64 irradiance E in W/m² (qsgi writes it since issue 35)."""
        v = self.vertices
        if "irradiance_r" not in v.dtype.names:
            raise ValueError("the PLY holds no irradiance (an older qsgi wrote it)")
        return np.stack([v["irradiance_r"], v["irradiance_g"], v["irradiance_b"]], axis=1).astype(np.float64)

    def triangles(self) -> np.ndarray:
        """(T, 3) int64 vertex indices of the face list qsgi writes (`list uchar int`, triangles)."""
        if b"element face" not in self.header:
            return np.zeros((0, 3), np.int64)
        count = int(self.header.split(b"element face ")[1].split(b"\n")[0])
        faces = np.frombuffer(self.rest, np.dtype([("n", "u1"), ("v", "<i4", (3,))]), count)
        if (faces["n"] != 3).any():
            raise ValueError("a face that is not a triangle")
        return faces["v"].astype(np.int64)


def _first_table(path, element):
    """(header bytes, the records of `element` — the file's first element, fixed-size properties —
    or None when the file has no such element, the bytes after them)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header\n")
    if not data.startswith(b"ply\n") or end < 0:
        raise ValueError(f"{path}: not a PLY file")
    header = data[:end + len(b"end_header\n")]
    lines = header.decode("ascii").splitlines()
    if "format binary_little_endian 1.0" not in lines:
        raise ValueError(f"{path}: not a binary little-endian PLY")
    fields, count, inside = [], None, False
    for line in lines:
        words = line.split()
        if words[:2] == ["element", element]:
            count, inside = int(words[2]), True
        elif words[:1] == ["element"]:
            inside = False
        elif inside and words[:1] == ["property"]:
            if words[1] == "list" or words[1] not in _PLY_TYPES:
                raise ValueError(f"{path}: unsupported {element} property '{line}'")
            fields.append((words[2], _PLY_TYPES[words[1]]))
    if count is None:
        return header, None, b""
    dtype = np.dtype(fields)
    start = len(header)
    if len(data) < start + count * dtype.itemsize:
        raise ValueError(f"{path}: truncated {element} table")
    records = np.frombuffer(data, dtype=dtype, count=count, offset=start).copy()
    return header, records, data[start + count * dtype.itemsize:]


def read(path) -> VertexPly:
    header, vertices, rest = _first_table(path, "vertex")
    if vertices is None or "radiosity_r" not in vertices.dtype.names:
        raise ValueError(f"{path}: no vertex radiosity (not written by qsgi?)")
    return VertexPly(header, vertices, rest)


def read_points(path) -> np.ndarray:
    """The `point` element of a surface reference (scripts/reference.py --surface) as a record array."""
    _, points, _ = _first_table(path, "point")
    if points is None:
        raise ValueError(f"{path}: no 'point' element (not a surface reference)")
    return points


def with_radiosity(template: VertexPly, radiosity: np.ndarray) -> bytes:
    """The bytes of `template` with its radiosity replaced (output_folder.write_file writes them)."""
    vertices = template.vertices.copy()
    for c, name in enumerate(("radiosity_r", "radiosity_g", "radiosity_b")):
        vertices[name] = radiosity[:, c]
    return template.header + vertices.tobytes() + template.rest


def count_non_finite(path) -> tuple:
    """(NaN count, Inf count) over the radiosity and position columns of one PLY."""
    v = read(path).vertices
    columns = [v[name].astype(np.float64) for name in ("x", "y", "z", "radiosity_r", "radiosity_g", "radiosity_b")]
    values = np.concatenate(columns)
    return int(np.isnan(values).sum()), int(np.isinf(values).sum())
