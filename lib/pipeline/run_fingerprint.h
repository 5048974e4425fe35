// What decides the bytes of a run's frame files, reduced to one number: the scene as loaded, the
// animation, and every setting that reaches the outputs. `qsgi render --resume` continues a folder
// only if the fingerprint recorded in its timing.json equals the current run's, so a resumed
// folder holds exactly what one uninterrupted run would have written.
//
// Left out on purpose: the thread count, --full-recompute, --always-update, --no-envelope and the
// blocking grid.
// They change how frames are computed, not what they hold (the tests prove the bytes equal), so a
// run may be resumed with more threads or another update strategy. The frame range is left out
// too: resuming may extend the range.
//
// Beside the one number, the parts it is made of (RunFingerprint::parts), which timing.json
// records, so that a folder of another run is refused naming what differs and both values.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

#include "pipeline/render_settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace qsgi {

struct RunFingerprint {
    std::string digest;  // 16 hex digits
    // {"qsgi": version, "scene_content", "lights", "animation_content", "camera": 16 hex digits
    // each, "options": the fingerprinted options' values by config key}
    nlohmann::json parts;
};

// `animationBytes`: the transform file's contents ("" for a still scene). `scene` must be in its
// rest pose. `settings` must hold the radius actually used.
RunFingerprint runFingerprint(const RenderSettings& settings, const Scene& scene, const std::string& animationBytes,
                              const Camera& camera);

// What differs between the parts of an earlier run (`there`, from its timing.json) and this one
// (`here`), one phrase each: "photons 20000 there, 1000000 here", "the scene's content (geometry
// or materials)". Empty when the parts agree.
std::vector<std::string> fingerprintDifferences(const nlohmann::json& there, const nlohmann::json& here);

}  // namespace qsgi
