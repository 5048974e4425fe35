// The envelope of the moving geometry (docs/design.md §6 step 5): boxes that hold every pose of each
// moving instance over the whole animation (Scene::sweptBoxes), dilated by a margin. A light path
// can change only from a segment that meets it: a moving triangle is hit or blocks inside it, and
// every disc an update recomputes lies inside it. Paths that never meet it are folded into the
// estimators' sums once and never searched again; the others are tracked from their first
// segment that does.
#pragma once

#include <vector>

#include "scene/scene.h"
#include "trace/ray_cache.h"

namespace qsgi {

class Envelope {
public:
    Envelope() = default;
    // Everything: every segment meets it (estimators that cannot fold, and --no-envelope).
    static Envelope everything();
    // The moving instances' swept boxes (Scene::sweptBoxes) dilated by `margin`.
    static Envelope ofAnimation(const Scene& scene, float margin);

    // Whether the segment, continued `extension` past its impact (an escaping segment: without
    // end), meets the envelope.
    bool meets(const Segment& s, float extension) const;
    // What is tracked of one path (its segments [begin, end), in bounce order): appends them from
    // the first that meets the envelope on, or nothing if none does.
    void appendTail(const Segment* begin, const Segment* end, float extension, std::vector<Segment>& out) const {
        for (const Segment* s = begin; s != end; ++s)
            if (meets(*s, extension)) {
                out.insert(out.end(), s, end);
                return;
            }
    }
    bool isEverything() const { return everything_; }
    const std::vector<Bounds3f>& boxes() const { return boxes_; }
    Bounds3f bounds() const;  // of all boxes

private:
    bool everything_ = false;
    std::vector<Bounds3f> boxes_;
    Bounds3f union_;  // of boxes_: most segments miss it, and test one box instead of several
};

// How far past its impact an estimator can count a segment, and how far from the moving geometry
// a vertex can be that the update recomputes: what the envelope's margin must cover.
// DETP: a crossing counts up to r past the impact, on a disc within r of a vertex, and a vertex
// is recomputed when its test region (r√2 around it, DiscRegions::touchedBy) meets a mover, so
// the margin is (1 + √2) r plus the regions' own slack (a margin of 2r would miss a corner of that).
// Impact count: nothing beyond the impact itself.
float envelopeMargin(bool discs, float radius, float sceneEpsilon);

}  // namespace qsgi
