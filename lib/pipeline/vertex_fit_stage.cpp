#include "pipeline/vertex_fit_stage.h"

#include "scene/back_sides.h"
#include "scene/contact_refinement.h"
#include "util/stopwatch.h"

namespace qsgi {

std::optional<Scene> VertexFitStage::samplingMesh(const Scene& output, const Animation& animation, const std::vector<uint8_t>& backSided,
                                                  float radius, size_t triangleLimit) {
    Scene samples = output;
    const std::optional<ContactRefinementReport> refined =
        refineContacts(samples, radius, animation.lastFrame(), [&](int frame) { return animation.poseAt(frame); }, triangleLimit);
    if (!refined) return std::nullopt;
    addBackSides(samples, backSided);
    samples.markDynamic(animation.movedNodes(), animation.morphedNodes());
    sweepAnimationBounds(samples, animation);
    return samples;
}

void VertexFitStage::start(const EmbreeDevice& device, const Scene& output) {
    fit_.emplace(output, samples_);
    outputBvh_.emplace(device, output);
}

VertexFitStage::Result VertexFitStage::fit(Scene& output, const Pose& pose, const std::vector<Vec3f>& sampleIrradiance,
                                           const std::vector<uint8_t>& covered) {
    Stopwatch clock;
    if (output.applyPose(pose)) outputBvh_->updateDynamic(output);
    const VertexFit::Report report = fit_->fit(output, samples_, sampleIrradiance, covered, fitted_);
    return Result{fitted_, report, clock.seconds()};
}

}  // namespace qsgi
