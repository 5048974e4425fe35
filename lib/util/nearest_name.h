// "Did you mean …?" for unknown keys and names: the known name closest to a misspelt one.
#pragma once

#include <string>
#include <vector>

namespace qsgi {

// Levenshtein distance (insertions, deletions, substitutions), case-sensitive.
size_t editDistance(const std::string& a, const std::string& b);

// ` (did you mean "photons"?)` when a known name is within a third of the word's length (at
// least 2 edits) of `word`, else "". Ties go to the earlier name in `known`.
std::string didYouMean(const std::string& word, const std::vector<std::string>& known);

}  // namespace qsgi
