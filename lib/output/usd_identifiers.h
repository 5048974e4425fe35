// Prim names for asset.usda from the glTF's node, mesh and material names. A USD prim name is an
// identifier, [A-Za-z_][A-Za-z0-9_]* (ASCII: OpenUSD before 24.03, and the tools built on it, accept no more),
// unique among its siblings; glTF names are any UTF-8 text, empty, or repeated.
#pragma once

#include <string>
#include <unordered_set>

namespace qsgi {

// `name` as an identifier: every character outside [A-Za-z0-9_] (each byte of a non-ASCII one)
// becomes '_', and a leading digit is preceded by '_'. An empty name gives `fallback`.
std::string usdIdentifier(const std::string& name, const std::string& fallback);

// Names among one prim's children: the first claim of an identifier keeps it; later ones get _1,
// _2, … (the first such name not taken, by a claim or by a name that was already so suffixed).
class UniqueNames {
public:
    std::string claim(const std::string& identifier);

private:
    std::unordered_set<std::string> taken_;
};

}  // namespace qsgi
