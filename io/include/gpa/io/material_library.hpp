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
// aluminium (the spec's), Weldox 460 E, 6061-T6 and 7075-T6 aluminium, Ti-6Al-4V, tungsten heavy
// alloy. Parsed once, on first use.
const std::vector<materials::Material>& builtin_materials();

// The library material of that name, letter case ignored; nullptr if there is none.
const materials::Material* find_builtin_material(std::string_view name);

// The same, but an unknown name throws gpa::InputError listing the known names.
const materials::Material& builtin_material(std::string_view name);

// "OFHC copper, Armco iron, ..." for messages.
std::string builtin_material_names();

// Every constant of a material as a [[material]] table of a scene file, in the units of the
// library (MPa and GPa, m/s, K, J/kg/K): `gpa materials NAME` prints it, and a scene may paste and
// edit it. Reading the text back (parse_material_library) gives the same material, every number
// bit for bit: each is written with the shortest digits that round-trip, its unit's power of ten
// moved into the decimal point. The melt temperature is left out when infinite (the default).
std::string material_as_toml(const materials::Material& material);

// Every constant of a material as the key it has in a [[material]] table ("density",
// "strength.a", "failure.johnson_cook.d1", ...) and its value as material_as_toml writes it
// ("\"90 MPa\""), in that order; the model names are constants too ("eos.model").
struct MaterialConstant {
    std::string key;
    std::string value;
};
std::vector<MaterialConstant> material_constants(const materials::Material& material);

// What a material derived with `base` changes: the constants whose key or value differ from the
// base's, as "strength.a = \"120 MPa\" (base: \"90 MPa\")"; a key the base does not have (another
// model) says "(base: none)", and one only the base has "no eos.k1 (base: \"165 GPa\")". Empty when
// nothing differs.
std::vector<std::string> material_changes(const materials::Material& material, const materials::Material& base);

// The embedded text of materials/data/library.toml.
std::string_view builtin_library_text();

// Parses a material library in the same format (a file of [[material]] tables); a table may
// derive from an earlier one or from a built-in material with `base`. Throws SceneError.
std::vector<materials::Material> parse_material_library(std::string_view text,
                                                        const std::string& file_name_for_messages);

}  // namespace gpa::io
