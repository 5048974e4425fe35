// Growing the long-lived stores of the incremental update (tracked segments, their grid, DETP's
// remembered crossings) by a quarter instead of std::vector's doubling: those stores hold most of
// a long run's memory, a doubling leaves up to half of one unused, and they grow a little every
// frame. Appends stay amortised O(1) (geometric growth, ratio 1.25).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace qsgi {

// Room for `extra` more elements, growing by at least a quarter when it must grow.
template <typename T>
void reserveModestly(std::vector<T>& v, size_t extra) {
    const size_t need = v.size() + extra;
    if (need > v.capacity()) v.reserve(std::max(need, v.capacity() + v.capacity() / 4 + 4));
}

// By value: `value` may be an element of v, which the growth moves.
template <typename T>
void pushBackModestly(std::vector<T>& v, T value) {
    reserveModestly(v, 1);
    v.push_back(value);
}

}  // namespace qsgi
