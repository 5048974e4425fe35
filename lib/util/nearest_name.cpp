#include "util/nearest_name.h"

#include <algorithm>

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

std::string didYouMean(const std::string& word, const std::vector<std::string>& known) {
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
    return best ? " (did you mean \"" + *best + "\"?)" : "";
}

}  // namespace qsgi
