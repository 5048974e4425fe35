// Reads the vertex data of a qsgi frame_NNNN.ply back (binary little-endian; properties found by
// name, any PLY scalar type), for comparisons and tools.
#pragma once

#include <string>
#include <vector>

#include "estimate/surface_accuracy.h"
#include "scene/scene.h"
#include "util/vecmath.h"

namespace qsgi {

class InputFile;

struct VertexRadiosityPly {
    std::vector<Vec3f> positions, normals, radiosity;
    std::vector<Vec3f> irradiance;    // empty when the file has none (written before issue 35)
    // The back sides of doubleSided surfaces (back_radiosity_*, back_irradiance_*): empty when the
    // file has none (a scene without such surfaces, or written before issue 57).
    std::vector<Vec3f> backRadiosity, backIrradiance;
    std::vector<Triangle> triangles;  // from `element face` (polygons fanned), if present
    // A reference of a vertex subset (scripts/reference.py --vertices N) flags the vertices it
    // computed in a `referenced` property; empty when the file has none (every vertex counts).
    std::vector<uint8_t> referenced;
};

// Throws InputError naming the file for anything it cannot read. The file is opened once, under
// the one opening rule (util/input_file.h), and read as a stream: its rows are not held twice.
VertexRadiosityPly readVertexRadiosityPly(const std::string& path);
// The same from a file already open (after plyFirstElement, say): it is read from its start.
VertexRadiosityPly readVertexRadiosityPly(InputFile& file);

// A surface reference (scripts/reference.py --surface N): `element point N` (N ≥ 1) with the
// properties SurfacePoint holds: int triangle, float b1 b2 x y z nx ny nz irradiance_r/g/b
// stderr_r/g/b, uchar hidden. `qsgi compare` finds each point on the frame by x y z and the normal
// (surface_accuracy.h); the triangle and barycentrics are checked, and read by the scripts.
struct SurfaceReferencePly {
    std::vector<SurfacePoint> points;
};
SurfaceReferencePly readSurfaceReferencePly(const std::string& path);
SurfaceReferencePly readSurfaceReferencePly(InputFile& file);

// The name of a PLY's first element ("vertex", "point"), or "" if it is not a PLY header: which
// of the two readers a file is for. Reads the open file's header, which the reader then reads
// again from the same descriptor.
std::string plyFirstElement(InputFile& file);

}  // namespace qsgi
