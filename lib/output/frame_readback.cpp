#include "output/frame_readback.h"

#include "output/folder_survey.h"
#include "output/output_directory.h"
#include "util/error.h"

namespace qsgi {

VertexRadiosityPly readFramePly(const OutputDirectory& folder, int frame, size_t vertexCount) {
    const std::string path = (folder.path() / frameFileName(frame, "ply")).string();
    VertexRadiosityPly ply = readVertexRadiosityPly(path);
    if (ply.radiosity.size() != vertexCount || ply.irradiance.size() != vertexCount)
        throw InputError(path, "",
                         ply.irradiance.empty() ? "has no irradiance (an older qsgi wrote it): render it again without --resume"
                                                : "does not hold this scene's vertices");
    return ply;
}

}  // namespace qsgi
