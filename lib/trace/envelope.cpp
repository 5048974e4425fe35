#include "trace/envelope.h"

#include <cmath>
#include <limits>

namespace qsgi {

Envelope Envelope::everything() {
    Envelope e;
    e.everything_ = true;
    return e;
}

Envelope Envelope::ofAnimation(const Scene& scene, float margin) {
    Envelope e;
    for (const Bounds3f& b : scene.sweptBoxes)
        if (!b.empty()) e.boxes_.push_back(b.expanded(margin));
    e.union_ = e.bounds();
    return e;
}

bool Envelope::meets(const Segment& s, float extension) const {
    if (everything_) return true;
    const double end = s.hasImpact() ? double(s.length) + double(extension) : std::numeric_limits<double>::infinity();
    if (boxes_.size() > 1 && !union_.meetsRay(s.origin, s.direction, end)) return false;
    return rayMeetsAny(boxes_, s.origin, s.direction, end);
}

Bounds3f Envelope::bounds() const {
    Bounds3f all;
    for (const Bounds3f& b : boxes_) all.extend(b);
    return all;
}

float envelopeMargin(bool discs, float radius, float sceneEpsilon) {
    const float slack = 16 * sceneEpsilon;
    return discs ? (1 + float(M_SQRT2)) * radius * 1.001f + slack : slack;
}

}  // namespace qsgi
