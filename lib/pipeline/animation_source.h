// Where a run's animation comes from (--animation), worked out once from the option: nothing (a
// still scene), a transform file, or the scene file's own glTF animations ("gltf": all at once,
// "gltf:N": one). The rest of the run asks this, never the option's string again.
#pragma once

#include <string>

#include "pipeline/render_settings.h"
#include "scene/animation.h"
#include "scene/scene.h"

namespace qsgi {

class AnimationSource {
public:
    enum class Kind { Still, TransformFile, Gltf };

    // From the settings' --animation (and its config file, for messages). A transform file is read
    // here, once (the opening rule, util/input_file.h): the parser and the run's fingerprint read
    // these bytes. Throws InputError for
    // "gltf:" without a valid index and for a transform file that cannot be read.
    static AnimationSource resolve(const RenderSettings& settings);

    Kind kind() const { return kind_; }
    bool still() const { return kind_ == Kind::Still; }
    bool transformFile() const { return kind_ == Kind::TransformFile; }
    bool gltf() const { return kind_ == Kind::Gltf; }
    // Kind::Gltf: the animation played, -1 for all at once.
    int gltfIndex() const { return gltfIndex_; }
    // As messages name it: the transform file's path, or "scene.gltf (--animation gltf:1)"; "" when still.
    const std::string& name() const { return name_; }

    // The animation, for the loaded scene (glTF animations sampled at `fps`). Throws InputError.
    Animation load(const Scene& scene, double fps) const;
    // The glTF animation the frames show, as asset.glb records it: the one played, or the only
    // one there is when "gltf" plays them all; -1 otherwise (none, or several at once).
    int playedGltfAnimation(const Scene& scene) const;
    // What the run's fingerprint digests of the animation: the transform file's bytes, or for a
    // glTF animation the keyframes the run samples (the fps is among the fingerprinted options);
    // "" when still. Their size is the file's, not the frame count's.
    std::string fingerprintBytes(const Scene& scene) const;

private:
    Kind kind_ = Kind::Still;
    int gltfIndex_ = -1;
    std::string path_;   // the transform file's
    std::string name_;
    std::string bytes_;  // the transform file's, read once: parsed by load(), digested by fingerprintBytes()
};

}  // namespace qsgi
