// asset.glb (--gltf-out; lib/output/baked_asset.h): the scene's own glTF with the run's frames
// first..last baked in. Made once, after the last frame, from the frames' PLYs in the folder, so
// a resumed run (or the Slurm merge's finishing run) writes it whole, with the bytes of one
// straight run.
#pragma once

#include <functional>
#include <memory>

#include "output/baked_asset.h"
#include "output/whole_run_sink.h"

namespace qsgi {

struct AssetSinkSettings {
    std::shared_ptr<const GltfDocument> document;  // the scene file as read
    int first = 0, last = 0;                       // the frames baked
    double fps = 0;                                // the animation's: a frame's time
    BakedAssetSettings asset;                      // all but the exposure, which the first frame sets
    std::vector<NodeMotion> motion;                // a transform file's, at every frame baked
};

class AssetSink : public WholeRunSink {
public:
    // scene: the render's (its vertices are the PLYs').
    AssetSink(const Scene& scene, AssetSinkSettings settings) : scene_(scene), settings_(std::move(settings)) {}
    WholeRunReport make(OutputDirectory& folder) override;

private:
    const Scene& scene_;
    AssetSinkSettings settings_;
};

}  // namespace qsgi
