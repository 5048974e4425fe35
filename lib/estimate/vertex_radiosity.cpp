#include "estimate/vertex_radiosity.h"

#include "scene/emission_pieces.h"
#include "scene/surface_lookup.h"
#include "trace/sampling.h"

namespace qsgi {

void computeRadiosity(const Scene& scene, VertexRadiosity& result) {
    result.radiosity.resize(result.irradiance.size());
    for (size_t v = 0; v < result.irradiance.size(); ++v) {
        // A hidden vertex (zero scale, docs/design.md §3) shows nothing, whatever its estimator found at
        // the point it was collapsed to; it is recomputed when it moves back into view.
        if (scene.vertexHidden[v]) {
            result.irradiance[v] = result.radiosity[v] = Vec3f(0.0f);
            continue;
        }
        result.radiosity[v] = vertexAlbedo(scene, uint32_t(v)) * result.irradiance[v] + vertexEmission(scene, uint32_t(v)) * kPi;
    }
}

}  // namespace qsgi
