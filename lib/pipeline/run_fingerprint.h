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
#pragma once

#include <string>

#include "pipeline/render_settings.h"
#include "scene/camera.h"
#include "scene/scene.h"

namespace qsgi {

// 16 hex digits. `animationBytes`: the transform file's contents ("" for a still scene). `scene`
// must be in its rest pose. `settings` must hold the radius actually used.
std::string runFingerprint(const RenderSettings& settings, const Scene& scene, const std::string& animationBytes,
                           const Camera& camera);

}  // namespace qsgi
