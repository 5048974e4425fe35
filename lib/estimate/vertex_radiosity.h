// The per-vertex result of density estimation: irradiance E and radiosity B = ρE + πL_e
// (docs/design.md §2), both W/m^2, RGB.
#pragma once

#include <vector>

#include "scene/scene.h"

namespace qsgi {

struct VertexRadiosity {
    std::vector<Vec3f> irradiance;
    std::vector<Vec3f> radiosity;
};

// Fills radiosity from irradiance with each vertex's material.
void computeRadiosity(const Scene& scene, VertexRadiosity& result);

}  // namespace qsgi
