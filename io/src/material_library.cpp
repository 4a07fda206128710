#include "gpa/io/material_library.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

namespace {

// A TOML basic string: quotes, backslashes and control characters escaped.
std::string toml_string(std::string_view text) {
    std::string out = "\"";
    for (const char c : text) {
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
            out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
            out += c;
        }
    }
    return out + "\"";
}

// `si` written in a unit 10^unit_exponent times the SI one, with the shortest digits that read back
// as `si` (the reader joins the unit's power of ten to the number's exponent before its one rounding,
// so moving the decimal point here changes nothing): 9e7 in MPa is "90", 7.519e10 in GPa "75.19".
std::string decimal_in(double si, int unit_exponent) {
    if (!std::isfinite(si)) return fmt::format("{}", si);  // "inf": only where a key accepts it
    // Zero in any unit is 0; -0.0 keeps its sign and reads as a float where TOML takes it plain.
    if (si == 0.0) return std::signbit(si) ? "-0.0" : "0";
    char buffer[64];
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, si, std::chars_format::scientific);
    if (ec != std::errc{}) return fmt::format("{}e{}", si, -unit_exponent);
    const std::string_view text(buffer, static_cast<std::size_t>(end - buffer));
    const std::size_t e = text.find('e');
    std::string mantissa(text.substr(0, e));
    const int exponent = std::atoi(std::string(text.substr(e + 1)).c_str()) - unit_exponent;
    const bool negative = !mantissa.empty() && mantissa.front() == '-';
    if (negative) mantissa.erase(0, 1);
    std::string digits;
    for (const char c : mantissa) {
        if (c != '.') digits += c;
    }
    // digits d0 d1 d2 ... stand for d0.d1d2... x 10^exponent.
    std::string out;
    if (exponent < -6 || exponent > 15) {
        out = fmt::format("{}{}{}e{}", digits.front(), digits.size() > 1 ? "." : "", std::string_view(digits).substr(1), exponent);
    } else if (exponent < 0) {
        out = "0." + std::string(static_cast<std::size_t>(-exponent - 1), '0') + digits;
    } else if (static_cast<std::size_t>(exponent) + 1 >= digits.size()) {
        out = digits + std::string(static_cast<std::size_t>(exponent) + 1 - digits.size(), '0');
    } else {
        out = digits.substr(0, static_cast<std::size_t>(exponent) + 1) + "." + digits.substr(static_cast<std::size_t>(exponent) + 1);
    }
    return (negative ? "-" : "") + out;
}

std::string quantity(double si, int unit_exponent, std::string_view unit) {
    return fmt::format("\"{} {}\"", decimal_in(si, unit_exponent), unit);
}

std::string plain(double value) { return decimal_in(value, 0); }

// Pressures in GPa from 1 GPa up, MPa below (as the library writes them).
std::string pressure(double si) { return std::abs(si) >= 1e9 ? quantity(si, 9, "GPa") : quantity(si, 6, "MPa"); }

}  // namespace

std::vector<MaterialConstant> material_constants(const materials::Material& m) {
    namespace mt = materials;
    std::vector<MaterialConstant> out;
    const auto add = [&](std::string key, std::string value) { out.push_back({std::move(key), std::move(value)}); };
    add("name", toml_string(m.name));
    if (!m.source.empty()) add("source", toml_string(m.source));
    add("density", quantity(m.density, 0, "kg/m^3"));
    add("shear_modulus", pressure(m.shear_modulus));
    add("specific_heat", quantity(m.specific_heat, 0, "J/kg/K"));
    add("taylor_quinney", plain(m.taylor_quinney));
    add("room_temperature", quantity(m.room_temperature, 0, "K"));
    if (std::isfinite(m.melt_temperature)) add("melt_temperature", quantity(m.melt_temperature, 0, "K"));
    if (const auto* linear = std::get_if<mt::LinearEos>(&m.eos)) {
        add("eos.model", "\"linear\"");
        add("eos.bulk_modulus", pressure(linear->bulk_modulus));
        add("eos.logarithmic", linear->logarithmic ? "true" : "false");
    } else if (const auto* poly = std::get_if<mt::PolynomialEos>(&m.eos)) {
        add("eos.model", "\"polynomial\"");
        add("eos.k1", pressure(poly->k1));
        add("eos.k2", pressure(poly->k2));
        add("eos.k3", pressure(poly->k3));
        add("eos.gruneisen", plain(poly->gruneisen));
    } else if (const auto* mg = std::get_if<mt::MieGruneisenEos>(&m.eos)) {
        add("eos.model", "\"mie-gruneisen\"");
        add("eos.sound_speed", quantity(mg->sound_speed, 0, "m/s"));
        add("eos.slope", plain(mg->slope));
        add("eos.gruneisen", plain(mg->gruneisen));
    }
    if (std::holds_alternative<mt::ElasticStrength>(m.strength)) {
        add("strength.model", "\"elastic\"");
    } else if (const auto* vm = std::get_if<mt::VonMisesStrength>(&m.strength)) {
        add("strength.model", "\"von-mises\"");
        add("strength.yield_stress", pressure(vm->yield_stress));
        add("strength.hardening_modulus", pressure(vm->hardening_modulus));
    } else if (const auto* jc = std::get_if<mt::JohnsonCookStrength>(&m.strength)) {
        add("strength.model", "\"johnson-cook\"");
        add("strength.a", pressure(jc->a));
        add("strength.b", pressure(jc->b));
        add("strength.n", plain(jc->n));
        add("strength.c", plain(jc->c));
        add("strength.m", plain(jc->m));
        add("strength.reference_strain_rate", quantity(jc->reference_strain_rate, 0, "1/s"));
    }
    if (!m.failure.johnson_cook && !m.failure.spall_pressure) add("failure", "\"none\"");
    if (const auto& f = m.failure.johnson_cook) {
        add("failure.johnson_cook.d1", plain(f->d1));
        add("failure.johnson_cook.d2", plain(f->d2));
        add("failure.johnson_cook.d3", plain(f->d3));
        add("failure.johnson_cook.d4", plain(f->d4));
        add("failure.johnson_cook.d5", plain(f->d5));
        add("failure.johnson_cook.reference_strain_rate", quantity(f->reference_strain_rate, 0, "1/s"));
        add("failure.johnson_cook.min_failure_strain", plain(f->min_failure_strain));
    }
    if (m.failure.spall_pressure) add("failure.spall_pressure", pressure(*m.failure.spall_pressure));
    return out;
}

std::string material_as_toml(const materials::Material& m) {
    // The models' constants as inline tables, one line each, as the library writes them.
    const std::array<std::string_view, 3> groups{"eos", "strength", "failure.johnson_cook"};
    const auto group_of = [&](std::string_view key) -> std::string_view {
        for (const std::string_view g : groups) {
            if (key.size() > g.size() && key.substr(0, g.size()) == g && key[g.size()] == '.' &&
                key.find('.', g.size() + 1) == std::string_view::npos) {
                return g;
            }
        }
        return {};
    };
    std::string out = "[[material]]\n";
    const auto constants = material_constants(m);
    for (std::size_t k = 0; k < constants.size();) {
        const std::string_view group = group_of(constants[k].key);
        if (group.empty()) {
            out += fmt::format("{} = {}\n", constants[k].key, constants[k].value);
            ++k;
            continue;
        }
        std::vector<std::string> entries;
        for (; k < constants.size() && group_of(constants[k].key) == group; ++k) {
            entries.push_back(fmt::format("{} = {}", constants[k].key.substr(group.size() + 1), constants[k].value));
        }
        out += fmt::format("{} = {{ {} }}\n", group, fmt::join(entries, ", "));
    }
    return out;
}

std::vector<std::string> material_changes(const materials::Material& material, const materials::Material& base) {
    const auto mine = material_constants(material);
    const auto theirs = material_constants(base);
    std::vector<std::string> out;
    for (const auto& c : mine) {
        if (c.key == "name" || c.key == "source") continue;
        const auto same_key = std::find_if(theirs.begin(), theirs.end(), [&](const MaterialConstant& t) { return t.key == c.key; });
        if (same_key == theirs.end()) {
            out.push_back(fmt::format("{} = {} (base: none)", c.key, c.value));
        } else if (same_key->value != c.value) {
            out.push_back(fmt::format("{} = {} (base: {})", c.key, c.value, same_key->value));
        }
    }
    for (const auto& t : theirs) {
        if (t.key == "name" || t.key == "source") continue;
        if (std::none_of(mine.begin(), mine.end(), [&](const MaterialConstant& c) { return c.key == t.key; })) {
            out.push_back(fmt::format("no {} (base: {})", t.key, t.value));
        }
    }
    return out;
}

std::vector<materials::Material> parse_material_library(std::string_view text,
                                                        const std::string& file_name_for_messages) {
    const detail::OutsideMaterials builtin{find_builtin_material, builtin_material_names};
    return read_library(text, file_name_for_messages, builtin);
}

}  // namespace gpa::io
