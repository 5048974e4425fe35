#include "pipeline/run_fingerprint.h"

#include <OpenImageIO/hash.h>

#include "pipeline/render_options.h"
#include "util/hex.h"

#include <cstdio>
#include <type_traits>
#include <vector>

namespace qsgi {
namespace {

// Farmhash fingerprints (stable across versions and machines by design) of each part, combined
// by fingerprinting the list of part fingerprints.
class Fingerprinter {
public:
    template <class T>
    void add(const std::vector<T>& values) {
        static_assert(std::is_trivially_copyable_v<T>);
        parts_.push_back(OIIO::farmhash::Fingerprint64(reinterpret_cast<const char*>(values.data()),
                                                       values.size() * sizeof(T)));
    }
    void add(const std::string& text) { parts_.push_back(OIIO::farmhash::Fingerprint64(text.data(), text.size())); }
    template <class T>
    void addValue(const T& value) {
        add(std::vector<T>{value});
    }
    uint64_t result() const {
        return OIIO::farmhash::Fingerprint64(reinterpret_cast<const char*>(parts_.data()), parts_.size() * sizeof(uint64_t));
    }

private:
    std::vector<uint64_t> parts_;
};

}  // namespace

namespace {

// An option's value as a message shows it: strings bare, numbers to 7 digits (a float's),
// values the estimator does not read as "unused".
std::string shown(const nlohmann::json& value) {
    if (value.is_null()) return "unused";
    if (value.is_number_float()) {
        char text[32];
        std::snprintf(text, sizeof text, "%.7g", value.get<double>());
        return text;
    }
    return value.is_string() ? value.get<std::string>() : value.dump();
}

}  // namespace

RunFingerprint runFingerprint(const RenderSettings& s, const Scene& scene, const std::string& animationBytes,
                              const Camera& camera) {
    // Each part on its own (for messages), and all of them in one list, in the order the digest
    // has always taken them. (The digest changes whenever a fingerprinted option is added: aim_emission,
    // back with issue 31, made every earlier folder another run's.)
    Fingerprinter all, content, lights, animation, view;
    auto both = [&](Fingerprinter& part, auto&& addTo) {
        addTo(part);
        addTo(all);
    };
    all.add(std::string(QSGI_VERSION));
    // The scene as loaded (rest pose), whatever files it came from.
    both(content, [&](Fingerprinter& f) {
        f.add(scene.positions);
        f.add(scene.normals);
        f.add(scene.triangles);
        f.add(scene.triangleMaterial);
        f.addValue(scene.worldOrigin);
        for (const Material& m : scene.materials) {
            f.addValue(m.albedo);
            f.addValue(m.emission);
        }
        // What the materials read besides their factors (issue 57), only where a scene has it,
        // so that this part stays as it was for scenes of plain colour factors.
        for (const Material& m : scene.materials)
            if (m.baseColour.used() || m.emissive.used() || m.transmission > 0 || m.alphaMode != AlphaMode::Opaque ||
                m.alpha != 1 || m.doubleSided) {
                f.addValue(m.alpha);
                f.addValue(int(m.alphaMode));
                f.addValue(m.alphaCutoff);
                f.addValue(int(m.doubleSided));
                f.addValue(m.transmission);
                for (const TextureSlot* slot : {&m.baseColour, &m.emissive, &m.transmissionTexture}) {
                    f.addValue(slot->texture);
                    f.addValue(slot->texCoord);
                    f.addValue(slot->transform);
                }
            }
        if (scene.textures)
            for (const Texture& t : *scene.textures) {
                if (!t.image) continue;
                f.addValue(t.image->width);
                f.addValue(t.image->height);
                f.add(t.image->rgba);
                f.addValue(int(t.wrapS) * 4 + int(t.wrapT) * 2 + int(t.nearest));
            }
        for (const std::vector<TexCoord>& set : scene.vertexTexCoords) f.add(set);
        if (!scene.vertexColours.empty()) f.add(scene.vertexColours);
    });
    both(lights, [&](Fingerprinter& f) {
        for (const PunctualLight& l : scene.lights) {
            f.addValue(int(l.type));
            f.addValue(l.position);
            f.addValue(l.direction);
            f.addValue(l.intensity);
            f.addValue(l.cosOuterCone);
        }
        // Only when there is one, so that this part stays as it was for runs without.
        if (scene.environment) {
            f.addValue(scene.environment->width());
            f.addValue(scene.environment->height());
            f.add(scene.environment->pixels());
            f.addValue(scene.environment->rotationDegrees());
        }
    });
    both(animation, [&](Fingerprinter& f) { f.add(animationBytes); });
    // Every option that reaches the frame files, as the option table declares them (the scene's
    // path among them: EXR metadata names it).
    const nlohmann::json options = optionValues(s, OptionSelection::Fingerprinted);
    all.add(options.dump());
    both(view, [&](Fingerprinter& f) {
        f.addValue(camera.position);
        f.addValue(camera.forward);
        f.addValue(camera.up);
        f.addValue(camera.yfov);
        f.addValue(int(camera.projection));
        f.addValue(camera.ymag);
        f.addValue(camera.node);
    });
    RunFingerprint fingerprint;
    fingerprint.digest = hex(all.result());
    fingerprint.parts = {{"qsgi", QSGI_VERSION},
                         {"scene_content", hex(content.result())},
                         {"lights", hex(lights.result())},
                         {"animation_content", hex(animation.result())},
                         {"camera", hex(view.result())},
                         {"options", options}};
    return fingerprint;
}

std::vector<std::string> fingerprintDifferences(const nlohmann::json& there, const nlohmann::json& here) {
    std::vector<std::string> differences;
    if (!there.is_object()) {
        differences.push_back("its timing.json, written by an older qsgi, does not record which settings it was made with");
        return differences;
    }
    auto part = [](const nlohmann::json& parts, const char* name) {
        return parts.contains(name) ? parts.at(name) : nlohmann::json(nullptr);
    };
    if (part(there, "qsgi") != part(here, "qsgi"))
        differences.push_back("qsgi " + shown(part(there, "qsgi")) + " there, " + shown(part(here, "qsgi")) + " here");
    // Options first, by the table's order: what a user most often changed.
    const nlohmann::json optionsThere = part(there, "options"), optionsHere = part(here, "options");
    for (const RenderOption& o : renderOptions()) {
        if (!o.key || !o.fingerprinted) continue;
        const nlohmann::json a = optionsThere.is_object() && optionsThere.contains(o.key) ? optionsThere.at(o.key) : nullptr;
        const nlohmann::json b = optionsHere.is_object() && optionsHere.contains(o.key) ? optionsHere.at(o.key) : nullptr;
        if (a != b) differences.push_back(std::string(o.key) + " " + shown(a) + " there, " + shown(b) + " here");
    }
    const std::pair<const char*, const char*> contents[] = {
        {"scene_content", "the scene's content (geometry or materials) differs"},
        {"lights", "the lights differ"},
        {"animation_content", "the animation's content differs"},
        {"camera", "the camera differs"}};
    for (const auto& [name, what] : contents)
        if (part(there, name) != part(here, name)) differences.push_back(what);
    return differences;
}

}  // namespace qsgi
