#include "pipeline/vertex_fit_stage.h"

#include "estimate/vertex_starts.h"
#include "scene/back_sides.h"
#include "scene/contact_refinement.h"
#include "scene/mesh_topology.h"
#include "util/stopwatch.h"

namespace qsgi {

std::optional<Scene> VertexFitStage::samplingMesh(const Scene& output, const Animation& animation, const std::vector<uint8_t>& backSided,
                                                  float radius, size_t triangleLimit) {
    Scene samples = output;
    const std::optional<ContactRefinementReport> refined =
        refineContacts(samples, radius, animation.lastFrame(), [&](int frame) { return animation.poseAt(frame); }, triangleLimit);
    if (!refined) return std::nullopt;
    // The output's vertices are judged covered by the output's resolution (Scene::coverEdges).
    const MeshTopology topology(output);
    samples.coverEdges.assign(samples.vertexCount(), 0.0f);
    for (size_t i = 0; i < output.instances.size(); ++i) {
        const MeshInstance& o = output.instances[i];
        const MeshInstance& s = samples.instances[i];
        for (uint32_t v = 0; v < o.vertexCount; ++v)
            samples.coverEdges[s.firstVertex + v] = float(longestIncidentEdge(output, topology, o.firstVertex + v));
    }
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
