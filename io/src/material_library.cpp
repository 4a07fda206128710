#include "gpa/io/material_library.hpp"

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "material_table.hpp"
#include "toml_reading.hpp"

namespace gpa::io {

namespace detail {
// Defined in the file that the build generates from materials/data/library.toml
// (see io/CMakeLists.txt and io/src/embed_text.cmake).
std::string_view embedded_material_library();
}  // namespace detail

namespace {

std::vector<materials::Material> read_library(std::string_view text, const std::string& file,
                                              const detail::OutsideMaterials& outside) {
    const detail::Reporter reporter(file);
    detail::check_text(text, reporter);
    const toml::table root = detail::parse_toml(text, reporter);
    const detail::TableReader top(reporter, root, "", "a material library", {"material"});
    return detail::read_materials(reporter, top.find("material"), outside);
}

}  // namespace

std::string_view builtin_library_text() { return detail::embedded_material_library(); }

const std::vector<materials::Material>& builtin_materials() {
    // The library refers to nothing outside itself.
    static const std::vector<materials::Material> library =
        read_library(builtin_library_text(), "materials/data/library.toml (built in)", {});
    return library;
}

const materials::Material* find_builtin_material(std::string_view name) {
    for (const auto& m : builtin_materials()) {
        if (detail::same_name(m.name, name)) return &m;
    }
    return nullptr;
}

std::string builtin_material_names() {
    std::string names;
    for (const auto& m : builtin_materials()) names += (names.empty() ? "" : ", ") + m.name;
    return names;
}

const materials::Material& builtin_material(std::string_view name) {
    if (const auto* m = find_builtin_material(name)) return *m;
    throw InputError(fmt::format("unknown material {}; the built-in library has {}", detail::in_quotes(name),
                                 builtin_material_names()));
}

std::vector<materials::Material> parse_material_library(std::string_view text,
                                                        const std::string& file_name_for_messages) {
    const detail::OutsideMaterials builtin{find_builtin_material, builtin_material_names};
    return read_library(text, file_name_for_messages, builtin);
}

}  // namespace gpa::io
