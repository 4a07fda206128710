#pragma once
// The `gpa run`, `gpa check` and `gpa materials` commands.

#include <filesystem>
#include <optional>
#include <string>

namespace gpa::app {

struct RunOptions {
    std::optional<std::filesystem::path> scene;  // none: the built-in default scene
    std::optional<std::filesystem::path> output;  // none: runs/<scene name>-<date-time>
    int threads = 0;
    bool overwrite = false;
    bool quiet = false;
};

// The output folder when none is given: <root>/<scene name with non-alphanumerics as '-'>-<local
// date-time>, e.g. runs/taylor-copper-190-20261201-153000.
std::filesystem::path default_output_folder(const std::string& root, const std::string& scene_name);

// Runs a scene to its end; returns the process exit code. Prints where the output went.
int run_scene(const RunOptions& options);
// Reads and checks a scene without running it: builds its nodes and prints what it holds.
int check_scene(const std::filesystem::path& scene);
// Lists the built-in material library.
int list_materials();

}  // namespace gpa::app
