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
#include "gpa/engine/limits.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa::io {

// A scene file that cannot be used. what() is one line: the file, the line where known, the key
// (a dotted path such as `body "bar" (body[0]).radius` or `solver.cfl`) and what is allowed.
class SceneError : public InputError {
public:
    using InputError::InputError;
};

// Reads and parses a scene file, then resolves the files it names (resolve_scene_files). Messages
// name the file as given. Throws SceneError (also when the file cannot be read); the warning of
// resolve_scene_files goes to *warning when given.
Scene load_scene(const std::filesystem::path& file, std::string* warning = nullptr, const MemoryLimit& memory = {});

// Makes the relative file names of a parsed scene (`[reference] elements`) relative to the folder
// of `scene_file`, the file the text came from, and checks them. A reference that is not there is
// no reason to refuse the scene (a shipped scene copied to another folder has none beside it): the
// returned warning names it and says that the run will not be compared with it (empty when all is
// there). A reference that is there but cannot be read (a folder, an empty or malformed file) is
// refused at once, naming the key, rather than at the end of the run: InputError.
// Bodies of shape "surface" and "nodes" get their STL and node files read here, within `memory`
// (LimitError, naming the body and the file, when one would not fit).
std::string resolve_scene_files(Scene& scene, const std::filesystem::path& scene_file, const MemoryLimit& memory = {});

// The bytes of a scene file, read with the scene-size limit (16 MiB) whatever the file is: a
// device or a pipe that never ends is refused once it passes the limit. Throws SceneError.
std::string read_scene_text(const std::filesystem::path& file);

// Parses scene text; `file_name_for_messages` is what messages call the file.
Scene parse_scene(std::string_view text, const std::string& file_name_for_messages);

}  // namespace gpa::io
