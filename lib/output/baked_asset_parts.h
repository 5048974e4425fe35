// What the parts of asset.glb's encoding (lib/output/baked_asset.cpp and the files it calls:
// glb_builder, gltf_repack, bake_groups, bake_targets, bake_animation, refined_attributes) name
// alike. Not for use beyond them.
#pragma once

#include <string>

namespace qsgi {

// Where a refusal of the asset as a whole points the user: the option that asked for it.
inline const char* const kOption = "gltf_out (--gltf-out)";

// The name of the colour set COLOR_n.
inline std::string colourName(int set) { return "COLOR_" + std::to_string(set); }

}  // namespace qsgi
