#pragma once
// Checkpoint files of a run (Simulation::save_checkpoint), written atomically: a reader finds
// either the previous checkpoint or the whole new one, never half of one.

#include <filesystem>
#include <string>
#include <string_view>

#include "gpa/engine/simulation.hpp"

namespace gpa::io {

// What identifies a scene to its checkpoints: a 64-bit FNV-1a hash of the scene file's bytes,
// as "fnv1a64:<16 hex digits>".
std::string scene_fingerprint(std::string_view scene_text);

// Writes `file` (through file.tmp). Throws OutputError naming the file.
void write_checkpoint(const std::filesystem::path& file, const Simulation& sim, std::string_view fingerprint,
                      std::string_view user_data);

// Restores `sim` from `file`; returns the user data. Throws CheckpointError (wrong build,
// scene, format, or a damaged file) or OutputError (cannot be read).
std::string read_checkpoint(const std::filesystem::path& file, Simulation& sim, std::string_view fingerprint);

// The header of `file`. Throws CheckpointError or OutputError.
CheckpointInfo checkpoint_info(const std::filesystem::path& file);

}  // namespace gpa::io
