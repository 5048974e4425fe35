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
    constexpr operator T() const&& noexcept;
};

template <class T, class... Fields>
constexpr auto initialisableWith(int) -> decltype(T{std::declval<Fields>()...}, true) {
    return true;
}
template <class T, class... Fields>
constexpr bool initialisableWith(long) {
    return false;
}

template <class T, class... Fields>
constexpr size_t fieldCount() {
    if constexpr (initialisableWith<T, Fields..., AnyField>(0)) return fieldCount<T, Fields..., AnyField>();
    else return sizeof...(Fields);
}

}  // namespace field_count_detail

// T must be an aggregate without base classes, C arrays or fields of reference type.
template <class T>
constexpr size_t fieldCount() {
    return field_count_detail::fieldCount<T>();
}

}  // namespace qsgi
