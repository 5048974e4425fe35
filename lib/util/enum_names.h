// One table of names per enum, read both ways: the name a value is written as (timing.json, EXR
// metadata, messages) and the value a name in a config or on the command line means. Declared
// once beside the enum, so a writer and a reader can never disagree.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace qsgi {

template <class E>
struct NamedValue {
    E value;
    const char* name;
};

template <class E, size_t N>
const char* nameOf(const NamedValue<E> (&table)[N], E value) {
    for (const NamedValue<E>& entry : table)
        if (entry.value == value) return entry.name;
    return "?";
}

template <class E, size_t N>
std::optional<E> valueNamed(const NamedValue<E> (&table)[N], const std::string& name) {
    for (const NamedValue<E>& entry : table)
        if (name == entry.name) return entry.value;
    return std::nullopt;
}

template <class E, size_t N>
std::vector<std::string> namesOf(const NamedValue<E> (&table)[N]) {
    std::vector<std::string> names;
    for (const NamedValue<E>& entry : table) names.push_back(entry.name);
    return names;
}

}  // namespace qsgi
