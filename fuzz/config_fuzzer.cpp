// Fuzzes the config reader (docs/design.md §8): JSON parsing as readJsonFile does it, applyConfigJson
// and validateSettings. Only InputError may leave qsgi's code.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>

#include "pipeline/render_options.h"
#include "pipeline/render_settings.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const nlohmann::json doc = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
    if (doc.is_discarded()) return 0;  // readJsonFile's "not valid JSON"
    try {
        qsgi::RenderSettings settings;
        qsgi::applyConfigJson("configs/fuzz.json", doc, settings);
        if (settings.scenePath.empty()) settings.scenePath = "scene.gltf";
        qsgi::validateSettings(settings);
        if (settings.frames) qsgi::parseFrameRange(std::to_string(settings.frames->first) + ":" +
                                                   std::to_string(settings.frames->last), "fuzz");
    } catch (const qsgi::InputError&) {
    }
    return 0;
}
