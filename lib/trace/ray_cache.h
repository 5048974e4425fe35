// The ray cache (DESIGN §4): every segment of every photon path, grouped by path so that "path i
// from bounce k on" is one contiguous range.
#pragma once

#include <cstdint>
#include <vector>

#include "util/vecmath.h"

namespace qsgi {

constexpr uint32_t kNoTriangle = 0xFFFFFFFFu;

struct Segment {
    Vec3f origin;
    Vec3f direction;    // unit
    float length = 0;   // to the impact; for an escaping photon, to where it leaves the scene bounds
    Vec3f power;        // W, RGB, carried along this segment
    uint32_t triangle = kNoTriangle;  // impacted triangle, or kNoTriangle if the photon escaped
    uint32_t path = 0;
    uint16_t bounce = 0;
    uint8_t impactDynamic = 0;        // impacted dynamic geometry

    bool hasImpact() const { return triangle != kNoTriangle; }
    Vec3f impactPoint() const { return origin + direction * length; }
};

struct RayCache {
    std::vector<Segment> segments;
    std::vector<uint64_t> pathBegin;  // path i owns segments [pathBegin[i], pathBegin[i+1])
    // Largest RGB component any photon starts with: the scale of fixed-point power sums.
    float maxPhotonPower = 0;

    size_t pathCount() const { return pathBegin.empty() ? 0 : pathBegin.size() - 1; }

    // Photons whose first segment hit nothing (lights pointing away from, or far from, the scene),
    // and photons with no segment (an aimed spot light's outside its cone).
    uint64_t pathsMissingScene() const {
        uint64_t missed = 0;
        for (size_t path = 0; path < pathCount(); ++path)
            if (pathBegin[path] == pathBegin[path + 1] || !segments[pathBegin[path]].hasImpact()) ++missed;
        return missed;
    }
};

}  // namespace qsgi
