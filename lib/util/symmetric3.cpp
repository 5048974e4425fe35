#include "util/symmetric3.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace qsgi {

std::array<double, 3> symmetricEigenvalues(const Symmetric3& m) {
    const double p1 = m[0][1] * m[0][1] + m[0][2] * m[0][2] + m[1][2] * m[1][2];
    if (p1 == 0) {
        std::array<double, 3> d{m[0][0], m[1][1], m[2][2]};
        std::sort(d.begin(), d.end(), std::greater<double>());
        return d;
    }
    const double q = (m[0][0] + m[1][1] + m[2][2]) / 3;
    const double p2 = (m[0][0] - q) * (m[0][0] - q) + (m[1][1] - q) * (m[1][1] - q) + (m[2][2] - q) * (m[2][2] - q) + 2 * p1;
    const double p = std::sqrt(p2 / 6);
    // B = (m − qI)/p; det(B)/2 = cos 3φ.
    const double b00 = (m[0][0] - q) / p, b11 = (m[1][1] - q) / p, b22 = (m[2][2] - q) / p;
    const double b01 = m[0][1] / p, b02 = m[0][2] / p, b12 = m[1][2] / p;
    const double det = b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02);
    const double phi = std::acos(std::clamp(det / 2, -1.0, 1.0)) / 3;
    const double largest = q + 2 * p * std::cos(phi);
    const double smallest = q + 2 * p * std::cos(phi + 2 * M_PI / 3);
    return {largest, 3 * q - largest - smallest, smallest};
}

double conditionNumber(const Symmetric3& m) {
    const auto e = symmetricEigenvalues(m);
    return e[2] > 0 ? e[0] / e[2] : std::numeric_limits<double>::infinity();
}

std::array<double, 3> inverseFirstRow(const Symmetric3& m) {
    const double c00 = m[1][1] * m[2][2] - m[1][2] * m[1][2];
    const double c01 = m[0][2] * m[1][2] - m[0][1] * m[2][2];
    const double c02 = m[0][1] * m[1][2] - m[0][2] * m[1][1];
    const double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    return {c00 / det, c01 / det, c02 / det};
}

}  // namespace qsgi
