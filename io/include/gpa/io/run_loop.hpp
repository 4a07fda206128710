#pragma once
// A run of a scene in its output folder, from its first step or from a checkpoint, to its end:
// the loop that `gpa run` is made of, for programs that embed gpa (docs/api.md).
//
// A run writes into <folder>.partial while it goes and renames it to <folder> when it finishes:
//   scene.toml        the scene's text as it was read
//   history.csv       a row of totals every output.history_every steps and at the last step
//   gauge_<name>.csv  each gauge, on the history's schedule
//   particles.pvd     the snapshot series (particles_*.vtp, elements_*.vtu), on output.snapshots
//                     or output.snapshot_interval, written by a background task
//   checkpoint.gpa    every output.checkpoint_every_steps / _seconds, and when the run is stopped
//   summary.json, profile.csv   at the end (summary.json also when it is stopped or fails)
// Before the first step the outputs' disk space is estimated and checked; a resumed run checks
// that its folder is the one its checkpoint describes and cuts its files back to it.
//
// Errors before the first step are thrown (InputError for the scene, LimitError for memory and
// disk, io::OutputError for the folder, CheckpointError on resume), with the messages `gpa run`
// prints, and leave no folder behind (a resumed run's folder is left as it was: it is checked, and
// its disk estimated, before anything in it changes). From the first step on, run() returns a
// RunResult: a failed step, an output that could not be written or an exception thrown by a hook
// is a RunStatus::Failed result, with what was written kept in the folder.
//
// The ten-line program (examples/run_scene.cpp):
//
//   gpa::io::RunSettings settings;
//   settings.output = "runs/copper";
//   settings.overwrite = true;
//   gpa::io::RunLoop run(gpa::io::SceneSource::from_file("scenes/taylor-copper-190.toml"), settings);
//   const gpa::io::RunResult result = run.run();
//   std::cout << gpa::io::run_report(run.simulation());

#include <cstddef>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/simulation.hpp"

namespace gpa::io {

// The text of a scene and the names it goes by.
struct SceneSource {
    std::string text;              // TOML (docs/scene-format.md)
    std::string name;              // what messages call it, e.g. "scenes/x.toml"
    std::string label;             // summary.json's scene_file
    std::filesystem::path file;    // the files the scene names are found relative to it (empty: the working folder)

    // Reads `file` (InputError naming it when it cannot be read); name, label and file are its path.
    static SceneSource from_file(const std::filesystem::path& file);
};

struct RunSettings {
    std::filesystem::path output;  // the run's folder; required for a fresh run (InputError when empty)
    bool overwrite = false;        // an existing folder is replaced when the run finishes
    int threads = 0;               // 0: every hardware thread
    MemoryLimit memory;            // the node store and lists are checked against it (limits.hpp)
    // Warnings of the set-up and of the steps: a file the scene names that is not there (what it
    // leaves uncompared), implausible scene values (scene_warnings), fixed nodes switched because a
    // lattice cell collapsed. Without one they are kept in RunLoop::warnings().
    std::function<void(const std::string&)> warning;
};

// What stops a run between steps (a signal, a user's request): code != 0 stops it after the step
// under way, with a snapshot, a checkpoint and summary.json; `by` names the request in the summary
// and the result ("SIGINT", "the user").
struct StopRequest {
    int code = 0;
    std::string by;
};

// Called by run(); any may be empty. An exception a hook throws fails the run like a failed step.
struct RunHooks {
    // After each step, before its outputs: may read and change the simulation between steps
    // (Simulation::apply_force, set_velocity, set_region_velocity), which the next step then sees.
    std::function<void(Simulation&)> after_step;
    // After each step and its outputs, and once more at the end (progress display).
    std::function<void(const Simulation&, bool last)> progress;
    // Asked before each step (also before the first).
    std::function<StopRequest()> stop_requested;
    // The program's own state, saved in every checkpoint the run writes (any bytes; a coupled
    // model's state, say), and given back by RunLoop::checkpoint_data() when the run is resumed,
    // so that a coupled run can continue bit for bit.
    std::function<std::string()> checkpoint_data;
    // Warnings of the steps (fixed nodes switched because a lattice cell collapsed); without one
    // they go where RunSettings::warning sends the set-up's.
    std::function<void(const std::string&)> step_warning;
};

enum class RunStatus { Finished, Interrupted, Failed };

struct RunResult {
    RunStatus status = RunStatus::Failed;
    // Finished: why the run stopped (Simulation::stop_reason); Interrupted: "stopped by <by> after
    // step N at t = T us"; Failed: the cause, as summary.json gives it.
    std::string message;
    // Failed: what else could not be written (each "; ..."); Interrupted: why saving the stopped
    // run failed, if it did. Empty otherwise.
    std::string problems;
    int stop_code = 0;                   // Interrupted: StopRequest::code
    std::optional<FailureSite> failure;  // Failed in a step: where (step, node, body, phase, field)
    bool resumable = false;              // the folder holds a checkpoint that continues the run
    std::filesystem::path folder;        // where the outputs are: <folder> when finished, else <folder>.partial
    double wall_seconds = 0.0;           // the run's wall time, across resumes
};

class RunLoop {
public:
    // A fresh run: parses the scene, resolves the files it names, builds the simulation, checks
    // its gauges and takes the folder: locks it (<folder>.lock, until the RunLoop is destroyed),
    // refuses it if it holds a run (unless overwrite) and makes <folder>.partial, empty (a stale
    // one from a failed run without a checkpoint is cleared). The outputs are written by run().
    RunLoop(SceneSource source, RunSettings settings);
    // Continues the run stopped in `folder` (<folder> or <folder>.partial) from its checkpoint;
    // `scene`, when given, must be the scene the run started with (the folder's copy is used
    // otherwise). settings.output is ignored; threads and memory apply. The folder is checked
    // and cut back to the checkpoint by run(), before the first step.
    static std::unique_ptr<RunLoop> resume(const std::filesystem::path& folder, std::optional<SceneSource> scene,
                                           RunSettings settings);
    ~RunLoop();
    RunLoop(const RunLoop&) = delete;
    RunLoop& operator=(const RunLoop&) = delete;

    Simulation& simulation();
    const Simulation& simulation() const;
    const Scene& scene() const;
    // <folder>.partial, where the run writes, and <folder>, where a finished run's outputs end up.
    const std::filesystem::path& partial_folder() const;
    const std::filesystem::path& final_folder() const;
    bool resumed() const;
    // Warnings so far, when RunSettings::warning was not given.
    const std::vector<std::string>& warnings() const;
    // A resumed run: what RunHooks::checkpoint_data gave when its checkpoint was written (empty
    // for a fresh run, or when there was no such hook).
    const std::string& checkpoint_data() const;

    // Writes the run's first outputs (or checks and cuts back a resumed run's), then steps until a
    // stop criterion of the scene is met, a hook asks to stop, or a step fails. Runs once: a
    // second call throws std::logic_error. Errors before the first step are thrown (see above).
    RunResult run(const RunHooks& hooks = {});

private:
    struct Impl;
    explicit RunLoop(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

// The report `gpa run` prints at the end: nodes, steps and why it stopped; length and footprint
// against the first rigid plane; the energies; the prescribed regions; the comparisons with the
// scene's references; the local peaks. One indented line each, ending in a line break.
std::string run_report(const Simulation& sim);

}  // namespace gpa::io
