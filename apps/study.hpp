#pragma once
// The `gpa study` command: one scene over several resolutions and method variants, with wall
// time, throughput, peak memory, the scene's metrics and their errors (docs/study.md).

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "gpa/engine/limits.hpp"

namespace gpa::app {

struct StudyOptions {
    std::filesystem::path scene;
    std::optional<std::filesystem::path> output;  // none: studies/<scene name>-<date-time>
    std::string refine = "1,1.5,2";               // refinement factors, as typed
    std::vector<std::string> variants;            // NAME[:key=value,...] as typed; none: the scene as written
    std::string threads = "0";                    // thread counts, as typed
    std::string metrics;                          // --metrics a,b: the metrics analysed; "": every one the runs produce
    bool overwrite = false;
    bool quiet = false;
    MemoryLimit memory;  // --max-memory, for every case
    // --reference FILE: write the series as the scene's element reference (io/reference.hpp); the
    // study must have one series and three or more resolutions.
    std::optional<std::filesystem::path> reference;
};

// Runs the study; returns the process exit code (0, or 3 when a case failed; the outputs are
// written either way). Bad options throw gpa::InputError before anything runs.
int run_study(const StudyOptions& options);

}  // namespace gpa::app
