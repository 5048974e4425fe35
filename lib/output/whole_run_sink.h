// The outputs of a whole run (docs/outputs.md): asset.glb (--gltf-out, AssetSink) and asset.usda
// (--usd-out, UsdSink). Each is made once, after the frame loop, from the frames' PLYs in the
// folder, verified as --resume verifies them, so that a resumed run (or the Slurm merge's
// finishing run) writes it whole with the bytes of one straight run, holding a bounded part of
// the frames at a time. They see no frame of the loop: what they need of a frame is on disk.
#pragma once

#include <string>
#include <vector>

namespace qsgi {

class OutputDirectory;

// What a whole-run file came to, for the run's report.
struct WholeRunReport {
    std::string name;  // asset.glb, asset.usda
    size_t bytes = 0;
    std::string sizes;  // for the user: "12.3 MB, of which the bake 4.5 MB"
    double seconds = 0;
    std::vector<std::string> warnings;
};

class WholeRunSink {
public:
    virtual ~WholeRunSink() = default;
    // After the last frame (or a resumed run with none left to compute): the file, written
    // through `folder`, from the frames the folder holds.
    virtual WholeRunReport make(OutputDirectory& folder) = 0;
};

}  // namespace qsgi
