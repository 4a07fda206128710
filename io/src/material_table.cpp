#include "material_table.hpp"

#include <optional>
#include <variant>

#include <fmt/format.h>

namespace gpa::io::detail {

namespace m = gpa::materials;

bool same_name(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; };
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

namespace {

using D = Dimension;

// --- model tables: eos and strength -----------------------------------------------------------

// A model key holds either a word ("elastic") or a table with `model = "..."` and the model's
// constants. Without `model` the table changes the constants of the base material's model.
struct ModelNode {
    const toml::table* table = nullptr;  // null for the one-word form
    std::optional<std::string> model;    // the word, when given
    std::size_t line = 0;
};

ModelNode model_node(const TableReader& material, std::string_view key) {
    const toml::node* node = material.find(key);
    ModelNode out;
    out.line = line_of(*node);
    if (const auto* word = node->as_string()) {
        out.model = word->get();
        return out;
    }
    out.table = node->as_table();
    if (!out.table) {
        material.fail_at(key, fmt::format("expected a model name or a table with `model = \"...\"` and its constants, got {}",
                                          type_name(*node)));
    }
    if (const toml::node* model = out.table->get("model")) {
        const auto* word = model->as_string();
        if (!word) {
            material.reporter().fail(line_of(*model), material.key_path(key) + ".model",
                                     fmt::format("expected a string, got {}", type_name(*model)));
        }
        out.model = word->get();
    }
    return out;
}

template <class Variant>
struct ModelChoice {
    std::string_view name;
    Variant fresh;  // the model with its defaults, constants to be filled
    std::vector<std::string_view> keys;  // allowed in its table, "model" included
};

// Resolves which model a material ends up with, and the starting values of its constants:
// the base's when the model is unchanged, the model's defaults otherwise (then every constant
// without a default is required).
template <class Variant>
std::pair<Variant, bool> start_model(const TableReader& material, std::string_view key, const ModelNode& node,
                                     const Variant* base, const std::vector<ModelChoice<Variant>>& choices,
                                     std::size_t& chosen) {
    if (!node.model) {
        if (!base) {
            material.reporter().fail(node.line, material.key_path(key),
                                     "missing required key \"model\" (the table of a material without `base` names its model)");
        }
        for (std::size_t i = 0; i < choices.size(); ++i) {
            if (choices[i].fresh.index() == base->index()) chosen = i;
        }
        return {*base, false};
    }
    for (std::size_t i = 0; i < choices.size(); ++i) {
        if (*node.model != choices[i].name) continue;
        chosen = i;
        if (base && base->index() == choices[i].fresh.index()) return {*base, false};
        return {choices[i].fresh, true};
    }
    std::vector<std::string_view> names;
    std::string list;
    for (const auto& c : choices) {
        names.push_back(c.name);
        list += list.empty() ? "" : ", ";
        list += fmt::format("\"{}\"", c.name);
    }
    std::string message = fmt::format("unknown model {}; {} is one of {}", in_quotes(*node.model), key, list);
    if (const auto s = closest(*node.model, names)) message += fmt::format(" (did you mean \"{}\"?)", *s);
    const std::string path = material.key_path(key) + (node.table ? ".model" : "");
    material.reporter().fail(node.line, path, message);
}

// A reader over the model's table, or over an empty one for the one-word form.
struct ModelTable {
    toml::table empty;
    std::optional<TableReader> reader;
};

void open_model_table(ModelTable& out, const TableReader& material, std::string_view key, const ModelNode& node,
                      std::string what, const std::vector<std::string_view>& keys) {
    const toml::table& table = node.table ? *node.table : out.empty;
    out.reader.emplace(material.reporter(), table, material.key_path(key), std::move(what), keys);
}

// Fills `value` from the key, or requires it when `required`.
void read_constant(const TableReader& t, std::string_view key, double& value, D d, Limit limit, bool required) {
    if (required) {
        value = t.required_quantity(key, d, limit);
    } else if (const auto v = t.quantity(key, d, limit)) {
        value = *v;
    }
}

m::EquationOfState read_eos(const TableReader& material, const m::EquationOfState* base) {
    const std::vector<ModelChoice<m::EquationOfState>> choices{
        {"linear", m::LinearEos{}, {"model", "bulk_modulus", "logarithmic"}},
        {"polynomial", m::PolynomialEos{}, {"model", "k1", "k2", "k3", "gruneisen"}},
        {"mie-gruneisen", m::MieGruneisenEos{}, {"model", "sound_speed", "slope", "gruneisen"}},
    };
    const ModelNode node = model_node(material, "eos");
    std::size_t chosen = 0;
    auto [eos, fresh] = start_model(material, "eos", node, base, choices, chosen);
    ModelTable table;
    open_model_table(table, material, "eos", node, fmt::format("a \"{}\" equation of state", choices[chosen].name),
                     choices[chosen].keys);
    const TableReader& t = *table.reader;
    if (auto* linear = std::get_if<m::LinearEos>(&eos)) {
        read_constant(t, "bulk_modulus", linear->bulk_modulus, D::Pressure, Limit::Positive, fresh);
        if (const auto log = t.boolean("logarithmic")) linear->logarithmic = *log;
    } else if (auto* poly = std::get_if<m::PolynomialEos>(&eos)) {
        read_constant(t, "k1", poly->k1, D::Pressure, Limit::Positive, fresh);
        read_constant(t, "k2", poly->k2, D::Pressure, Limit::Any, false);
        read_constant(t, "k3", poly->k3, D::Pressure, Limit::Any, false);
        read_constant(t, "gruneisen", poly->gruneisen, D::Dimensionless, Limit::NonNegative, false);
    } else if (auto* mg = std::get_if<m::MieGruneisenEos>(&eos)) {
        read_constant(t, "sound_speed", mg->sound_speed, D::Velocity, Limit::Positive, fresh);
        read_constant(t, "slope", mg->slope, D::Dimensionless, Limit::NonNegative, fresh);
        read_constant(t, "gruneisen", mg->gruneisen, D::Dimensionless, Limit::NonNegative, fresh);
    }
    return eos;
}

m::Strength read_strength(const TableReader& material, const m::Strength* base) {
    const std::vector<ModelChoice<m::Strength>> choices{
        {"elastic", m::ElasticStrength{}, {"model"}},
        {"von-mises", m::VonMisesStrength{}, {"model", "yield_stress", "hardening_modulus"}},
        {"johnson-cook", m::JohnsonCookStrength{}, {"model", "a", "b", "n", "c", "m", "reference_strain_rate"}},
    };
    const ModelNode node = model_node(material, "strength");
    std::size_t chosen = 0;
    auto [strength, fresh] = start_model(material, "strength", node, base, choices, chosen);
    ModelTable table;
    open_model_table(table, material, "strength", node, fmt::format("\"{}\" strength", choices[chosen].name),
                     choices[chosen].keys);
    const TableReader& t = *table.reader;
    if (auto* vm = std::get_if<m::VonMisesStrength>(&strength)) {
        read_constant(t, "yield_stress", vm->yield_stress, D::Pressure, Limit::NonNegative, fresh);
        read_constant(t, "hardening_modulus", vm->hardening_modulus, D::Pressure, Limit::NonNegative, false);
    } else if (auto* jc = std::get_if<m::JohnsonCookStrength>(&strength)) {
        read_constant(t, "a", jc->a, D::Pressure, Limit::NonNegative, fresh);
        read_constant(t, "b", jc->b, D::Pressure, Limit::NonNegative, fresh);
        read_constant(t, "n", jc->n, D::Dimensionless, Limit::NonNegative, fresh);
        read_constant(t, "c", jc->c, D::Dimensionless, Limit::NonNegative, fresh);
        read_constant(t, "m", jc->m, D::Dimensionless, Limit::Positive, fresh);
        read_constant(t, "reference_strain_rate", jc->reference_strain_rate, D::StrainRate, Limit::Positive, false);
    }
    return strength;
}

// --- failure ------------------------------------------------------------------------------

bool is_none(const toml::node& node) {
    const auto* word = node.as_string();
    return word && word->get() == "none";
}

m::JohnsonCookFailure read_johnson_cook_failure(const TableReader& failure, const m::JohnsonCookFailure* base) {
    const toml::node* node = failure.find("johnson_cook");
    const auto* table = node->as_table();
    if (!table) {
        failure.fail_at("johnson_cook", fmt::format("expected a table of D1-D5 (d1 = ..., ...) or \"none\", got {}",
                                                    as_written(*node)));
    }
    const TableReader t(failure.reporter(), *table, failure.key_path("johnson_cook"), "Johnson-Cook fracture",
                        {"d1", "d2", "d3", "d4", "d5", "reference_strain_rate", "min_failure_strain"});
    m::JohnsonCookFailure f = base ? *base : m::JohnsonCookFailure{};
    const bool required = base == nullptr;
    read_constant(t, "d1", f.d1, D::Dimensionless, Limit::Any, required);
    read_constant(t, "d2", f.d2, D::Dimensionless, Limit::Any, required);
    read_constant(t, "d3", f.d3, D::Dimensionless, Limit::Any, required);
    read_constant(t, "d4", f.d4, D::Dimensionless, Limit::Any, required);
    read_constant(t, "d5", f.d5, D::Dimensionless, Limit::Any, required);
    read_constant(t, "reference_strain_rate", f.reference_strain_rate, D::StrainRate, Limit::Positive, false);
    read_constant(t, "min_failure_strain", f.min_failure_strain, D::Dimensionless, Limit::Positive, false);
    return f;
}

m::Failure read_failure(const TableReader& material, const m::Failure& base) {
    const toml::node* node = material.find("failure");
    if (is_none(*node)) return {};
    const auto* table = node->as_table();
    if (!table) {
        material.fail_at("failure", fmt::format("expected a table (spall_pressure, johnson_cook) or \"none\", got {}",
                                                as_written(*node)));
    }
    const TableReader t(material.reporter(), *table, material.key_path("failure"), "failure",
                        {"spall_pressure", "johnson_cook"});
    m::Failure f = base;
    if (const toml::node* spall = t.find("spall_pressure")) {
        if (is_none(*spall)) {
            f.spall_pressure.reset();
        } else {
            f.spall_pressure = t.quantity("spall_pressure", D::Pressure, Limit::Positive);
        }
    }
    if (const toml::node* jc = t.find("johnson_cook")) {
        if (is_none(*jc)) {
            f.johnson_cook.reset();
        } else {
            f.johnson_cook = read_johnson_cook_failure(t, base.johnson_cook ? &*base.johnson_cook : nullptr);
        }
    }
    return f;
}

// --- one material -------------------------------------------------------------------------

const std::vector<std::string_view> material_keys{
    "name",          "base",          "source",           "density",          "shear_modulus", "specific_heat",
    "taylor_quinney", "room_temperature", "melt_temperature", "eos",           "strength",      "failure",
};

std::string material_path(const toml::table& table, std::size_t index) {
    if (const toml::node* name = table.get("name")) {
        if (const auto* s = name->as_string()) return fmt::format("material {} (material[{}])", in_quotes(s->get()), index);
    }
    return fmt::format("material[{}]", index);
}

m::Material read_material(const Reporter& reporter, const toml::table& table, std::size_t index,
                          const std::vector<m::Material>& earlier, const OutsideMaterials& outside) {
    const TableReader r(reporter, table, material_path(table, index), "a material", material_keys);
    const std::string name = r.required_string("name", "the name bodies use for the material");
    if (name.empty()) r.fail_at("name", "a material's name must not be empty");
    for (const auto& other : earlier) {
        if (same_name(other.name, name)) {
            r.fail_at("name", fmt::format("another [[material]] is already called {}", in_quotes(other.name)));
        }
    }

    const m::Material* base = nullptr;
    if (const auto base_name = r.string("base")) {
        for (const auto& other : earlier) {
            if (same_name(other.name, *base_name)) base = &other;
        }
        if (!base && outside.find) base = outside.find(*base_name);
        if (!base) {
            std::string known;
            for (const auto& other : earlier) known += (known.empty() ? "" : ", ") + other.name;
            if (outside.names) {
                const std::string library = outside.names();
                if (!library.empty()) known += (known.empty() ? "" : ", ") + library;
            }
            r.fail_at("base", fmt::format("unknown base material {}; known materials: {}", in_quotes(*base_name),
                                          known.empty() ? "none (define the base in an earlier [[material]])" : known));
        }
    } else {
        for (const std::string_view key : {"density", "shear_modulus", "eos", "strength"}) {
            if (!r.has(key)) {
                r.fail_missing(key, key == "eos"        ? "an equation of state: linear, polynomial or mie-gruneisen"
                                    : key == "strength" ? "a strength model: elastic, von-mises or johnson-cook"
                                    : key == "density"  ? "a density such as \"8.96 g/cc\""
                                                        : "a shear modulus such as \"46 GPa\"");
            }
        }
    }

    m::Material mat = base ? *base : m::Material{};
    mat.name = name;
    mat.base = base ? base->name : std::string();
    if (const auto v = r.quantity("density", D::Density, Limit::Positive)) mat.density = *v;
    if (const auto v = r.quantity("shear_modulus", D::Pressure, Limit::NonNegative)) mat.shear_modulus = *v;
    if (const auto v = r.quantity("specific_heat", D::SpecificHeat, Limit::NonNegative)) mat.specific_heat = *v;
    if (const auto v = r.quantity("taylor_quinney", D::Dimensionless, Limit::NonNegative)) mat.taylor_quinney = *v;
    if (const auto v = r.quantity("room_temperature", D::Temperature, Limit::Positive)) mat.room_temperature = *v;
    if (const auto v = r.quantity("melt_temperature", D::Temperature, Limit::PositiveOrInfinite)) {
        mat.melt_temperature = *v;
    }
    if (r.has("eos")) mat.eos = read_eos(r, base ? &base->eos : nullptr);
    if (r.has("strength")) mat.strength = read_strength(r, base ? &base->strength : nullptr);
    if (r.has("failure")) mat.failure = read_failure(r, base ? base->failure : m::Failure{});

    if (const auto source = r.string("source")) {
        mat.source = *source;
    } else if (base) {
        std::string changed;
        for (const auto& [key, value] : table) {
            const std::string_view k = key.str();
            if (k == "name" || k == "base") continue;
            changed += (changed.empty() ? "" : ", ") + std::string(k);
        }
        mat.source = fmt::format("{} with {} changed in {}. {}: {}", base->name, changed.empty() ? "nothing" : changed,
                                 reporter.file(), base->name, base->source);
    }
    return mat;
}

}  // namespace

std::vector<m::Material> read_materials(const Reporter& reporter, const toml::node* node,
                                        const OutsideMaterials& outside) {
    std::vector<m::Material> out;
    if (!node) return out;
    const auto* array = node->as_array();
    if (!array) {
        reporter.fail(line_of(*node), "material",
                      fmt::format("expected [[material]] tables (an array of tables), got {}", type_name(*node)));
    }
    for (std::size_t i = 0; i < array->size(); ++i) {
        const toml::node& element = (*array)[i];
        const auto* table = element.as_table();
        if (!table) {
            reporter.fail(line_of(element), fmt::format("material[{}]", i),
                          fmt::format("expected a table, got {}", type_name(element)));
        }
        out.push_back(read_material(reporter, *table, i, out, outside));
    }
    return out;
}

}  // namespace gpa::io::detail
