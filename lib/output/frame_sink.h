// The outputs of a render as sinks of its one frame loop (docs/design.md §7). The loop solves a
// frame and hands it to every sink; each encodes its files of the frame, and the loop writes them
// all together through the output folder's one door (OutputDirectory::write), as one transaction
// that the log then lists. A sink never writes a frame's file itself. The files of the whole run
// (asset.glb, asset.usda) are another kind of sink, made after the loop from the frames on disk
// (whole_run_sink.h).
#pragma once

#include <string>
#include <vector>

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"

namespace qsgi {

// One solved frame, as the sinks see it: the scene posed at it and the solver's result.
struct SolvedFrame {
    int frame = 0;
    const Scene& scene;
    const SceneBvh& bvh;
    const VertexRadiosity& result;
};

// One of a frame's files, named by its extension: frame_NNNN.<extension> (the loop names it).
struct EncodedFile {
    std::string extension;
    std::string bytes;
};

class FrameSink {
public:
    virtual ~FrameSink() = default;
    // Fixes what every frame's previews share from animation frame 0, whichever frame a run starts
    // at (docs/design.md §6.0): called once, before the first frame is encoded.
    virtual void calibrate(const SolvedFrame& /*frame0*/) {}
    // The stage a sink's preparation is reported as ("image"), or nullptr if it prepares nothing.
    virtual const char* preparingStage() const { return nullptr; }
    // The frame's heavy work before any file is encoded (an image). Returns its seconds, the
    // frame's render time.
    virtual double prepare(const SolvedFrame& /*frame*/) { return 0; }
    // Appends the frame's files, in the order the log lists them. Nothing is written.
    virtual void encode(const SolvedFrame& /*frame*/, std::vector<EncodedFile>& /*files*/) = 0;
};

}  // namespace qsgi
