#include "gpa/engine/solver_options.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "gpa/engine/weights.hpp"

namespace gpa {

namespace {

constexpr double inf = std::numeric_limits<double>::infinity();

// Interval constructors named by their brackets, so that each row reads like its range.
constexpr OptionRange closed(double lo, double hi) { return {lo, hi, true, true}; }        // [lo, hi]
constexpr OptionRange exclusive(double lo, double hi) { return {lo, hi, false, false}; }   // (lo, hi)
constexpr OptionRange closed_open(double lo, double hi) { return {lo, hi, true, false}; }  // [lo, hi)
constexpr OptionRange open_closed(double lo, double hi) { return {lo, hi, false, true}; }  // (lo, hi]

// A choice row for the enum member `member`: its accessors cast between the enum and int, the
// only place where the enum's type is known.
template <class E>
ChoiceOption choice_of(E SolverOptions::* member, std::initializer_list<std::pair<std::string_view, E>> words) {
    static_assert(std::is_enum_v<E>);
    ChoiceOption c;
    for (const auto& [word, value] : words) c.words.push_back({word, static_cast<int>(value)});
    c.get = [member](const SolverOptions& s) { return static_cast<int>(s.*member); };
    c.set = [member](SolverOptions& s, int v) { s.*member = static_cast<E>(v); };
    return c;
}

NumberOption number(double SolverOptions::* member, OptionRange range) { return {member, OptionUnit::Dimensionless, range}; }
NumberOption duration(double SolverOptions::* member, OptionRange range) { return {member, OptionUnit::Time, range}; }

// The rows, in the order of docs/scene-format.md's [solver] table.
std::vector<SolverOption> make_table() {
    using S = SolverOptions;
    std::vector<SolverOption> t;
    t.push_back({"connectivity",
                 choice_of(&S::connectivity, {{"fixed", ConnectivityMode::Fixed},
                                              {"variable", ConnectivityMode::Variable},
                                              {"automatic", ConnectivityMode::Automatic}}),
                 "neighbour lists: lattice neighbours, all nodes within 2 h re-found every step, or fixed until "
                 "switch_plastic_strain",
                 ""});
    t.push_back({"switch_plastic_strain", number(&S::switch_plastic_strain, exclusive(0.0, inf)),
                 "equivalent plastic strain that ends the lattice regime of a node", ""});
    t.push_back({"influence_distance", number(&S::influence_distance, closed(min_influence_distance, max_influence_distance)),
                 "dimensionless influence distance a (Eq. 2)", "the method's range"});
    t.push_back({"node_diameter",
                 choice_of(&S::node_diameter, {{"hoop", NodeDiameter::Hoop},
                                               {"volume", NodeDiameter::Volume},
                                               {"section", NodeDiameter::Section},
                                               {"stretch", NodeDiameter::Stretch}}),
                 "how a particle node's diameter follows the deformation (section = Eq. 3 as printed; stretch: 3D, the largest isochoric stretch)", ""});
    t.push_back({"weight", choice_of(&S::weight, {{"gpa", WeightKind::Gpa}, {"sph-nsf", WeightKind::SphNsf}}),
                 "variable-connectivity weight: GPA (Eq. 1b) or the SPH-NSF cubic spline (Eqs. 62-65)", ""});
    t.push_back({"normalisation",
                 choice_of(&S::normalisation, {{"per-direction", Normalisation::PerDirection},
                                               {"moment-matrix", Normalisation::MomentMatrix}}),
                 "geometry factors alpha_b (Eq. 14-15) or the inverse of the full moment matrix", ""});
    t.push_back({"surface_correction", BooleanOption{&S::surface_correction},
                 "halve the geometry factor normal to a free surface (the paper's section 2.5; per axis, or along the "
                 "neighbourhood's normal with the moment matrix)",
                 ""});
    t.push_back({"force_form",
                 choice_of(&S::force_form, {{"pairwise", ForceForm::Pairwise}, {"stress-difference", ForceForm::StressDifference}}),
                 "stress forces: equal and opposite pair forces (Eq. 29) or each node's own divergence of the stress (Eq. 28)", ""});
    t.push_back({"viscosity",
                 choice_of(&S::viscosity, {{"none", ViscosityKind::None},
                                           {"nodal", ViscosityKind::Nodal},
                                           {"bond", ViscosityKind::Bond}}),
                 "artificial viscosity (Eqs. 36-38)", ""});
    t.push_back({"viscosity_linear", number(&S::viscosity_linear, closed_open(0.0, inf)), "C_L of the viscosity (Eq. 36-37)", ""});
    t.push_back({"viscosity_quadratic", number(&S::viscosity_quadratic, closed_open(0.0, inf)),
                 "C_Q of the viscosity (Eq. 36-37)", ""});
    t.push_back({"bond_viscosity_eps0", number(&S::bond_viscosity_eps0, exclusive(0.0, inf)), "eps0 of the bond viscosity (Eq. 38)", ""});
    t.push_back({"hourglass_coefficient", number(&S::hourglass_coefficient, closed(0.0, 1.0)),
                 "C_hg, damping of the zero-energy modes of lattice-regime nodes (or of every node: hourglass_nodes)", "0 = off"});
    t.push_back({"hourglass_nodes",
                 choice_of(&S::hourglass_nodes, {{"automatic", HourglassNodes::Automatic},
                                                 {"lattice", HourglassNodes::Lattice},
                                                 {"all", HourglassNodes::All}}),
                 "the nodes the hourglass damping acts on: the lattice regime, every node that has not failed, or "
                 "automatic (every node in 3D, the lattice regime in 2D)",
                 ""});
    t.push_back({"hourglass_fit", choice_of(&S::hourglass_fit, {{"linear", HourglassFitOrder::Linear}, {"quadratic", HourglassFitOrder::Quadratic}}),
                 "the hourglass control's fit around a centre: affine, or with second derivatives (the damping's, and the relaxing stiffness's)", ""});
    t.push_back({"hourglass_stiffness", number(&S::hourglass_stiffness, closed(0.0, 1.0)),
                 "C_hs, stiffness against the non-affine displacement of fixed nodes' lattice pairs", "0 = off"});
    t.push_back({"hourglass_stiffness_relaxation", duration(&S::hourglass_stiffness_relaxation, closed_open(0.0, inf)),
                 "time constant of the relaxing reference of the stiffness form on flowing nodes", "0 = fixed nodes only"});
    t.push_back({"smoothing",
                 choice_of(&S::smoothing, {{"off", SmoothingMode::Off},
                                           {"everywhere", SmoothingMode::Everywhere},
                                           {"tension", SmoothingMode::Tension}}),
                 "velocity smoothing (Eqs. 66-73); tension: only around nodes with negative pressure", ""});
    t.push_back({"smoothing_coefficient", number(&S::smoothing_coefficient, closed_open(0.0, 1.0)), "C_cs (Eq. 67)", ""});
    t.push_back({"cfl", number(&S::cfl, open_closed(0.0, 1.0)), "C_cfl of the stable time step", ""});
    t.push_back({"alpha_limit", number(&S::alpha_limit, closed_open(0.0, inf)),
                 "upper bound on the geometry factors, alpha_b <= alpha_limit / W_i", "0 = no limit"});
    t.push_back({"max_time_step", duration(&S::max_time_step, open_closed(0.0, inf)), "upper bound of the time step",
                 "inf = no limit"});
    t.push_back({"time_step_growth", number(&S::time_step_growth, closed_open(1.0, inf)),
                 "largest ratio of one step to the previous", ""});
    t.push_back({"max_volume_change", number(&S::max_volume_change, closed_open(0.0, 1.0)),
                 "largest fraction by which one step may change a node's volume", "0 = no limit"});
    t.push_back({"failure", BooleanOption{&S::failure}, "apply the materials' failure models (Johnson-Cook damage, spall)", ""});
    t.push_back({"energy_update",
                 choice_of(&S::energy_update, {{"compatible", EnergyUpdate::Compatible}, {"point", EnergyUpdate::Point}}),
                 "internal energy from the work of the stress forces, or the point update's own equation", ""});
    t.push_back({"separate_failed", BooleanOption{&S::separate_failed},
                 "with failure: a pair with a failed node may open like a pair between bodies", ""});
    t.push_back({"sliding_contact", BooleanOption{&S::sliding_contact},
                 "closed pairs between bodies and through cracks carry no shear (frictionless sliding)", ""});
    t.push_back({"scatter",
                 choice_of(&S::scatter, {{"slabs", ScatterScheme::Slabs},
                                         {"cells", ScatterScheme::Cells},
                                         {"graph", ScatterScheme::Graph},
                                         {"serial", ScatterScheme::Serial}}),
                 "force-scatter plan (plans differ only in the order of summation)", ""});
    t.push_back({"reorder_interval", WholeNumberOption{&S::reorder_interval, closed_open(0.0, inf)},
                 "steps between locality reorderings", "0 = never"});
    t.push_back({"neighbour_skin", number(&S::neighbour_skin, closed(0.0, 1.0)),
                 "skin of the neighbour lists, a fraction of the largest interaction radius",
                 "0 = a full search every step"});
    return t;
}

std::string number_text(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    return fmt::format("{}", v);
}

}  // namespace

bool OptionRange::contains(double value) const {
    if (std::isnan(value)) return false;
    const bool above = lowest_included ? value >= lowest : value > lowest;
    const bool below = highest_included ? value <= highest : value < highest;
    return above && below;
}

bool OptionRange::allows_infinity() const { return std::isinf(highest) && highest_included; }

std::string OptionRange::text() const {
    return fmt::format("{}{}, {}{}", lowest_included ? '[' : '(', number_text(lowest), number_text(highest),
                       highest_included ? ']' : ')');
}

std::optional<std::string_view> ChoiceOption::word_of(const SolverOptions& s) const {
    const int v = get(s);
    for (const auto& w : words) {
        if (w.value == v) return w.word;
    }
    return std::nullopt;
}

std::optional<int> ChoiceOption::value_of(std::string_view word) const {
    for (const auto& w : words) {
        if (w.word == word) return w.value;
    }
    return std::nullopt;
}

std::string ChoiceOption::list(bool quoted) const {
    std::string out;
    for (const auto& w : words) {
        out += fmt::format("{}{}{}{}", out.empty() ? "" : ", ", quoted ? "\"" : "", w.word, quoted ? "\"" : "");
    }
    return out;
}

std::span<const SolverOption> solver_option_table() {
    static const std::vector<SolverOption> table = make_table();
    return table;
}

const SolverOption* find_solver_option(std::string_view key) {
    for (const auto& row : solver_option_table()) {
        if (row.key == key) return &row;
    }
    return nullptr;
}

std::vector<std::string_view> solver_option_keys() {
    std::vector<std::string_view> keys;
    for (const auto& row : solver_option_table()) keys.push_back(row.key);
    return keys;
}

std::string option_value_text(const SolverOption& option, const SolverOptions& s) {
    return std::visit(
        [&](const auto& k) -> std::string {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                const double v = s.*k.member;
                return k.unit == OptionUnit::Time && std::isfinite(v) ? number_text(v) + " s" : number_text(v);
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                return fmt::format("{}", s.*k.member);
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                return s.*k.member ? "true" : "false";
            } else {
                const auto word = k.word_of(s);
                return word ? fmt::format("\"{}\"", *word) : fmt::format("{} (no listed word)", k.get(s));
            }
        },
        option.kind);
}

std::string option_default_text(const SolverOption& option) { return option_value_text(option, SolverOptions{}); }

std::string option_allowed_text(const SolverOption& option) {
    return std::visit(
        [](const auto& k) -> std::string {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                return k.unit == OptionUnit::Time ? k.range.text() + " s" : k.range.text();
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                return "whole numbers in " + k.range.text();
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                return "true or false";
            } else {
                return k.list(false);
            }
        },
        option.kind);
}

std::optional<std::string> option_error(const SolverOption& option, const SolverOptions& s) {
    const std::string note = option.range_note.empty() ? "" : fmt::format(" ({})", option.range_note);
    return std::visit(
        [&](const auto& k) -> std::optional<std::string> {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                const double v = s.*k.member;
                if (k.range.contains(v)) return std::nullopt;
                return fmt::format("solver.{} = {}{} is outside {}{}", option.key, number_text(v),
                                   k.unit == OptionUnit::Time ? " s" : "", option_allowed_text(option), note);
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                const std::size_t v = s.*k.member;
                if (k.range.contains(static_cast<double>(v))) return std::nullopt;
                return fmt::format("solver.{} = {} is outside {}{}", option.key, v, k.range.text(), note);
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                return std::nullopt;
            } else {
                if (k.word_of(s)) return std::nullopt;
                return fmt::format("solver.{}: {} is not a known value; the words are {}", option.key, k.get(s), k.list(true));
            }
        },
        option.kind);
}

std::span<const SolverPreset> solver_presets() {
    // docs/validation.md has the measurements behind each.
    static const std::vector<SolverPreset> presets{
        {"paper",
         "the paper's kernel: its weight R = 1 - v/2 (Eq. 1b) at a = 1 with the per-direction geometry factors; best on "
         "the elastic bar, spall, perforation and the stretched bar",
         {{"weight", "gpa"}, {"influence_distance", "1"}, {"normalisation", "per-direction"}}},
        {"taylor-bar",
         "the SPH-NSF cubic spline at a = 1.3 with the per-direction factors: within 0.6 % of converged elements on "
         "every Johnson-Cook Taylor bar, worse than the paper's on the other scenes",
         {{"weight", "sph-nsf"}, {"influence_distance", "1.3"}, {"normalisation", "per-direction"}}},
    };
    return presets;
}

const SolverPreset* find_solver_preset(std::string_view name) {
    for (const SolverPreset& p : solver_presets()) {
        if (p.name == name) return &p;
    }
    return nullptr;
}

std::string solver_preset_list(bool quoted) {
    std::string s;
    for (const SolverPreset& p : solver_presets()) {
        s += fmt::format("{}{}{}{}", s.empty() ? "" : ", ", quoted ? "\"" : "", p.name, quoted ? "\"" : "");
    }
    return s;
}

void apply_solver_preset(const SolverPreset& preset, SolverOptions& s) {
    for (const auto& setting : preset.settings) {
        // Plain names, not a structured binding: clang 14 (the sanitizer build) refuses lambdas
        // that capture one.
        const std::string_view key = setting.first, value = setting.second;
        const SolverOption* option = find_solver_option(key);
        if (!option) throw std::logic_error(fmt::format("preset {}: {} is no solver option", preset.name, key));
        std::visit(
            [&](const auto& row) {
                using Row = std::decay_t<decltype(row)>;
                if constexpr (std::is_same_v<Row, NumberOption>) {
                    s.*row.member = std::stod(std::string(value));
                } else if constexpr (std::is_same_v<Row, WholeNumberOption>) {
                    s.*row.member = static_cast<std::size_t>(std::stoull(std::string(value)));
                } else if constexpr (std::is_same_v<Row, BooleanOption>) {
                    s.*row.member = value == "true";
                } else {
                    const auto v = row.value_of(value);
                    if (!v) throw std::logic_error(fmt::format("preset {}: {} is no word of {}", preset.name, value, key));
                    row.set(s, *v);
                }
            },
            option->kind);
    }
}

}  // namespace gpa
