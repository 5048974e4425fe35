// Fixed-point sums of photon power. Integer addition is associative, so a vertex's sum is the
// same bits whatever order threads add in, and "+ new - old" in the incremental update is exact
// (docs/design.md §6.7; floating-point sums would depend on the order threads add in).
#pragma once

#include <cmath>
#include <cstdint>

#include "util/vecmath.h"

namespace qsgi {

class PowerQuantizer {
public:
    // maxPhotonPower: the largest RGB component a photon starts with. Russian roulette never
    // raises a component above it (ρ_c / max ρ ≤ 1), so 2^31 quanta cover any one segment and
    // an int64 sum holds 2^32 segments.
    explicit PowerQuantizer(float maxPhotonPower)
        : quantum_(maxPhotonPower > 0 ? double(maxPhotonPower) * 0x1p-31 : 1.0) {}

    int64_t quantize(float power) const { return std::llround(double(power) / quantum_); }
    double quantum() const { return quantum_; }

private:
    double quantum_;
};

struct PowerSum {
    int64_t r = 0, g = 0, b = 0;

    void add(const Vec3f& power, const PowerQuantizer& q) {
        r += q.quantize(power.x);
        g += q.quantize(power.y);
        b += q.quantize(power.z);
    }
    void subtract(const Vec3f& power, const PowerQuantizer& q) {
        r -= q.quantize(power.x);
        g -= q.quantize(power.y);
        b -= q.quantize(power.z);
    }
    PowerSum& operator+=(const PowerSum& o) { r += o.r; g += o.g; b += o.b; return *this; }
    Vec3d watts(const PowerQuantizer& q) const { return Vec3d(double(r), double(g), double(b)) * q.quantum(); }
};

}  // namespace qsgi
