// Each frame solved for the output mesh, as the sinks see it (lib/output/frame_sink.h): the
// FrameSolver on the scene itself, or with the vertex fit (VertexFitStage) on the fit's sampling
// mesh, then fitted to the output's vertices. It assembles the frame's record from both stages.
#pragma once

#include <optional>

#include "output/frame_sink.h"
#include "pipeline/frame_solver.h"
#include "pipeline/vertex_fit_stage.h"

namespace qsgi {

class OutputFrameSolver {
public:
    // output: the scene the bake is written on, in the rest pose; fit: the vertex fit's stage, or
    // null. Both outlive the solver.
    OutputFrameSolver(Scene& output, VertexFitStage* fit, const EmbreeDevice& device, FrameSolverSettings settings);

    struct Result {
        SolvedFrame frame;  // valid until the next solve
        FrameTiming record;
        uint64_t fitFallbacks = 0;  // meshes whose fit failed and kept their point values
    };
    Result solve(int frame, const Pose& pose, bool updateFollows);
    void reset() { solver_.reset(); }

    FrameSolver& frameSolver() { return solver_; }
    const FrameSolver& frameSolver() const { return solver_; }

private:
    static Scene& solvedScene(Scene& output, VertexFitStage* fit);

    Scene& output_;
    VertexFitStage* fit_;
    FrameSolver solver_;
};

}  // namespace qsgi
