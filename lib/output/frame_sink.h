// The outputs of a render as sinks of its one frame loop (docs/design.md §7). The loop solves a
// frame and hands it to every sink; each encodes its files of the frame, and the loop writes them
// all together through the output folder's one door (OutputDirectory::write), as one transaction
// that the log then lists. A sink never writes a frame's file itself. After the last frame, a sink
// of the whole run (the glTF asset) makes its file from the frames on disk, whichever run wrote
// them (--resume, the Slurm merge's finishing run).
#pragma once

#include <string>
#include <vector>

#include "estimate/vertex_radiosity.h"
#include "scene/scene.h"
#include "trace/scene_bvh.h"
#include "util/frame_timing.h"

namespace qsgi {

class OutputDirectory;

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

// What a sink's whole-run file came to, for the run's report.
struct WholeRunReport {
    std::string name;  // asset.glb, asset.usda; empty: the sink has no whole-run file
    size_t bytes = 0;
    std::string sizes;  // for the user: "12.3 MB, of which the bake 4.5 MB"
    double seconds = 0;
    std::vector<std::string> warnings;
};

class FrameSink {
public:
    virtual ~FrameSink() = default;
    // Fixes what every frame's previews share from animation frame 0, whichever frame a run starts
    // at (docs/design.md §6.0): called once, before the first frame is encoded.
    virtual void calibrate(const SolvedFrame& /*frame0*/) {}
    // The stage a sink's preparation is reported as ("image"), or nullptr if it prepares nothing.
    virtual const char* preparingStage() const { return nullptr; }
    // The frame's heavy work before any file is encoded (an image), timed into `timing`.
    virtual void prepare(const SolvedFrame& /*frame*/, FrameTiming& /*timing*/) {}
    // Appends the frame's files, in the order the log lists them. Nothing is written.
    virtual void encode(const SolvedFrame& /*frame*/, std::vector<EncodedFile>& /*files*/) {}
    // After the last frame (or a resumed run with none left to compute): the sink's whole-run
    // file, written through `out`. Sinks of frames only have none.
    virtual void finish(OutputDirectory& /*out*/, WholeRunReport& /*report*/) {}
};

}  // namespace qsgi
