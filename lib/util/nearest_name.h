// "Did you mean …?" for unknown keys and names: the known name closest to a misspelt one.
#pragma once

#include <string>
#include <vector>

namespace qsgi {

// Levenshtein distance (insertions, deletions, substitutions), case-sensitive.
size_t editDistance(const std::string& a, const std::string& b);

// ` (did you mean "photons"?)` when a known name is within a third of the word's length (at
// least 2 edits) of `word` (a misspelling); else, when some known names share words with it (a
// name put in other words: "photon_count", "num_photons", "--photon-count", "photonCount" ->
// "photons"; words are split at non-alphanumerics and camelCase, and match when equal or when
// one begins or ends the other), the one sharing the most, then with the fewest words of its
// own left over, then the closest; else "". Ties go to the earlier name in `known`.
std::string didYouMean(const std::string& word, const std::vector<std::string>& known);

}  // namespace qsgi
