// One render run: load and check every input, then per frame pose the scene, trace photons,
// estimate vertex radiosity and write the outputs (docs/design.md §1). The CLI is a thin host over this.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "output/folder_survey.h"
#include "output/frame_sink.h"
#include "output/whole_run_sink.h"
#include "pipeline/animation_source.h"
#include "pipeline/run_fingerprint.h"
#include "pipeline/vertex_fit_stage.h"
#include "pipeline/render_settings.h"
#include "scene/animation.h"
#include "scene/mesh_resolution.h"
#include "scene/scene.h"
#include "util/error.h"
#include "util/stopwatch.h"

namespace qsgi {

class OutputDirectory;

struct FrameReport {
    int frame;
    int index, count;  // position in the run
    double seconds;
    double missedFraction;  // of the photons emitted this frame, those that hit no geometry
};

// What a frame is doing, for a progress display: the solver's stages (FrameSolver::StageReporter),
// then "image" and "writing".
struct StageReport {
    int frame;
    int index, count;  // position in the run
    const char* stage;
    uint64_t done, total;  // how far the stage is; total 0 when unknown
};

// How run() ended: every frame written, or stopped early on request with the frames before
// `nextFrame` on disk.
// What a run with these settings expects of its output folder (lib/output/folder_survey.h): its
// fingerprint, the files every frame has, --resume and --overwrite.
FolderExpectations folderExpectations(const RenderSettings& settings, const RunFingerprint& fingerprint);

struct RunOutcome {
    bool interrupted = false;
    int nextFrame = 0;      // the first frame not written
    int framesResumed = 0;  // frames an earlier run had written (--resume)
    int framesKept = 0;     // frames of an earlier run of the same inputs outside this run's range (no --resume)
    int framesRemoved = 0;  // frames outside the range whose files failed verification: unlinked
    int filesReplaced = 0;  // of another run, unlinked by --overwrite (frame files and timing.json)
    int framesWritten = 0;  // by this run
    // asset.glb (--gltf-out), asset.usda (--usd-out): what each came to and the seconds to make it
    std::vector<WholeRunReport> wholeRunFiles;
};

// What a run tells its host, all optional: onFrame after each frame; stopRequested, asked after
// each frame, ends the run early with the folder consistent; onStage each stage of a frame as it
// starts, and how far tracing is a few times a second (from another thread); onWarning what the
// user should know about the folder (a file system that cannot lock, frames of an earlier run
// computed again because their files were damaged).
struct RunObserver {
    std::function<void(const FrameReport&)> onFrame;
    std::function<bool()> stopRequested;
    std::function<void(const StageReport&)> onStage;
    std::function<void(const std::string&)> onWarning;
};

class RenderJob {
public:
    // Loads the scene, animation and lights and checks them all; throws InputError before
    // anything is written. A scene without light loads (inspect reports it); run() refuses it.
    RenderJob(RenderSettings settings, Warnings& warnings);

    // Refuses a scene without light, then creates the output folder, takes its lock and renders
    // every frame (with --resume, those an earlier run of the same inputs has not written whole).
    // The folder is consistent whenever run() returns or throws: every file complete, timing.json
    // listing exactly the frames on disk. Throws InputError for a folder it may not use,
    // FolderBusyError when another run holds it, EnvironmentError when the disk fails.
    RunOutcome run(const RunObserver& observer = {});

    const Scene& scene() const { return scene_; }
    const std::string& outputFolder() const { return settings_.outDir; }
    const RenderSettings& settings() const { return settings_; }  // with the defaults the scene decides
    const Animation& animation() const { return animation_; }
    const Camera& camera() const { return camera_; }  // at frame 0
    int firstFrame() const { return first_; }
    int lastFrame() const { return last_; }
    // The rest pose's triangles against 4 r (a warning when any is longer: mesh_resolution.h).
    const MeshResolution& meshResolution() const { return resolution_; }
    // Whether anything emits: an emissive triangle with area or a light of nonzero power.
    bool hasLight() const { return lit_; }
    // Throws InputError for a scene without light (run() does too).
    void refuseIfUnlit() const;
    // What the run's frame files depend on (what --resume and a folder's earlier run are compared by).
    const RunFingerprint& fingerprint() const { return fingerprint_; }

    // When the scene file carries glTF animations the run does not play (no --animation, or a
    // transform file): "the scene file has 1 animation: 'Walk', 97 frames at 24 fps;
    // --animation gltf plays it"; otherwise "".
    std::string unplayedAnimationsNote() const;

private:
    // The constructor's steps, in order (each reads what the ones before it settled).
    void loadScene(Warnings& warnings);      // the glTF, the config's lights, the environment
    void resolveAnimation();                 // the animation and the rest pose
    void refineScene();                      // --subdivide, --refine-contacts, movers, the fit's samples
    void describeScene(Warnings& warnings);  // the camera, the radius, the mesh's resolution; back sides
    void resolveFrames();                    // --frames against the animation, the camera at each
    void preflight() const;                  // refuses, before any work, what memory cannot hold

    // The run's outputs: the sinks of the frame loop (lib/output/frame_sink.h: the PLY, the
    // images), and (not with --frames-only) those of the whole run made after it from the
    // folder's PLYs (asset.glb with --gltf-out, asset.usda with --usd-out).
    std::vector<std::unique_ptr<FrameSink>> makeFrameSinks() const;
    std::vector<std::unique_ptr<WholeRunSink>> makeWholeRunSinks() const;

    Stopwatch started_;  // first: the job's set-up is timed from its construction (timing.json's "setup")
    RenderSettings settings_;
    Scene scene_;
    // --vertex-fit least-squares: the fit's stage, with its sampling mesh (which the frames are
    // solved on; the bake is then fitted to scene_'s vertices).
    std::optional<VertexFitStage> fit_;
    Camera camera_;  // at frame 0
    Camera cameraAt(int frame) const;
    AnimationSource source_;
    Animation animation_;
    int first_ = 0, last_ = 0;
    std::shared_ptr<const struct GltfDocument> assetDocument_;  // --gltf-out: the scene file as the render read it
    std::vector<std::string> meshNames_;                         // the file's, by mesh index
    RunFingerprint fingerprint_;
    bool lit_ = false;
    MeshResolution resolution_;
    uint64_t inputVertices_ = 0;           // before --subdivide and --refine-contacts
    nlohmann::json contactRefinement_;     // what --refine-contacts added (timing.json), null without it
    std::vector<uint8_t> backSided_;       // the instances that get a back side (decided on the output mesh)
};

}  // namespace qsgi
