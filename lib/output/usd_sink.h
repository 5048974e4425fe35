// asset.usda (--usd-out; lib/output/usd_asset.h): the scene's meshes with the run's frames
// first..last as time-sampled colours. Made once, after the last frame, from the frames' PLYs in the
// folder, so a resumed run (or the Slurm merge's finishing run) writes it whole, with the bytes of
// one straight run; written as it is made, so a long animation's text is never held whole.
#pragma once

#include "output/whole_run_sink.h"
#include "output/usd_asset.h"

namespace qsgi {

class UsdSink : public WholeRunSink {
public:
    // scene: the render's (its vertices are the PLYs').
    UsdSink(const Scene& scene, UsdAssetSettings settings) : scene_(scene), settings_(std::move(settings)) {}
    WholeRunReport make(OutputDirectory& folder) override;

private:
    const Scene& scene_;
    UsdAssetSettings settings_;
};

}  // namespace qsgi
