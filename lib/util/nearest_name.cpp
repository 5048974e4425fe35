#include "util/nearest_name.h"

#include <algorithm>
#include <cctype>

namespace qsgi {

size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diagonal = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            const size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

namespace {

// "photon_count", "--photon-count", "photonCount" -> {"photon", "count"}: lower-case words split at
// anything that is not a letter or digit and where a lower-case letter meets an upper-case one.
std::vector<std::string> wordsOf(const std::string& name) {
    std::vector<std::string> words(1);
    for (size_t i = 0; i < name.size(); ++i) {
        const unsigned char c = static_cast<unsigned char>(name[i]);
        if (!std::isalnum(c)) {
            if (!words.back().empty()) words.emplace_back();
            continue;
        }
        if (std::isupper(c) && i > 0 && std::islower(static_cast<unsigned char>(name[i - 1])) && !words.back().empty())
            words.emplace_back();
        words.back() += char(std::tolower(c));
    }
    if (words.back().empty()) words.pop_back();
    return words;
}

// Two words name the same thing: equal, one begins the other ("photon", "photons"; "out",
// "output") or ends it ("photons", "totalphotons"), the shorter of at least 3 letters, or one
// slip apart in words of at least 5 letters ("bounce", "bounse").
bool sameWord(const std::string& a, const std::string& b) {
    if (a == b) return true;
    const std::string& shorter = a.size() < b.size() ? a : b;
    const std::string& longer = a.size() < b.size() ? b : a;
    if (shorter.size() >= 3 && (longer.compare(0, shorter.size(), shorter) == 0 ||
                                longer.compare(longer.size() - shorter.size(), shorter.size(), shorter) == 0))
        return true;
    return shorter.size() >= 5 && editDistance(a, b) <= 1;
}

}  // namespace

std::string didYouMean(const std::string& word, const std::vector<std::string>& known) {
    // A misspelling: within a third of the word's length (at least 2 edits).
    const size_t limit = std::max<size_t>(2, word.size() / 3);
    const std::string* best = nullptr;
    size_t bestDistance = limit + 1;
    for (const std::string& name : known) {
        const size_t d = editDistance(word, name);
        if (d < bestDistance) {
            bestDistance = d;
            best = &name;
        }
    }
    // Else a name put in other words: the known name sharing the most words with it
    // ("photon_count" -> "photons", "num_threads" -> "threads"), then the one with the fewest
    // words of its own left over, then the closest.
    if (!best) {
        const std::vector<std::string> words = wordsOf(word);
        size_t bestShared = 0, bestLeftOver = 0;
        for (const std::string& name : known) {
            const std::vector<std::string> theirs = wordsOf(name);
            size_t shared = 0;
            for (const std::string& t : theirs)
                shared += std::any_of(words.begin(), words.end(), [&](const std::string& w) { return sameWord(w, t); });
            if (shared == 0) continue;
            const size_t leftOver = theirs.size() - shared, d = editDistance(word, name);
            if (!best || shared > bestShared || (shared == bestShared && leftOver < bestLeftOver) ||
                (shared == bestShared && leftOver == bestLeftOver && d < bestDistance)) {
                best = &name;
                bestShared = shared;
                bestLeftOver = leftOver;
                bestDistance = d;
            }
        }
    }
    return best ? " (did you mean \"" + *best + "\"?)" : "";
}

}  // namespace qsgi
