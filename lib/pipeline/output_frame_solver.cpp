#include "pipeline/output_frame_solver.h"

namespace qsgi {

namespace {
FrameSolverSettings withCover(FrameSolverSettings settings, bool fits) {
    // The fit gives no weight to covered samples: the solver keeps what tells them.
    settings.reportsCoveredVertices = settings.reportsCoveredVertices || fits;
    return settings;
}
}  // namespace

Scene& OutputFrameSolver::solvedScene(Scene& output, VertexFitStage* fit) {
    // Built in the rest pose, before any frame: every run refits the same BVHs (docs/design.md §6.0).
    Scene& solved = fit ? fit->samplingScene() : output;
    solved.applyPose(solved.restPose());
    return solved;
}

OutputFrameSolver::OutputFrameSolver(Scene& output, VertexFitStage* fit, const EmbreeDevice& device, FrameSolverSettings settings)
    : output_(output), fit_(fit), solver_(solvedScene(output, fit), device, withCover(std::move(settings), fit != nullptr)) {
    if (fit_) {
        output_.applyPose(output_.restPose());
        fit_->start(device, output_);
    }
}

OutputFrameSolver::Result OutputFrameSolver::solve(int frame, const Pose& pose, bool updateFollows) {
    FrameSolver::Solution solved = solver_.solve(pose, updateFollows);
    if (!fit_) return Result{SolvedFrame{frame, output_, solver_.bvh(), solved.radiosity}, std::move(solved.record)};
    const VertexFitStage::Result fitted = fit_->fit(output_, pose, solved.radiosity.irradiance, solver_.coveredVertices());
    FrameTiming& record = solved.record;
    record.fitSeconds = fitted.seconds;
    record.fitFactorisations = fitted.report.factorisations;
    record.fitClampedVertices = fitted.report.clampedVertices;
    record.fitBytes = fit_->bytes();
    return Result{SolvedFrame{frame, output_, fit_->outputBvh(), fitted.radiosity}, std::move(record), fitted.report.pointFallbacks};
}

}  // namespace qsgi
