#pragma once
// Scene files (TOML) in, gpa::Scene out. The format is documented in docs/scene-format.md.
//
// Every quantity may be a plain number (SI) or a string with a unit ("15.2 mm", "305 m/s");
// every key has one dimension, and unknown keys, units of the wrong dimension, non-finite
// numbers and impossible values are errors. The Scene returned has passed validate_scene().

#include <filesystem>
#include <string>
#include <string_view>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa::io {

// A scene file that cannot be used. what() is one line: the file, the line where known, the key
// (a dotted path such as `body "bar" (body[0]).radius` or `solver.cfl`) and what is allowed.
class SceneError : public InputError {
public:
    using InputError::InputError;
};

// Reads and parses a scene file. Messages name the file as given. Throws SceneError (also when
// the file cannot be read).
Scene load_scene(const std::filesystem::path& file);

// The bytes of a scene file, read with the scene-size limit (16 MiB) whatever the file is: a
// device or a pipe that never ends is refused once it passes the limit. Throws SceneError.
std::string read_scene_text(const std::filesystem::path& file);

// Parses scene text; `file_name_for_messages` is what messages call the file.
Scene parse_scene(std::string_view text, const std::string& file_name_for_messages);

}  // namespace gpa::io
