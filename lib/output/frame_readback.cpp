#include "output/frame_readback.h"

#include "output/folder_survey.h"
#include "output/output_directory.h"
#include "util/error.h"

namespace qsgi {

VertexRadiosityPly readFramePly(const OutputDirectory& folder, int frame, const Scene& scene) {
    const std::string path = (folder.path() / frameFileName(frame, "ply")).string();
    VertexRadiosityPly ply = readVertexRadiosityPly(path);
    const size_t vertexCount = scene.frontVertexCount();
    if (ply.radiosity.size() != vertexCount || ply.irradiance.size() != vertexCount)
        throw InputError(path, "",
                         ply.irradiance.empty() ? "has no irradiance (an older qsgi wrote it): render it again without --resume"
                                                : "does not hold this scene's vertices");
    if (scene.backSides.has_value() != !ply.backRadiosity.empty())
        throw InputError(path, "",
                         scene.backSides ? "has no back-side values, which this scene's doubleSided surfaces have (an older qsgi "
                                           "wrote it): render it again without --resume"
                                         : "has back-side values, which this scene has no doubleSided surface for");
    return ply;
}

}  // namespace qsgi
