#include "estimate/vertex_radiosity.h"

#include "trace/sampling.h"

namespace qsgi {

void computeRadiosity(const Scene& scene, VertexRadiosity& result) {
    result.radiosity.resize(result.irradiance.size());
    for (size_t v = 0; v < result.irradiance.size(); ++v) {
        const Material& m = scene.materials[scene.vertexMaterial[v]];
        result.radiosity[v] = m.albedo * result.irradiance[v] + m.emission * kPi;
    }
}

}  // namespace qsgi
