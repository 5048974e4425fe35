// glTF 2.0 rules about how objects refer to each other, checked on the JSON for every object of
// the document: every index names an object that exists, arrays the specification says must not
// be empty are not, a camera has the one projection its type names, and a punctual light's range,
// where given, is positive (tinygltf reads an absent range as 0). tinygltf reads such files
// without a word (a texture naming image 7 of 2 is kept as is), so they are found here and
// returned, not thrown: the loader refuses those in objects the render reads and warns about the
// others (the contract of docs/inputs.md), since only it knows which objects it read.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace qsgi {

struct GltfFinding {
    std::string object;   // the top-level object it is in ("nodes[3]"), "" for the document itself
    std::string place;    // where exactly ("nodes[3].mesh")
    std::string problem;  // what is wrong, in words
};

std::vector<GltfFinding> findReferenceProblems(const nlohmann::json& doc);

}  // namespace qsgi
