// Reads the vertex data of a qsgi frame_NNNN.ply back (binary little-endian; properties found by
// name, any PLY scalar type), for comparisons and tools.
#pragma once

#include <string>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

struct VertexRadiosityPly {
    std::vector<Vec3f> positions, normals, radiosity;
};

// Throws InputError naming the file for anything it cannot read.
VertexRadiosityPly readVertexRadiosityPly(const std::string& path);

}  // namespace qsgi
