// Small dense linear algebra for 3×3 symmetric matrices: eigenvalues (closed form) and the first
// row of the inverse, as DETP's linear boundary fit needs them.
#pragma once

#include <array>

namespace qsgi {

// Row-major symmetric 3×3 matrix; only m[i][j] with i ≤ j need be consistent.
using Symmetric3 = std::array<std::array<double, 3>, 3>;

// Eigenvalues, largest first (Smith's trigonometric method).
std::array<double, 3> symmetricEigenvalues(const Symmetric3& m);

// 2-norm condition number λ_max / λ_min for a positive semi-definite matrix (infinity if λ_min ≤ 0).
double conditionNumber(const Symmetric3& m);

// First row of m⁻¹ (m invertible): the weights that give the first unknown of m·x = b.
std::array<double, 3> inverseFirstRow(const Symmetric3& m);

}  // namespace qsgi
