#pragma once
// The `gpa run`, `gpa check` and `gpa materials` commands.
//
// Exit codes of `gpa run`: 0 the run finished; 2 refused before it started (a bad scene or
// option, a memory or disk estimate over its limit, an output folder in use, a checkpoint of
// another build or scene); 3 the run failed (a numerical failure, the energy guard, an output
// that could not be written); 128 + the signal (130 for SIGINT, 143 for SIGTERM) when it was
// interrupted and stopped after writing a checkpoint; 1 anything else.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/limits.hpp"

namespace gpa::app {

struct RunOptions {
    std::optional<std::filesystem::path> scene;   // none: the built-in default scene
    std::optional<std::filesystem::path> output;  // none: runs/<scene name>-<date-time>
    std::optional<std::filesystem::path> resume;  // continue the stopped run in this folder
    int threads = 0;
    bool overwrite = false;
    bool quiet = false;
    MemoryLimit memory;  // --max-memory
};

// The output folder when none is given: <root>/<scene name with non-alphanumerics as '-'>-<local
// date-time>, e.g. runs/taylor-copper-190-20261201-153000.
std::filesystem::path default_output_folder(const std::string& root, const std::string& scene_name);

// Runs a scene to its end (or resumes a stopped run); returns the process exit code. Prints
// where the output went.
int run_scene(const RunOptions& options);
// Reads and checks a scene without running it: builds its nodes and prints what it holds.
int check_scene(const std::filesystem::path& scene, const MemoryLimit& memory = {});
// Lists the built-in material library.
// `gpa materials`: one paragraph per built-in material; with names, every constant of each as a
// [[material]] table (io::material_as_toml). An unknown name is an InputError listing the library.
int list_materials(const std::vector<std::string>& names);

// Logs a scene's implausible values (gpa::scene_warnings), each prefixed with `label` (the scene
// file), before its set-up: gpa run, check and study.
void log_scene_warnings(const Scene& scene, std::string_view label);

}  // namespace gpa::app
