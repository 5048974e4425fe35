#include "pipeline/animation_source.h"

#include <optional>

#include "util/input_file.h"
#include "util/json_file.h"

namespace qsgi {

AnimationSource AnimationSource::resolve(const RenderSettings& settings) {
    AnimationSource source;
    const std::string& option = settings.animationPath;
    if (option.empty()) return source;
    const std::optional<int> gltf = gltfAnimationSelector(option, settings.configPath.empty() ? "command line" : settings.configPath);
    if (gltf) {
        source.kind_ = Kind::Gltf;
        source.gltfIndex_ = *gltf;
        source.name_ = settings.scenePath + " (--animation " + option + ")";
        return source;
    }
    source.kind_ = Kind::TransformFile;
    source.path_ = option;
    source.name_ = option;
    source.bytes_ = readInputFile(option, kMaxJsonFileBytes, "a transform file");
    return source;
}

Animation AnimationSource::load(const Scene& scene, double fps) const {
    switch (kind_) {
    case Kind::Still: return Animation::still(scene);
    case Kind::Gltf: return Animation::fromGltf(scene, gltfIndex_, fps, name_);
    case Kind::TransformFile: break;
    }
    return Animation::fromTransformFileBytes(path_, bytes_, scene);
}

int AnimationSource::playedGltfAnimation(const Scene& scene) const {
    if (!gltf()) return -1;
    return gltfIndex_ >= 0 ? gltfIndex_ : scene.animations.size() == 1 ? 0 : -1;
}

std::string AnimationSource::fingerprintBytes(const Scene& scene) const {
    if (transformFile()) return bytes_;
    std::string bytes;
    if (!gltf()) return bytes;
    auto append = [&](const void* data, size_t size) { bytes.append(static_cast<const char*>(data), size); };
    append(&gltfIndex_, sizeof(int));
    for (size_t a = 0; a < scene.animations.size(); ++a) {
        if (gltfIndex_ >= 0 && size_t(gltfIndex_) != a) continue;
        for (const AnimationChannel& channel : scene.animations[a].channels) {
            const int64_t header[6] = {channel.node, int64_t(channel.property), int64_t(channel.track.interpolation),
                                       channel.track.components, int64_t(channel.track.times.size()),
                                       int64_t(channel.track.values.size())};
            append(header, sizeof header);
            append(channel.track.times.data(), sizeof(double) * channel.track.times.size());
            append(channel.track.values.data(), sizeof(double) * channel.track.values.size());
        }
    }
    return bytes;
}

}  // namespace qsgi
