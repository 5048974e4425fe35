// What a render would see, before it runs (`qsgi inspect`, issue 22): the scene as loaded (meshes,
// triangles, materials, lights and their share of the power, cameras), the animation the render
// would play (frames, which nodes move and what share of the triangles that is, its bounds), the
// default radius, and every warning the render would print. Built from a RenderJob, so that it
// checks exactly what a render checks and refuses bad input with the same message.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "pipeline/render_job.h"
#include "util/error.h"

namespace qsgi {

nlohmann::json inspectRender(const RenderJob& job, const Warnings& warnings);

// The same report as lines of text for a terminal.
std::string inspectionText(const nlohmann::json& report);

}  // namespace qsgi
