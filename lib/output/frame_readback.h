// A frame's PLY read back for a whole-run file (asset.glb, asset.usda), which a resumed run or the
// Slurm merge's finishing run makes from frames other runs wrote: one check that the file holds
// this scene's frame, and one rule for the radiance a bake shows.
#pragma once

#include <cmath>
#include <string>

#include "output/ply_reader.h"
#include "util/vecmath.h"

namespace qsgi {

// B/π (W m⁻² sr⁻¹), the radiance of a Lambertian surface of radiosity B: what a bake shows
// (asset.glb's _RADIANCE, asset.usda's radiance).
inline Vec3f bakedRadiance(const Vec3f& radiosity) { return radiosity * float(1 / M_PI); }

class OutputDirectory;

// Frame `frame`'s PLY in the folder. Throws InputError naming it unless it holds the scene's
// (front) vertices with irradiance (an older qsgi wrote none), and back-side values exactly when
// the scene has back sides (lib/scene/back_sides.h; an older qsgi wrote none).
VertexRadiosityPly readFramePly(const OutputDirectory& folder, int frame, const Scene& scene);

}  // namespace qsgi
