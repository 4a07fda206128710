#pragma once
// A convergence study: one scene run over several resolutions and method variants, with the
// discretisation error of each run estimated by Richardson extrapolation and, where the scene
// states an answer, the error against that answer. The `gpa study` command drives it
// (apps/study.cpp); this header holds what can be tested without running anything: the
// extrapolation arithmetic, the parsers of the command's lists, what a run is measured by, and
// the writers of study.csv, study.md and the error plots. docs/study.md describes the outputs.

#include <array>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/reference.hpp"

namespace gpa::io {

// --- Richardson extrapolation --------------------------------------------------------------
//
// A quantity computed on spacing h is modelled as f(h) = f0 + C h^p. From three spacings
// h1 > h2 > h3 with values f1, f2, f3 the differences satisfy
//
//   (f1 - f2) / (f2 - f3) = (h1^p - h2^p) / (h2^p - h3^p),
//
// which for a constant ratio r = h1/h2 = h2/h3 is r^p, so p = ln((f1 - f2)/(f2 - f3)) / ln r.
// With unequal ratios the right-hand side still increases strictly with p (it is
// (x^k - x)/(x - 1) with x = (h2/h3)^p and k = ln(h1/h3)/ln(h2/h3) > 1), so p is found by
// bisection. The limit is then f0 = f3 + (f3 - f2) / ((h2/h3)^p - 1).

enum class ConvergenceStatus {
    Converging,    // monotone with an order p > 0: extrapolated
    Unchanged,     // the three values are equal: they are the limit, no order
    NotMonotone,   // (f1 - f2)(f2 - f3) <= 0 and not all equal: no order, no extrapolation
    Diverging,     // monotone but the differences grow with refinement (p <= 0): no extrapolation
    TooFew,        // fewer than three resolutions
    NotAvailable,  // one of the three finest values is missing (a failed run, a metric not produced)
};

// A few words for tables: "converging", "not monotone", ...
std::string_view describe(ConvergenceStatus s);

struct Extrapolation {
    ConvergenceStatus status = ConvergenceStatus::TooFew;
    double order = std::numeric_limits<double>::quiet_NaN();         // observed order p
    double extrapolated = std::numeric_limits<double>::quiet_NaN();  // f0; also set when Unchanged
    double ratio = std::numeric_limits<double>::quiet_NaN();         // h2 / h3 of the finest pair
    std::array<std::size_t, 3> used{0, 0, 0};                        // indices of h1, h2, h3 in the input
    // Converging with an order below slow_order: the extrapolation is a rough guess (see gain).
    bool slow = false;
    // (f0 - f3) / (f3 - f2) = 1 / ((h2/h3)^p - 1): how many times the last change the
    // extrapolation adds. Large where p is small, since then the differences barely shrink.
    double gain = std::numeric_limits<double>::quiet_NaN();
};

// Below this observed order the error falls more slowly than the square root of the spacing; the
// Richardson step then multiplies the last change by 1/((h2/h3)^p - 1), 7 for p = 0.45 at a
// ratio of 4/3 and 16 for p = 0.15 at 1.5, so small wobbles of the values move the limit a lot.
// Such series are still extrapolated, and marked as converging slowly.
inline constexpr double slow_order = 0.5;

// The observed order p from three spacings h1 > h2 > h3 and their values; NaN when the
// sequence is not monotone ((f1 - f2)(f2 - f3) <= 0) or a value is not finite. With unequal
// ratios the bisection brackets p in [-64, 64], and an order beyond that is returned as -inf or
// +inf. Throws std::invalid_argument unless h1 > h2 > h3 > 0.
double observed_order(double h1, double h2, double h3, double f1, double f2, double f3);

// 1 / ((h2/h3)^p - 1), 0 for p = +inf: the factor by which the Richardson step multiplies the
// last change f3 - f2 (Extrapolation::gain).
double richardson_gain(double h2, double h3, double order);

// f0 = f3 + (f3 - f2) / ((h2/h3)^p - 1): the limit h -> 0 of f0 + C h^p through (h2, f2), (h3, f3).
double richardson_limit(double h2, double h3, double f2, double f3, double order);

// Extrapolation from the three smallest spacings of a series (in any order). Spacings must be
// positive and distinct (std::invalid_argument otherwise); values may be NaN (missing).
Extrapolation extrapolate(std::span<const double> spacing, std::span<const double> value);

// (value - reference) / |reference|; NaN when either is not finite or the reference is zero.
double relative_error(double value, double reference);

// --- the command's lists --------------------------------------------------------------------

// "1,1.5,2": refinement factors (each body's spacing is divided by each), positive, finite and
// distinct, returned in ascending order. Throws InputError naming `option` and what is allowed.
std::vector<double> parse_refinements(std::string_view text, std::string_view option = "--refine");

// "1,2": thread counts, whole numbers in [0, 4096] (0 = all hardware threads), distinct, in the
// order given. Throws InputError naming `option`.
std::vector<int> parse_thread_counts(std::string_view text, std::string_view option = "--threads");

// A method variant: a name and settings that change the scene's [solver] options. The keys are
// those of docs/study.md (the scene file's words, plus `threads`).
struct Variant {
    std::string name;
    std::vector<std::pair<std::string, std::string>> settings;  // key, value; in the order given
    std::optional<int> threads;                                 // `threads=N`: overrides --threads
};

// "NAME" (the scene as written) or "NAME:key=value,key=value". Names are letters, digits and
// - _ . +; keys and values are checked here, so that a bad one fails before anything runs.
// Throws InputError: "--variant 'x:weight=foo': weight must be one of gpa, sph, sph-nsf, not 'foo'".
Variant parse_variant(std::string_view text);

// The keys a variant may set and the values each takes, for help texts and messages.
std::string variant_keys_help();

// Applies the variant's settings to `scene` and checks the result with validate_scene; setting
// `connectivity` also removes the bodies' own connectivity, so that the variant holds for every
// body. Throws InputError naming the variant.
void apply_variant(const Variant& variant, Scene& scene);

// The scene with every body's spacing (and spacing_z) divided by `factor`. Throws InputError for a
// body of imported nodes (factor other than 1).
Scene refined(const Scene& scene, double factor);

// The resolution a study reports for a scene: the cell size of its first body's lattice as the
// engine builds it (which fits the body exactly, so it differs slightly from the nominal
// spacing), the geometric mean over the lattice axes, m.
double lattice_cell_size(const Scene& scene);

// --- what a run is measured by --------------------------------------------------------------

// A metric of a run: its key (also the scene's [reference] key that gives its answer), unit and
// whether errors are computed for it (the energy error is itself an error: shown, not analysed).
struct MetricInfo {
    std::string key;
    std::string unit;          // SI unit of the stored value, "" for a pure number
    std::string display_unit;  // unit of the tables: mm, us, ...
    double display_scale;      // value in display units = scale * SI value
    bool analysed;
    std::string description;
};

// Every metric a study may report, in table order: final_length, footprint_diameter,
// contact_time, rebound_speed, crater_depth, crater_diameter, residual_velocity, plastic_work,
// peak_plastic_strain, peak_temperature, face_roughness,
// energy_error, variable_fraction, hourglass_work.
const std::vector<MetricInfo>& study_metrics();
const MetricInfo* find_study_metric(std::string_view key);
// The metrics a comma-separated list names ("crater_depth,residual_velocity"), each once; throws
// InputError naming the option, the word and the metrics there are.
std::vector<std::string> parse_metric_list(std::string_view text);

// Follows a run step by step and gives its metrics at the end:
//   final_length, footprint_diameter: Totals.length and .footprint_diameter when the scene has a
//     rigid plane (measured on the body itself, so also after it has left the plane);
//   peak_plastic_strain, peak_temperature, face_roughness: Totals.local, when the caller has called
//     Simulation::measure_bodies() before metrics();
//   contact_time, rebound_speed: when the first rigid plane allows lift-off and the bodies touched
//     it and then left it for good: the time from the onset of contact to its end (each placed
//     half way between the last step on one side and the first on the other) and
//     |momentum along the plane normal| / total mass at the end of the run;
//   crater_depth, crater_diameter, residual_velocity: when a body is at rest at t = 0 and another
//     moves (the first target's crater, the first moving body's residual speed along the impact
//     axis; body_report.hpp), as of the caller's Simulation::measure_bodies();
//   plastic_work (J), energy_error (relative), variable_fraction (share of the real nodes with
//     variable connectivity), hourglass_work (J): from the final totals.
// A metric that does not apply is absent from the map.
class RunProbe {
public:
    explicit RunProbe(const Simulation& sim);  // reads the state at t = 0
    void observe(const Simulation& sim);       // after each step
    std::map<std::string, double> metrics(const Simulation& sim) const;

private:
    int plane_ = -1;  // index of the first rigid plane in Totals::planes (-1: none)
    std::array<double, 3> normal_{0, 1, 0};  // the first rigid plane's unit normal
    bool lift_off_ = false;
    double mass_ = 0.0;
    double previous_time_ = 0.0;
    bool touching_ = false;
    double contact_start_ = -1.0;  // < 0: no contact yet
    double contact_end_ = -1.0;    // time contact last ended (< 0: not ended, or still touching)
};

// --- a study's results and its outputs ------------------------------------------------------

// One run of a study.
struct StudyCase {
    std::string variant;      // the variant's name
    std::string series;       // the variant with its thread count where a variant runs on several
    double refinement = 1.0;  // the factor the spacings were divided by
    double cell_size = 0.0;   // lattice_cell_size of the refined scene, m
    int threads = 1;          // threads the run used
    bool finished = false;
    std::string message;      // the stop reason, or the error
    std::size_t nodes = 0, steps = 0;
    double simulated_time = 0.0;   // s
    double mean_time_step = 0.0;   // s
    double wall_seconds = 0.0;     // the stepping loop
    double node_steps_per_second = 0.0;
    double peak_bytes = std::numeric_limits<double>::quiet_NaN();  // the process's high-water mark during the run
    double case_bytes = std::numeric_limits<double>::quiet_NaN();  // that minus the resident size before it
    std::map<std::string, double> metrics;
    std::vector<std::pair<double, double>> outline;  // final outline (io::final_outline), m
};

struct StudyReport {
    std::string scene_name;
    std::string scene_file;
    std::string scene_description;
    std::vector<double> refinements;                 // ascending
    std::vector<Variant> variants;
    std::vector<std::string> chosen_metrics;         // --metrics: analysed and plotted; empty: every metric produced
    std::map<std::string, double> reference;         // the scene's [reference]
    std::string reference_source;
    std::string memory_note;                         // how peak memory was measured
    std::vector<StudyCase> cases;
    // The scene's element reference ([reference] elements), when it names one: each case is
    // also reported as ratios to it (L*, D*, PW*, the peaks) and its outline distance.
    std::optional<ElementReference> element_reference;
};

// Errors of one case against the extrapolation of its series and against the scene's answer.
struct CaseErrors {
    double discretisation = std::numeric_limits<double>::quiet_NaN();  // relative, against the extrapolation
    double reference = std::numeric_limits<double>::quiet_NaN();       // relative, against the scene's answer
};

// The analysis of a study: per series and analysed metric, the extrapolation from the series'
// three finest cases, and each case's errors.
struct StudyAnalysis {
    std::vector<std::string> metrics;  // metrics some case produced, in study_metrics() order
    std::vector<std::string> series;   // in the order of first appearance
    std::map<std::pair<std::string, std::string>, Extrapolation> extrapolations;  // (series, metric)
    std::vector<std::map<std::string, CaseErrors>> errors;                       // per case, per metric
};
StudyAnalysis analyse_study(const StudyReport& report);

// study.csv: one row per case; every column named with its unit.
void write_study_csv(const std::filesystem::path& file, const StudyReport& report, const StudyAnalysis& analysis);

// study.md: the cases, a table per metric, the extrapolations and observed orders.
void write_study_markdown(const std::filesystem::path& file, const StudyReport& report, const StudyAnalysis& analysis);

// The error plots: error_vs_time.svg (the error against the scene's answers where it states
// some, else the discretisation error) and, when both exist, discretisation_error_vs_time.svg;
// a panel per metric with a point to draw, and no file for a figure without one. Returns the
// files written.
std::vector<std::filesystem::path> write_study_plots(const std::filesystem::path& folder, const StudyReport& report,
                                                     const StudyAnalysis& analysis);

}  // namespace gpa::io
