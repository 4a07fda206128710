#pragma once
// The built-in material library: materials/data/library.toml, embedded into the library at build
// time so that a program finds it from any directory. Its tables have the format of a scene's
// [[material]] tables (docs/scene-format.md).

#include <string>
#include <string_view>
#include <vector>

#include "gpa/materials/material.hpp"

namespace gpa::io {

// The library's materials in file order: OFHC copper, Armco iron, 4340 steel, 2024-T351
// aluminium. Parsed once, on first use.
const std::vector<materials::Material>& builtin_materials();

// The library material of that name, letter case ignored; nullptr if there is none.
const materials::Material* find_builtin_material(std::string_view name);

// The same, but an unknown name throws gpa::InputError listing the known names.
const materials::Material& builtin_material(std::string_view name);

// "OFHC copper, Armco iron, ..." for messages.
std::string builtin_material_names();

// The embedded text of materials/data/library.toml.
std::string_view builtin_library_text();

// Parses a material library in the same format (a file of [[material]] tables); a table may
// derive from an earlier one or from a built-in material with `base`. Throws SceneError.
std::vector<materials::Material> parse_material_library(std::string_view text,
                                                        const std::string& file_name_for_messages);

}  // namespace gpa::io
