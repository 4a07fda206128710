#include "gpa/io/study.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numeric>
#include <optional>
#include <set>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/solver_options.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/svg_plot.hpp"
#include "solver_reading.hpp"

namespace gpa::io {

namespace fs = std::filesystem;

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Bisection brackets the observed order in [-max_order, max_order].
constexpr double max_order = 64.0;

// ln of (h1^p - h2^p) / (h2^p - h3^p) in terms of la = ln(h1/h3) > lb = ln(h2/h3) > 0, written
// so that neither large |p| nor p near 0 loses the answer to overflow or cancellation. Both
// numerator and denominator share the sign of p, so the ratio is positive for every p.
double log_difference_ratio(double p, double la, double lb) {
    if (p == 0.0) return std::log((la - lb) / lb);  // the limit p -> 0
    if (p > 0.0) {
        // h1^p - h2^p = a^p (1 - e^{-p (la - lb)}), h2^p - h3^p = e^{p lb} - 1.
        return p * la + std::log(-std::expm1(-p * (la - lb))) - std::log(std::expm1(p * lb));
    }
    // p < 0: (b^p - a^p) / (1 - b^p) = b^p (1 - e^{p (la - lb)}) / (1 - e^{p lb}).
    return p * lb + std::log(-std::expm1(p * (la - lb))) - std::log(-std::expm1(p * lb));
}

std::string trim(std::string_view s) {
    const auto first = s.find_first_not_of(" \t");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t");
    return std::string(s.substr(first, last - first + 1));
}

std::vector<std::string> split(std::string_view text, char separator) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (true) {
        const auto end = text.find(separator, start);
        parts.push_back(trim(text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start)));
        if (end == std::string_view::npos) break;
        start = end + 1;
    }
    return parts;
}

std::optional<double> to_double(const std::string& s) {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
    return v;
}

std::optional<long> to_long(const std::string& s) {
    long v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
    return v;
}

// --- variant keys --------------------------------------------------------------------------

// A variant sets the keys of the engine's table of solver options (solver_options.hpp), with the
// scene file's words, units and ranges, plus two keys of its own.

// discretisation: every body's discretisation (not a solver option).
const std::vector<std::pair<std::string_view, Discretisation>> discretisation_words{
    {"particles", Discretisation::Particles}, {"elements", Discretisation::Elements}};

std::string allowed_keys() {
    std::string s;
    for (const auto& option : solver_option_table()) s += fmt::format("{}{}", s.empty() ? "" : ", ", option.key);
    return s + ", preset, discretisation, threads";
}

// A row's values for the help text: "fixed|variable|automatic", "NUMBER", "TIME", "true|false", "N".
std::string values_help(const SolverOption& option) {
    return std::visit(
        [](const auto& k) -> std::string {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                return k.unit == OptionUnit::Time ? "TIME" : "NUMBER";
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                return "N";
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                return "true|false";
            } else {
                std::string words;
                for (const auto& w : k.words) words += fmt::format("{}{}", words.empty() ? "" : "|", w.word);
                return words;
            }
        },
        option.kind);
}

// --- formatting ----------------------------------------------------------------------------

std::string csv_field(const std::string& s) {
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) {
        if (c == '"') out += '"';
        out += (c == '\n' || c == '\r') ? ' ' : c;
    }
    return out + "\"";
}

std::string csv_number(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : ""; }

// A value for a Markdown table: four significant figures, "-" when missing.
std::string cell(double v, int digits = 4) {
    if (!std::isfinite(v)) return "-";
    return fmt::format("{:.{}g}", v, digits);
}

std::string percent(double v) {
    if (!std::isfinite(v)) return "-";
    const double a = std::abs(100.0 * v);
    return fmt::format("{:+.{}f} %", 100.0 * v, a >= 10.0 ? 1 : a >= 0.1 ? 2 : 3);
}

std::string unit_suffix(const MetricInfo& m) {
    std::string s;
    for (char c : m.unit) s += (c == '/' || c == ' ') ? '_' : c;
    return s.empty() ? m.key : m.key + "_" + s;
}

std::string order_text(double p) {
    if (std::isnan(p)) return "-";
    if (std::isinf(p)) return p > 0.0 ? "> 64" : "< -64";
    return fmt::format("{:.2f}", p);
}

std::string memory_mb(double bytes) { return std::isfinite(bytes) ? fmt::format("{:.1f}", bytes / 1048576.0) : "-"; }

double bytes_per_node(const StudyCase& c) { return c.nodes > 0 ? c.case_bytes / double(c.nodes) : nan; }

const std::map<std::string, CaseErrors>& errors_of(const StudyAnalysis& a, std::size_t k) {
    static const std::map<std::string, CaseErrors> none;
    return k < a.errors.size() ? a.errors[k] : none;
}

double metric_value(const StudyCase& c, const std::string& key) {
    const auto it = c.metrics.find(key);
    return c.finished && it != c.metrics.end() ? it->second : nan;
}

// The ratio columns against an element reference: (metric key, column name, table heading).
const std::vector<std::array<const char*, 3>> ratio_columns{
    {"final_length", "L_star", "L*"},
    {"footprint_diameter", "D_star", "D*"},
    {"plastic_work", "PW_star", "PW*"},
    {"peak_plastic_strain", "peak_plastic_strain_star", "peak strain*"},
    {"peak_temperature", "peak_temperature_star", "peak T*"},
};

std::map<std::string, double> ratios_of(const StudyReport& report, const StudyCase& c) {
    if (!report.element_reference || !c.finished) return {};
    return compare_with_reference(c.metrics, c.outline, *report.element_reference);
}

double ratio_value(const std::map<std::string, double>& r, const std::string& key) {
    const auto it = r.find(key);
    return it != r.end() ? it->second : nan;
}

}  // namespace

// --- Richardson extrapolation --------------------------------------------------------------

std::string_view describe(ConvergenceStatus s) {
    switch (s) {
        case ConvergenceStatus::Converging: return "converging";
        case ConvergenceStatus::Unchanged: return "unchanged";
        case ConvergenceStatus::NotMonotone: return "not monotone";
        case ConvergenceStatus::Diverging: return "diverging";
        case ConvergenceStatus::TooFew: return "fewer than three resolutions";
        case ConvergenceStatus::NotAvailable: return "a value is missing";
    }
    return "?";
}

double observed_order(double h1, double h2, double h3, double f1, double f2, double f3) {
    if (!(h1 > h2 && h2 > h3 && h3 > 0.0) || !std::isfinite(h1)) {
        throw std::invalid_argument(fmt::format("observed_order: spacings {}, {}, {} are not decreasing and positive", h1, h2, h3));
    }
    if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3)) return nan;
    const double e21 = f1 - f2, e32 = f2 - f3;
    if (!(e21 * e32 > 0.0)) return nan;  // not monotone (or no change)
    const double la = std::log(h1 / h3), lb = std::log(h2 / h3);
    const double target = std::log(e21 / e32);
    const double r21 = h1 / h2, r32 = h2 / h3;
    // A constant ratio has the closed form; exact to round-off.
    if (std::abs(r21 / r32 - 1.0) < 1e-12) return target / std::log(r32);
    // Otherwise bisection on the strictly increasing log_difference_ratio.
    double lo = -max_order, hi = max_order;
    if (target >= log_difference_ratio(hi, la, lb)) return INFINITY;
    if (target <= log_difference_ratio(lo, la, lb)) return -INFINITY;
    for (int it = 0; it < 400 && hi - lo > 1e-15 * std::max(1.0, std::abs(lo)); ++it) {
        const double mid = 0.5 * (lo + hi);
        (log_difference_ratio(mid, la, lb) < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double richardson_gain(double h2, double h3, double order) {
    if (std::isinf(order) && order > 0.0) return 0.0;
    return 1.0 / std::expm1(order * std::log(h2 / h3));
}

double richardson_limit(double h2, double h3, double f2, double f3, double order) {
    return f3 + (f3 - f2) * richardson_gain(h2, h3, order);
}

Extrapolation extrapolate(std::span<const double> spacing, std::span<const double> value) {
    if (spacing.size() != value.size()) throw std::invalid_argument("extrapolate: as many spacings as values are needed");
    std::vector<std::size_t> order(spacing.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    for (double h : spacing) {
        if (!(h > 0.0) || !std::isfinite(h)) throw std::invalid_argument(fmt::format("extrapolate: spacing {} is not positive", h));
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return spacing[a] > spacing[b]; });
    for (std::size_t k = 1; k < order.size(); ++k) {
        if (!(spacing[order[k - 1]] > spacing[order[k]])) {
            throw std::invalid_argument(fmt::format("extrapolate: spacing {} appears twice", spacing[order[k]]));
        }
    }
    Extrapolation e;
    if (order.size() < 3) return e;  // TooFew
    const std::size_t n = order.size();
    e.used = {order[n - 3], order[n - 2], order[n - 1]};
    const double h1 = spacing[e.used[0]], h2 = spacing[e.used[1]], h3 = spacing[e.used[2]];
    const double f1 = value[e.used[0]], f2 = value[e.used[1]], f3 = value[e.used[2]];
    e.ratio = h2 / h3;
    if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3)) {
        e.status = ConvergenceStatus::NotAvailable;
        return e;
    }
    if (f1 == f2 && f2 == f3) {
        e.status = ConvergenceStatus::Unchanged;
        e.extrapolated = f3;
        return e;
    }
    e.order = observed_order(h1, h2, h3, f1, f2, f3);
    if (std::isnan(e.order)) {
        e.status = ConvergenceStatus::NotMonotone;
    } else if (!(e.order > 0.0)) {
        e.status = ConvergenceStatus::Diverging;
    } else {
        e.status = ConvergenceStatus::Converging;
        e.gain = richardson_gain(h2, h3, e.order);
        e.extrapolated = richardson_limit(h2, h3, f2, f3, e.order);
        e.slow = e.order < slow_order;
    }
    return e;
}

double relative_error(double value, double reference) {
    if (!std::isfinite(value) || !std::isfinite(reference) || reference == 0.0) return nan;
    return (value - reference) / std::abs(reference);
}

// --- the command's lists --------------------------------------------------------------------

std::vector<double> parse_refinements(std::string_view text, std::string_view option) {
    std::vector<double> out;
    for (const auto& part : split(text, ',')) {
        const auto v = to_double(part);
        if (!v) {
            throw InputError(fmt::format("{} '{}': '{}' is not a number; give refinement factors separated by commas, "
                                         "e.g. 1,1.5,2",
                                         option, text, part));
        }
        if (!(*v > 0.0) || !std::isfinite(*v)) {
            throw InputError(fmt::format("{} '{}': {} must be a positive refinement factor (spacings are divided by it)",
                                         option, text, part));
        }
        if (std::find(out.begin(), out.end(), *v) != out.end()) {
            throw InputError(fmt::format("{} '{}': {} is listed twice", option, text, part));
        }
        out.push_back(*v);
    }
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<int> parse_thread_counts(std::string_view text, std::string_view option) {
    std::vector<int> out;
    for (const auto& part : split(text, ',')) {
        const auto v = to_long(part);
        if (!v || *v < 0 || *v > 4096) {
            throw InputError(fmt::format("{} '{}': '{}' is not a thread count; give whole numbers from 0 to 4096 (0 = all "
                                         "hardware threads) separated by commas, e.g. 1,2",
                                         option, text, part));
        }
        if (std::find(out.begin(), out.end(), static_cast<int>(*v)) != out.end()) {
            throw InputError(fmt::format("{} '{}': {} is listed twice", option, text, part));
        }
        out.push_back(static_cast<int>(*v));
    }
    return out;
}

Variant parse_variant(std::string_view text) {
    const auto fail = [&](const std::string& what) -> InputError {
        return InputError(fmt::format("--variant '{}': {}", text, what));
    };
    Variant v;
    const auto colon = text.find(':');
    v.name = trim(text.substr(0, colon));
    if (v.name.empty()) throw fail("the variant needs a name: NAME or NAME:key=value,key=value");
    for (char c : v.name) {
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.' && c != '+') {
            if (c == '=') throw fail("the variant needs a name before its settings: NAME:key=value,key=value");
            throw fail(fmt::format("the name '{}' may hold only letters, digits and - _ . +", v.name));
        }
    }
    if (colon == std::string_view::npos) return v;
    const std::string settings = trim(text.substr(colon + 1));
    if (settings.empty()) return v;
    std::set<std::string> seen;
    for (const auto& item : split(settings, ',')) {
        const auto eq = item.find('=');
        if (eq == std::string::npos) throw fail(fmt::format("'{}' is not key=value; keys: {}", item, allowed_keys()));
        const std::string key = trim(std::string_view(item).substr(0, eq)), value = trim(std::string_view(item).substr(eq + 1));
        if (!seen.insert(key).second) throw fail(fmt::format("{} is set twice", key));
        if (const auto* option = find_solver_option(key)) {
            // Read as a scene file reads the same value, then range-checked as validate_scene
            // does, so that a bad value fails before anything runs.
            SolverOptions scratch;
            detail::read_solver_option_text(*option, value, fmt::format("--variant '{}'", text), scratch);
            if (const auto message = option_error(*option, scratch)) throw fail(*message);
        } else if (key == "preset") {
            if (!find_solver_preset(value)) {
                throw fail(fmt::format("preset must be one of {}, not '{}'", solver_preset_list(false), value));
            }
        } else if (key == "discretisation") {
            if (std::none_of(discretisation_words.begin(), discretisation_words.end(),
                             [&](const auto& w) { return value == w.first; })) {
                throw fail(fmt::format("discretisation must be one of particles, elements, not '{}'", value));
            }
        } else if (key == "threads") {
            const auto n = to_long(value);
            if (!n || *n < 0 || *n > 4096) throw fail(fmt::format("threads must be a whole number from 0 to 4096, not '{}'", value));
            v.threads = static_cast<int>(*n);
            continue;
        } else {
            // A near miss of a key is named, as the scene reader does.
            std::vector<std::string_view> keys = solver_option_keys();
            keys.insert(keys.end(), {"preset", "discretisation", "threads"});
            if (const auto near = detail::closest(key, keys)) throw fail(fmt::format("unknown key '{}'; did you mean '{}'?", key, *near));
            throw fail(fmt::format("unknown key '{}'; keys: {}", key, allowed_keys()));
        }
        v.settings.emplace_back(key, value);
    }
    return v;
}

std::string variant_keys_help() {
    std::string s;
    for (const auto& option : solver_option_table()) {
        s += fmt::format("{}{}={}", s.empty() ? "" : ", ", option.key, values_help(option));
    }
    std::string presets;
    for (const SolverPreset& p : solver_presets()) presets += fmt::format("{}{}", presets.empty() ? "" : "|", p.name);
    return s + ", preset=" + presets + ", discretisation=particles|elements, threads=N";
}

void apply_variant(const Variant& variant, Scene& scene) {
    // A preset first, as in a scene file: the variant's other solver keys override it.
    for (const auto& setting : variant.settings) {
        if (setting.first == "preset") apply_solver_preset(*find_solver_preset(setting.second), scene.solver);
    }
    for (const auto& setting : variant.settings) {
        if (setting.first == "preset") continue;
        // Plain names, not a structured binding: clang 14 (the sanitizer build) refuses lambdas
        // that capture one.
        const std::string& key = setting.first;
        const std::string& value = setting.second;
        if (const auto* option = find_solver_option(key)) {
            detail::read_solver_option_text(*option, value, fmt::format("--variant {}", variant.name), scene.solver);
            // The variant's connectivity holds for every body.
            if (key == "connectivity") {
                for (auto& b : scene.bodies) b.connectivity.reset();
            }
        } else if (key == "discretisation") {
            // Every body, meshed from the same shape at the same spacing; the particle-only body
            // keys go, since they do not apply to element bodies.
            const auto d = std::find_if(discretisation_words.begin(), discretisation_words.end(),
                                        [&](const auto& w) { return value == w.first; });
            if (d == discretisation_words.end()) {
                throw InputError(fmt::format("--variant {}: discretisation must be one of particles, elements, not '{}'",
                                             variant.name, value));
            }
            for (auto& b : scene.bodies) {
                b.discretisation = d->second;
                if (b.discretisation == Discretisation::Elements) {
                    b.connectivity.reset();
                    b.lattice_neighbours = 0;
                }
            }
        } else {
            throw InputError(fmt::format("--variant {}: unknown key '{}'", variant.name, key));
        }
    }
    try {
        validate_scene(scene);
    } catch (const InputError& e) {
        throw InputError(fmt::format("--variant {}: {}", variant.name, e.what()));
    }
}

Scene refined(const Scene& scene, double factor) {
    Scene s = scene;
    for (auto& b : s.bodies) {
        if (b.shape == ShapeKind::Nodes && factor != 1.0) {
            throw InputError(fmt::format("body \"{}\": its nodes are imported, so a refinement cannot divide its spacing; "
                                         "import each resolution as its own scene", b.name));
        }
        b.spacing /= factor;
        if (b.spacing_z > 0.0) b.spacing_z /= factor;
    }
    return s;
}

double lattice_cell_size(const Scene& scene) {
    if (scene.bodies.empty()) return nan;
    if (scene.bodies[0].shape == ShapeKind::Nodes) return nominal_spacing(scene.bodies[0]);
    const auto block = body_lattice(scene, 0);
    const int dim = dimension_of(scene.geometry);
    double log_sum = 0.0;
    for (int c = 0; c < dim; ++c) log_sum += std::log(block.spacing[c]);
    return std::exp(log_sum / dim);
}

// --- what a run is measured by --------------------------------------------------------------

const std::vector<MetricInfo>& study_metrics() {
    static const std::vector<MetricInfo> metrics{
        {"final_length", "m", "mm", 1e3, true, "length above the first rigid plane at the end (docs/measurement.md)"},
        {"footprint_diameter", "m", "mm", 1e3, true, "width of the body on the first rigid plane at the end (docs/measurement.md)"},
        {"contact_time", "s", "us", 1e6, true, "time from the onset of contact with the first rigid plane to lift-off"},
        {"rebound_speed", "m/s", "m/s", 1.0, true, "|momentum along the plane normal| / mass after lift-off"},
        {"crater_depth", "m", "mm", 1e3, true,
         "depth of the first target's crater along the impact axis at the end, its thickness there if perforated (docs/measurement.md)"},
        {"crater_diameter", "m", "mm", 1e3, true, "diameter of the first target's crater at its front face at the end (docs/measurement.md)"},
        {"residual_velocity", "m/s", "m/s", 1.0, true,
         "centre-of-mass velocity of the main piece of the first body moving at t = 0 (the projectile) along the impact axis at the end "
         "(docs/measurement.md)"},
        {"plastic_work", "J", "J", 1.0, true, "plastic work at the end"},
        {"peak_plastic_strain", "", "", 1.0, true,
         "largest mean equivalent plastic strain over a neighbourhood of the scene's peak_radius at the end (docs/measurement.md)"},
        {"peak_temperature", "K", "K", 1.0, true,
         "largest mean temperature over a neighbourhood of the scene's peak_radius at the end (docs/measurement.md)"},
        {"face_roughness", "", "", 1.0, false,
         "node-to-node scatter of the plastic strain along the impact face at the end (docs/measurement.md)"},
        {"energy_error", "", "%", 100.0, false, "(KE + IE + boundary work - E0) / (E0 + positive prescribed-velocity work) at the end"},
        {"variable_fraction", "", "%", 100.0, false, "share of the real nodes with variable connectivity at the end"},
        {"hourglass_work", "J", "J", 1.0, false, "work of the hourglass control of lattice-regime nodes at the end"},
    };
    return metrics;
}

const MetricInfo* find_study_metric(std::string_view key) {
    for (const auto& m : study_metrics()) {
        if (m.key == key) return &m;
    }
    return nullptr;
}

std::vector<std::string> parse_metric_list(std::string_view text) {
    std::vector<std::string> out;
    std::string known;
    for (const auto& m : study_metrics()) known += (known.empty() ? "" : ", ") + m.key;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t comma = std::min(text.find(',', start), text.size());
        std::string word(text.substr(start, comma - start));
        word.erase(0, word.find_first_not_of(' '));
        word.erase(word.find_last_not_of(' ') + 1);
        if (word.empty()) throw InputError(fmt::format("--metrics '{}': an empty name; the metrics are {}", text, known));
        if (!find_study_metric(word)) throw InputError(fmt::format("--metrics '{}': no metric '{}'; the metrics are {}", text, word, known));
        if (std::find(out.begin(), out.end(), word) != out.end()) {
            throw InputError(fmt::format("--metrics '{}': '{}' is named twice", text, word));
        }
        out.push_back(word);
        start = comma + 1;
    }
    return out;
}

RunProbe::RunProbe(const Simulation& sim) {
    const auto& planes = sim.scene().planes;
    const auto first = std::find_if(planes.begin(), planes.end(), [](const PlaneSpec& p) { return p.kind == PlaneKind::Rigid; });
    if (first != planes.end() && !sim.totals().planes.empty()) {
        plane_ = 0;  // Totals::planes lists the rigid planes in scene order
        normal_ = plane_normal(*first);
        lift_off_ = first->lift_off;
    }
    for (std::size_t i = 0; i < sim.real_count(); ++i) mass_ += sim.nodes().mass[i];
    if (const ElementPart* e = sim.elements()) {
        for (double m : e->mesh().nodes.mass) mass_ += m;
    }
    previous_time_ = sim.time();
}

void RunProbe::observe(const Simulation& sim) {
    if (plane_ < 0) return;
    const double t = sim.time();
    const bool touching = sim.totals().planes.at(static_cast<std::size_t>(plane_)).reaction != 0.0;
    // The onset and the end of contact lie between the last step on one side and the first on
    // the other: take the middle, so that neither end is biased by a whole step.
    if (touching && !touching_) {
        if (contact_start_ < 0.0) contact_start_ = 0.5 * (previous_time_ + t);
        contact_end_ = -1.0;
    } else if (!touching && touching_) {
        contact_end_ = 0.5 * (previous_time_ + t);
    }
    touching_ = touching;
    previous_time_ = t;
}

std::map<std::string, double> RunProbe::metrics(const Simulation& sim) const {
    const auto& t = sim.totals();
    std::map<std::string, double> m{{"plastic_work", t.plastic_work},
                                    {"energy_error", t.energy_error},
                                    {"variable_fraction", static_cast<double>(t.variable_nodes) / static_cast<double>(t.real_nodes)},
                                    {"hourglass_work", t.hourglass_work}};
    if (t.local.measured && t.local.plastic_strain.has_peak()) {
        m["peak_plastic_strain"] = t.local.plastic_strain.value;
        m["peak_temperature"] = t.local.temperature.value;
        m["peak_radius"] = t.local.radius;  // not a study metric: tells the reference comparison the neighbourhood
        if (t.local.face_points >= 3) m["face_roughness"] = t.local.face_roughness;
    }
    // A projectile and a target (body_report.hpp): measured when some body moves and another is at
    // rest at t = 0, as of the caller's measure_bodies().
    const auto target = std::find_if(t.bodies.begin(), t.bodies.end(), [](const BodyTotals& b) { return b.measured && b.target; });
    if (target != t.bodies.end()) {
        m["crater_depth"] = target->crater_depth;
        m["crater_diameter"] = target->crater_diameter;
        const auto projectile = std::find_if(t.bodies.begin(), t.bodies.end(), [](const BodyTotals& b) { return b.measured && !b.target; });
        if (projectile != t.bodies.end()) m["residual_velocity"] = projectile->residual_speed_along_axis;
    }
    if (plane_ < 0) return m;
    const bool left = lift_off_ && contact_start_ >= 0.0 && !touching_ && contact_end_ >= 0.0;
    if (left) {
        m["contact_time"] = contact_end_ - contact_start_;
        double along = 0.0;
        for (std::size_t c = 0; c < 3; ++c) along += normal_[c] * t.momentum[c];
        m["rebound_speed"] = mass_ > 0.0 ? std::abs(along) / mass_ : nan;
    }
    // Measured on the body itself (docs/measurement.md), so they hold after lift-off too.
    m["final_length"] = t.length;
    m["footprint_diameter"] = t.footprint_diameter;
    return m;
}

// --- analysis ------------------------------------------------------------------------------

StudyAnalysis analyse_study(const StudyReport& report) {
    StudyAnalysis a;
    for (const auto& m : study_metrics()) {
        // A metric that no case produced, or that is zero in every case (the plastic work of an
        // elastic body), says nothing.
        bool produced = false;
        for (const auto& c : report.cases) {
            const double v = metric_value(c, m.key);
            if (std::isfinite(v) && v != 0.0) produced = true;
        }
        const auto& chosen = report.chosen_metrics;
        if (!chosen.empty() && std::find(chosen.begin(), chosen.end(), m.key) == chosen.end()) continue;
        if (produced) a.metrics.push_back(m.key);
    }
    for (const auto& c : report.cases) {
        if (std::find(a.series.begin(), a.series.end(), c.series) == a.series.end()) a.series.push_back(c.series);
    }
    a.errors.resize(report.cases.size());
    for (const auto& series : a.series) {
        std::vector<std::size_t> members;
        for (std::size_t k = 0; k < report.cases.size(); ++k) {
            if (report.cases[k].series == series) members.push_back(k);
        }
        for (const auto& key : a.metrics) {
            const auto* info = find_study_metric(key);
            std::vector<double> h, f;
            for (std::size_t k : members) {
                h.push_back(report.cases[k].cell_size);
                f.push_back(metric_value(report.cases[k], key));
            }
            Extrapolation e;
            if (info->analysed) {
                try {
                    e = extrapolate(h, f);
                } catch (const std::invalid_argument&) {
                    e.status = ConvergenceStatus::NotAvailable;  // two cases on one lattice
                }
            }
            a.extrapolations[{series, key}] = e;
            const auto ref = report.reference.find(key);
            for (std::size_t j = 0; j < members.size(); ++j) {
                if (!info->analysed) continue;
                CaseErrors& err = a.errors[members[j]][key];
                err.discretisation = relative_error(f[j], e.extrapolated);
                if (ref != report.reference.end()) err.reference = relative_error(f[j], ref->second);
            }
        }
    }
    return a;
}

// --- outputs -------------------------------------------------------------------------------

void write_study_csv(const fs::path& file, const StudyReport& report, const StudyAnalysis& analysis) {
    std::string s =
        "variant,series,threads,refinement,cell_size_m,nodes,steps,simulated_time_s,mean_time_step_s,wall_s,"
        "node_steps_per_s,peak_memory_MB,case_memory_MB,bytes_per_node,status";
    for (const auto& key : analysis.metrics) {
        const auto* m = find_study_metric(key);
        s += fmt::format(",{}", unit_suffix(*m));
        if (m->analysed) {
            s += fmt::format(",{}_discretisation_error", key);
            if (report.reference.count(key)) s += fmt::format(",{}_reference_error", key);
        }
    }
    if (report.element_reference) {
        for (const auto& col : ratio_columns) s += fmt::format(",{}", col[1]);
        s += ",outline_distance_m";
    }
    s += ",message\n";
    for (std::size_t k = 0; k < report.cases.size(); ++k) {
        const auto& c = report.cases[k];
        s += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}", csv_field(c.variant), csv_field(c.series), c.threads,
                         csv_number(c.refinement), csv_number(c.cell_size), c.nodes, c.steps, csv_number(c.simulated_time),
                         csv_number(c.mean_time_step), csv_number(c.wall_seconds), csv_number(c.node_steps_per_second),
                         csv_number(c.peak_bytes / 1048576.0), csv_number(c.case_bytes / 1048576.0),
                         csv_number(bytes_per_node(c)), c.finished ? "finished" : "failed");
        const auto& errors = errors_of(analysis, k);
        for (const auto& key : analysis.metrics) {
            const auto* m = find_study_metric(key);
            s += fmt::format(",{}", csv_number(metric_value(c, key)));
            if (!m->analysed) continue;
            const auto e = errors.find(key);
            const CaseErrors err = e != errors.end() ? e->second : CaseErrors{};
            s += fmt::format(",{}", csv_number(err.discretisation));
            if (report.reference.count(key)) s += fmt::format(",{}", csv_number(err.reference));
        }
        if (report.element_reference) {
            const auto r = ratios_of(report, c);
            for (const auto& col : ratio_columns) s += fmt::format(",{}", csv_number(ratio_value(r, col[0])));
            s += fmt::format(",{}", csv_number(ratio_value(r, "outline_distance")));
        }
        s += fmt::format(",{}\n", csv_field(c.message));
    }
    write_text_file(file, s);
}

void write_study_markdown(const fs::path& file, const StudyReport& report, const StudyAnalysis& analysis) {
    std::string s = fmt::format("# Convergence study: {}\n\n", report.scene_name.empty() ? report.scene_file : report.scene_name);
    if (!report.scene_description.empty()) s += report.scene_description + "\n\n";
    s += fmt::format("* scene file: `{}`\n", report.scene_file);
    std::string factors;
    for (double f : report.refinements) factors += fmt::format("{}{:g}", factors.empty() ? "" : ", ", f);
    s += fmt::format("* refinement factors (every body's spacing divided by each): {}\n", factors);
    s += "* variants:";
    for (std::size_t v = 0; v < report.variants.size(); ++v) {
        const auto& var = report.variants[v];
        std::string settings;
        for (const auto& [key, value] : var.settings) settings += fmt::format("{}{}={}", settings.empty() ? "" : ", ", key, value);
        if (var.threads) settings += fmt::format("{}threads={}", settings.empty() ? "" : ", ", *var.threads);
        s += fmt::format("{} `{}` ({})", v ? ";" : "", var.name, settings.empty() ? "the scene as written" : settings);
    }
    s += "\n";
    if (!report.reference.empty()) {
        std::string refs;
        for (const auto& [key, value] : report.reference) {
            const auto* m = find_study_metric(key);
            refs += fmt::format("{}{} = {}", refs.empty() ? "" : ", ", key,
                                m ? fmt::format("{:.6g} {}", value * m->display_scale, m->display_unit) : fmt::format("{:.6g}", value));
        }
        s += fmt::format("* the scene's answers: {}{}\n", refs,
                         report.reference_source.empty() ? "" : fmt::format(" ({})", report.reference_source));
    } else {
        s += "* the scene states no answers: the errors below are discretisation errors only\n";
    }
    if (!report.memory_note.empty()) s += fmt::format("* memory: {}\n", report.memory_note);
    s += "\nErrors are relative, (value - answer) / |answer|. The *discretisation error* is measured against the "
         "Richardson extrapolation of the series' three finest resolutions (h -> 0 of f0 + C h^p, h the first body's "
         "lattice cell size); the *reference error* against the answer the scene states, which also holds the error of "
         "the material model and need not go to zero. Wall time is the stepping loop alone.\n\n";

    s += "## Cases\n\n";
    s += "| series | refinement | cell mm | threads | nodes | steps | mean dt ns | wall s | node-steps/s | peak MB | B/node | "
         "energy error | status |\n";
    s += "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& c : report.cases) {
        const double energy = metric_value(c, "energy_error");
        s += fmt::format("| {} | {:g} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n", c.series, c.refinement,
                         cell(c.cell_size * 1e3), c.threads, c.nodes, c.steps, cell(c.mean_time_step * 1e9, 3),
                         cell(c.wall_seconds, 3), cell(c.node_steps_per_second, 3), memory_mb(c.peak_bytes),
                         cell(bytes_per_node(c), 3), percent(energy),
                         c.finished ? c.message : "failed: " + c.message);
    }

    for (const auto& key : analysis.metrics) {
        const auto* m = find_study_metric(key);
        if (!m->analysed) continue;
        const auto ref = report.reference.find(key);
        const bool has_ref = ref != report.reference.end();
        s += fmt::format("\n## {}{}\n\n{}", key, m->display_unit.empty() ? "" : fmt::format(" ({})", m->display_unit), m->description);
        if (has_ref) s += fmt::format("; the scene's answer {:.6g} {}", ref->second * m->display_scale, m->display_unit);
        s += ".\n\n";
        s += fmt::format("| series | refinement | cell mm | wall s | node-steps/s | peak MB | B/node | {} {} | discretisation "
                         "error |{}\n",
                         key, m->display_unit, has_ref ? " reference error |" : "");
        s += fmt::format("|---|---|---|---|---|---|---|---|---|{}\n", has_ref ? "---|" : "");
        for (std::size_t k = 0; k < report.cases.size(); ++k) {
            const auto& c = report.cases[k];
            const auto& errors = errors_of(analysis, k);
            const auto e = errors.find(key);
            const CaseErrors err = e != errors.end() ? e->second : CaseErrors{};
            s += fmt::format("| {} | {:g} | {} | {} | {} | {} | {} | {} | {} |{}\n", c.series, c.refinement,
                             cell(c.cell_size * 1e3), cell(c.wall_seconds, 3), cell(c.node_steps_per_second, 3),
                             memory_mb(c.peak_bytes), cell(bytes_per_node(c), 3),
                             cell(metric_value(c, key) * m->display_scale, 6), percent(err.discretisation),
                             has_ref ? fmt::format(" {} |", percent(err.reference)) : "");
        }
        s += fmt::format("\n| series | extrapolated {} | observed order | ratio h2/h3 |{} note |\n", m->display_unit,
                         has_ref ? " reference error of the extrapolation |" : "");
        s += fmt::format("|---|---|---|---|{}---|\n", has_ref ? "---|" : "");
        for (const auto& series : analysis.series) {
            const auto& x = analysis.extrapolations.at({series, key});
            std::string note(describe(x.status));
            if (x.status == ConvergenceStatus::NotMonotone) note += ": no order, no extrapolation";
            if (x.status == ConvergenceStatus::Diverging) note += ": the differences grow; no extrapolation";
            if (x.slow) {
                note = fmt::format("converging slowly (order below {:g}): the extrapolation adds {:.3g} times the last "
                                   "change; a rough guess",
                                   slow_order, x.gain);
            }
            s += fmt::format("| {} | {} | {} | {} |{} {} |\n", series, cell(x.extrapolated * m->display_scale, 6),
                             order_text(x.order),
                             cell(x.ratio, 4),
                             has_ref ? fmt::format(" {} |", percent(relative_error(x.extrapolated, ref->second))) : "", note);
        }
    }

    std::vector<std::string> analysed;
    for (const auto& key : analysis.metrics) {
        if (find_study_metric(key)->analysed) analysed.push_back(key);
    }
    if (!analysed.empty()) {
        s += "\n## Observed orders of convergence\n\nFrom the three finest resolutions of each series; \"not monotone\" "
             "where the values do not approach a limit from one side.\n\n| series |";
        for (const auto& key : analysed) s += fmt::format(" {} |", key);
        s += "\n|---|";
        for (std::size_t k = 0; k < analysed.size(); ++k) s += "---|";
        s += "\n";
        for (const auto& series : analysis.series) {
            s += fmt::format("| {} |", series);
            for (const auto& key : analysed) {
                const auto& x = analysis.extrapolations.at({series, key});
                const std::string order = order_text(x.order);
                if (x.status == ConvergenceStatus::Converging) {
                    s += x.slow ? fmt::format(" {} (slow) |", order) : fmt::format(" {} |", order);
                } else if (x.status == ConvergenceStatus::Diverging) {
                    s += fmt::format(" {} (diverging) |", order);
                } else {
                    s += fmt::format(" {} |", describe(x.status));
                }
            }
            s += "\n";
        }
    }
    if (report.element_reference) {
        const auto& ref = *report.element_reference;
        s += fmt::format("\n## Against the element reference\n\nThe scene's element reference `{}` ({} at {}, {}; "
                         "docs/validation.md): each case's value over the reference's (the paper's L*, D*, PW*), and the mean "
                         "distance between the final outlines.\n\n| metric | reference | kind | uncertainty |\n|---|---|---|---|\n",
                         report.scene_file.empty() ? ref.scene : ref.scene, ref.variant, ref.commit, ref.date);
        for (const auto& [key, v] : ref.values) {
            const auto* m = find_study_metric(key);
            const double scale = m ? m->display_scale : 1.0;
            const std::string unit = m ? m->display_unit : "";
            s += fmt::format("| {} | {} {} | {} | {} {} |\n", key, cell(v.value * scale, 6), unit, v.kind, cell(v.uncertainty * scale, 3), unit);
        }
        s += "\n| series | refinement | cell mm | wall s |";
        for (const auto& col : ratio_columns) s += fmt::format(" {} |", col[2]);
        s += " outline distance mm |\n|---|---|---|---|";
        for (std::size_t k = 0; k < ratio_columns.size(); ++k) s += "---|";
        s += "---|\n";
        for (const auto& c : report.cases) {
            const auto r = ratios_of(report, c);
            s += fmt::format("| {} | {:g} | {} | {} |", c.series, c.refinement, cell(c.cell_size * 1e3), cell(c.wall_seconds, 3));
            for (const auto& col : ratio_columns) s += fmt::format(" {} |", cell(ratio_value(r, col[0]), 5));
            s += fmt::format(" {} |\n", cell(ratio_value(r, "outline_distance") * 1e3, 3));
        }
    }
    write_text_file(file, s);
}

namespace {

// One figure: a panel per analysed metric, a line per series, x = wall time, y = |error|.
LogLogFigure error_figure(const StudyReport& report, const StudyAnalysis& analysis, bool against_reference) {
    LogLogFigure fig;
    fig.title = against_reference ? "Error against the scene's answer vs wall time"
                                  : "Discretisation error (against the Richardson extrapolation) vs wall time";
    fig.legend = analysis.series;
    for (const auto& key : analysis.metrics) {
        const auto* m = find_study_metric(key);
        if (!m->analysed) continue;
        if (against_reference && !report.reference.count(key)) continue;
        PlotPanel panel;
        panel.title = key;
        panel.x_label = "wall time (s)";
        panel.y_label = "|relative error|";
        std::vector<std::string> missing;
        for (const auto& series : analysis.series) {
            std::vector<PlotPoint> points;
            for (std::size_t k = 0; k < report.cases.size(); ++k) {
                const auto& c = report.cases[k];
                if (c.series != series) continue;
                const auto& errors = errors_of(analysis, k);
                const auto e = errors.find(key);
                if (e == errors.end()) continue;
                const double err = against_reference ? e->second.reference : e->second.discretisation;
                if (!std::isfinite(err)) continue;
                points.push_back({c.wall_seconds, std::abs(err),
                                  fmt::format("{}, refinement {:g}: {:.3g} s, {}", series, c.refinement, c.wall_seconds, percent(err))});
            }
            if (points.empty()) {
                const auto& x = analysis.extrapolations.at({series, key});
                missing.push_back(against_reference ? series : fmt::format("{} ({})", series, describe(x.status)));
            }
            panel.series.push_back(std::move(points));
        }
        // A panel with no point at all says nothing: study.md gives each metric's status.
        if (missing.size() == analysis.series.size()) continue;
        if (!missing.empty()) {
            panel.note = "no points: ";
            for (std::size_t k = 0; k < missing.size(); ++k) panel.note += (k ? ", " : "") + missing[k];
        }
        fig.panels.push_back(std::move(panel));
    }
    return fig;
}

}  // namespace

std::vector<fs::path> write_study_plots(const fs::path& folder, const StudyReport& report, const StudyAnalysis& analysis) {
    bool any_reference = false;
    for (const auto& key : analysis.metrics) {
        if (find_study_metric(key)->analysed && report.reference.count(key)) any_reference = true;
    }
    // A figure without a panel (no metric has an error to draw: fewer than three resolutions, or
    // nothing measured) is not written.
    std::vector<fs::path> written;
    const LogLogFigure main = error_figure(report, analysis, any_reference);
    if (!main.panels.empty()) {
        write_loglog_svg(folder / "error_vs_time.svg", main);
        written.push_back(folder / "error_vs_time.svg");
    }
    if (any_reference) {
        const LogLogFigure discretisation = error_figure(report, analysis, false);
        if (!discretisation.panels.empty()) {
            write_loglog_svg(folder / "discretisation_error_vs_time.svg", discretisation);
            written.push_back(folder / "discretisation_error_vs_time.svg");
        }
    }
    return written;
}

}  // namespace gpa::io
