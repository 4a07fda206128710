#pragma once
// Private to io/: the [[material]] tables of scene files and of the material library.

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/materials/material.hpp"
#include "toml_reading.hpp"

namespace gpa::io::detail {

// Looks up a material a table may derive from (`base = "..."`) among materials defined outside
// the file (the built-in library); nullptr when unknown.
struct OutsideMaterials {
    std::function<const materials::Material*(std::string_view)> find;
    std::function<std::string()> names;  // for messages; empty = none
};

// Reads the array of [[material]] tables (`node` is the value of the "material" key, may be
// null). A table may derive from an earlier table of the same file or from `outside`.
std::vector<materials::Material> read_materials(const Reporter& reporter, const toml::node* node,
                                                const OutsideMaterials& outside);

// ASCII letter case ignored.
bool same_name(std::string_view a, std::string_view b);

}  // namespace gpa::io::detail
