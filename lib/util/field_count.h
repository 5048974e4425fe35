// The number of fields of an aggregate, at compile time: the most initialisers `T{...}` accepts,
// each a value that converts to any type (the technique of Boost.PFR). It lets a static_assert
// beside a list that must cover a struct's fields (render_options.cpp: every setting has an
// option) fail by itself when a field is added, without a second, hand-kept list of names.
#pragma once

#include <cstddef>
#include <utility>

namespace qsgi {
namespace field_count_detail {

// Converts to any field's type; only ever named in unevaluated contexts. The rvalue ref-qualifier
// makes it lose, rather than tie, against a field type's own converting constructor template
// (std::optional's), so that such a field still counts once.
struct AnyField {
    template <class T>
    operator T() const&&;
};

// Whether T{AnyField × N} compiles. N is tried from kMostFields down, so the first that compiles
// initialises every field (trying 1, 2, … would name aggregates with fields left out, which
// clang's -Wmissing-field-initializers reports even here).
template <class T, size_t... I>
constexpr auto initialisableWith(std::index_sequence<I...>, int) -> decltype(T{(void(I), std::declval<AnyField>())...}, true) {
    return true;
}
template <class T, size_t... I>
constexpr bool initialisableWith(std::index_sequence<I...>, long) {
    return false;
}

constexpr size_t kMostFields = 64;

template <class T, size_t N>
constexpr size_t fieldCountFrom() {
    if constexpr (N == 0) return 0;
    else if constexpr (initialisableWith<T>(std::make_index_sequence<N>{}, 0)) return N;
    else return fieldCountFrom<T, N - 1>();
}

}  // namespace field_count_detail

// T must be an aggregate without base classes, C arrays or fields of reference type.
template <class T>
constexpr size_t fieldCount() {
    constexpr size_t count = field_count_detail::fieldCountFrom<T, field_count_detail::kMostFields>();
    static_assert(count < field_count_detail::kMostFields, "more fields than fieldCount can count");
    return count;
}

}  // namespace qsgi
