#include "estimate/disc_pattern.h"

#include <cmath>

namespace qsgi {

int CellMask::count() const {
    int n = 0;
    for (uint64_t w : words) n += __builtin_popcountll(w);
    return n;
}

int discCellOf(double x, double y) {
    // Rings of equal area: ring i spans ρ² in [i/R, (i+1)/R).
    const int ring = std::min(kDiscRings - 1, int((x * x + y * y) * kDiscRings));
    double phi = std::atan2(y, x);
    if (phi < 0) phi += 2 * M_PI;
    const int sector = std::min(kDiscSectors - 1, int(phi * (kDiscSectors / (2 * M_PI))));
    return ring * kDiscSectors + sector;
}

namespace {
void cellBounds(int cell, double& rho0, double& rho1, double& phi0, double& phi1) {
    const int ring = cell / kDiscSectors, sector = cell % kDiscSectors;
    rho0 = std::sqrt(double(ring) / kDiscRings);
    rho1 = std::sqrt(double(ring + 1) / kDiscRings);
    phi0 = 2 * M_PI * sector / kDiscSectors;
    phi1 = 2 * M_PI * (sector + 1) / kDiscSectors;
}

std::array<CellMoments, kDiscCells> computeMoments() {
    std::array<CellMoments, kDiscCells> table;
    for (int c = 0; c < kDiscCells; ++c) {
        double rho0, rho1, phi0, phi1;
        cellBounds(c, rho0, rho1, phi0, phi1);
        // In polar coordinates dA = ρ dρ dφ: ∫ρ^k·ρ dρ and the angular integrals are closed forms.
        const double r2 = (rho1 * rho1 - rho0 * rho0) / 2, r3 = (std::pow(rho1, 3) - std::pow(rho0, 3)) / 3,
                     r4 = (std::pow(rho1, 4) - std::pow(rho0, 4)) / 4;
        const double s0 = std::sin(phi0), s1 = std::sin(phi1), c0 = std::cos(phi0), c1 = std::cos(phi1);
        const double s20 = std::sin(2 * phi0), s21 = std::sin(2 * phi1);
        table[c] = CellMoments{r2 * (phi1 - phi0),
                               r3 * (s1 - s0),
                               r3 * (c0 - c1),
                               r4 * ((phi1 - phi0) / 2 + (s21 - s20) / 4),
                               r4 * (s1 * s1 - s0 * s0) / 2,
                               r4 * ((phi1 - phi0) / 2 - (s21 - s20) / 4)};
    }
    return table;
}
}  // namespace

void discCellCentre(int cell, double& x, double& y) {
    double rho0, rho1, phi0, phi1;
    cellBounds(cell, rho0, rho1, phi0, phi1);
    const double rho = 0.5 * (rho0 + rho1), phi = 0.5 * (phi0 + phi1);
    x = rho * std::cos(phi);
    y = rho * std::sin(phi);
}

namespace {
DiscPatternPoints computePatternPoints() {
    DiscPatternPoints p;
    for (int i = 0; i <= kDiscRings; ++i)
        for (int j = 0; j < kDiscSectors; ++j) {
            const double rho = std::sqrt(double(i) / kDiscRings), phi = 2 * M_PI * j / kDiscSectors;
            p.corners[size_t(i) * kDiscSectors + size_t(j)] = {rho * std::cos(phi), rho * std::sin(phi)};
        }
    for (int c = 0; c < kDiscCells; ++c) {
        discCellCentre(c, p.centres[size_t(c)].x, p.centres[size_t(c)].y);
        const int ring = c / kDiscSectors, sector = c % kDiscSectors;
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                const double rho = std::sqrt((ring + (i + 0.5) / 4) / kDiscRings);
                const double phi = 2 * M_PI * (sector + (j + 0.5) / 4) / kDiscSectors;
                p.subPoints[size_t(c)][size_t(4 * i + j)] = {rho * std::cos(phi), rho * std::sin(phi)};
            }
    }
    return p;
}
}  // namespace

const DiscPatternPoints& discPatternPoints() {
    static const DiscPatternPoints points = computePatternPoints();
    return points;
}

const CellMoments& discCellMoments(int cell) {
    static const std::array<CellMoments, kDiscCells> table = computeMoments();
    return table[cell];
}

double discAreaWithin(const std::array<double, kDiscRings>& ringShare, double s) {
    const double s2 = s * s;
    double area = 0;
    for (int ring = 0; ring < kDiscRings; ++ring) {
        const double lo = double(ring) / kDiscRings, hi = double(ring + 1) / kDiscRings;
        if (s2 <= lo) break;
        area += M_PI * (std::min(s2, hi) - lo) * ringShare[ring];
    }
    return area;
}

}  // namespace qsgi
