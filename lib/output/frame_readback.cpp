#include "output/frame_readback.h"

#include "util/error.h"

namespace qsgi {

VertexRadiosityPly readFramePly(const std::string& path, size_t vertexCount) {
    VertexRadiosityPly ply = readVertexRadiosityPly(path);
    if (ply.radiosity.size() != vertexCount || ply.irradiance.size() != vertexCount)
        throw InputError(path, "",
                         ply.irradiance.empty() ? "has no irradiance (an older qsgi wrote it): render it again without --resume"
                                                : "does not hold this scene's vertices");
    return ply;
}

}  // namespace qsgi
