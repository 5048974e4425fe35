// The least-squares vertex fit as a stage of the run (--vertex-fit least-squares; lib/estimate/
// vertex_fit.h, docs/method.md): it owns what the fit needs from the first frame to the last —
// the sampling mesh (the output mesh refined near contacts, which the frames are solved on), the
// fit itself with its kept factorisations, and the output mesh's own BVH (the images trace the
// output mesh). OutputFrameSolver runs it after each solve.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "estimate/vertex_fit.h"
#include "estimate/vertex_radiosity.h"
#include "scene/animation.h"
#include "scene/scene.h"
#include "trace/embree_device.h"
#include "trace/scene_bvh.h"

namespace qsgi {

class VertexFitStage {
public:
    // The sampling mesh for `output` (marked dynamic, animation bounds swept, in the rest pose):
    // output refined where surfaces touch as --refine-contacts R refines, R = `radius` (the
    // default photon radius: the score's contact band), every frame of the animation judged; then
    // the back sides output will take (`backSided`, decided on the output mesh so that the fit
    // pairs their instances). nullopt when the refinement would pass `triangleLimit`.
    static std::optional<Scene> samplingMesh(const Scene& output, const Animation& animation, const std::vector<uint8_t>& backSided,
                                             float radius, size_t triangleLimit);
    // samples: samplingMesh's.
    explicit VertexFitStage(Scene samples) : samples_(std::move(samples)) {}

    // The mesh the frames are solved on.
    Scene& samplingScene() { return samples_; }
    const Scene& samplingScene() const { return samples_; }

    // Builds what fitting keeps, for `output` in the rest pose (call once, before the first fit).
    void start(const EmbreeDevice& device, const Scene& output);

    struct Result {
        const VertexRadiosity& radiosity;  // output's, valid until the next fit
        VertexFit::Report report;
        double seconds = 0;
    };
    // Poses `output` as `pose` and fits its values to the samples' irradiance (the sampling mesh
    // solved in the same pose); `covered`: the samples no weight is given (FrameSolver::coveredVertices).
    Result fit(Scene& output, const Pose& pose, const std::vector<Vec3f>& sampleIrradiance, const std::vector<uint8_t>& covered);

    // The output mesh's BVH in the last fit's pose.
    const SceneBvh& outputBvh() const { return *outputBvh_; }
    // Bytes kept across frames (each mesh's matrix and factorisation).
    size_t bytes() const { return fit_ ? fit_->bytes() : 0; }

private:
    Scene samples_;
    std::optional<VertexFit> fit_;
    std::optional<SceneBvh> outputBvh_;
    VertexRadiosity fitted_;
};

}  // namespace qsgi
