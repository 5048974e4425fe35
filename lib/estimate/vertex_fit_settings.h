// How each output vertex's value is chosen (--vertex-fit; lib/estimate/vertex_fit.h): its own
// irradiance (point sampling, the paper's and every baking tool's), or the values whose linear
// interpolation across the triangles is closest to the irradiance sampled over them.
#pragma once

#include "util/enum_names.h"

namespace qsgi {

enum class VertexFitKind { Point, LeastSquares };
inline constexpr NamedValue<VertexFitKind> kVertexFitNames[] = {{VertexFitKind::Point, "point"},
                                                                {VertexFitKind::LeastSquares, "least-squares"}};

}  // namespace qsgi
