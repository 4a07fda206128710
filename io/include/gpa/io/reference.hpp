#pragma once
// The element reference of a scene (issue 13; docs/validation.md, "Element references"): the
// converged answer of the same impact computed with the element solver, which separates the
// particle method's own error from the material model's. `gpa study SCENE --variant
// elements:discretisation=elements --reference FILE` derives it from a study over three or more
// resolutions and writes FILE; a scene names it in `[reference] elements = "FILE"`, and `gpa run`
// and `gpa study` of the particle scene then report the paper's ratios L*, D*, PW* beside the
// experiment.
//
// The rule that makes a study's series a reference, per metric (reference_from_study):
//   * Richardson: the three finest resolutions converge monotonically with an observed order
//     p >= 1/2 (not "slow"): the reference is the extrapolated value f0, its uncertainty |f0 - f3|;
//   * settled: otherwise, when the three finest values lie within 2 % of each other (max - min
//     <= 0.02 |f3|), the reference is the finest value f3, its uncertainty max - min (a series that
//     is slow, not monotone or diverging at that level has no better estimate than its finest run);
//   * none: otherwise the metric has no reference, and the file says why.

#include <array>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace gpa {
class Simulation;
}

namespace gpa::io {

struct StudyReport;
struct StudyAnalysis;

struct ReferenceValue {
    double value = 0.0;          // SI
    std::string kind;            // "richardson" or "finest"
    std::string status;          // the series' convergence status ("converging", "not monotone", ...)
    double order = 0.0;          // observed order (NaN when none)
    double uncertainty = 0.0;    // SI, see the rule above
    std::vector<double> values;  // the series, coarse to fine
};

struct ElementReference {
    std::string scene;                          // the scene's name
    std::string scene_file;                     // as given to the study
    std::string variant;                        // the element variant, as typed
    std::vector<double> cell_sizes;             // m, coarse to fine
    double peak_radius = 0.0;                   // m: the neighbourhood of its peaks (0: not recorded)
    std::string date;                           // UTC, YYYY-MM-DD
    std::string commit;                         // source_commit() of the program that ran the cases
    std::string written_by = "gpa study --reference";  // what assembled the file
    std::map<std::string, ReferenceValue> values;        // metric key -> reference
    std::map<std::string, std::string> missing;          // metric key -> why it has none
    std::vector<std::pair<double, double>> outline;      // (height, radius) of the finest run, m
};

// The rule above, applied to one series of a study; `outline` is the finest case's outline.
// Throws InputError when the series has fewer than three finished resolutions.
ElementReference reference_from_study(const StudyReport& report, const StudyAnalysis& analysis, const std::string& series,
                                      std::vector<std::pair<double, double>> outline);

// Writes the reference as TOML (values in SI, with the rule and provenance as comments and keys).
void write_element_reference(const std::filesystem::path& file, const ElementReference& reference);

// Reads a file written by write_element_reference. Throws InputError naming the file, the key
// and what is wrong.
ElementReference read_element_reference(const std::filesystem::path& file);

// The body's outline at the end of a run, (height above the base, largest radius) from the base
// to the top, by the rules of measure.hpp (what profile.csv holds); empty without a rigid plane.
std::vector<std::pair<double, double>> final_outline(const Simulation& sim);

// The outline distance of two outlines: the mean of |r_a(z) - r_b(z)| over 200 heights evenly
// spaced across the lower 98 % of the shorter of the two (the top row, where an outline closes
// to the axis, is left out), r interpolated linearly between outline points, m. NaN when either
// outline has fewer than two points.
double outline_distance(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b);

// Ratios of a run to the reference (the paper's L*, D*, PW* and the peaks): value / reference
// for each metric both have; and "outline_distance" (m) when both have outlines. The peaks are
// compared only when `metrics` holds "peak_radius" equal to the reference's (a peak over another
// neighbourhood is another quantity).
std::map<std::string, double> compare_with_reference(const std::map<std::string, double>& metrics,
                                                     const std::vector<std::pair<double, double>>& outline,
                                                     const ElementReference& reference);

}  // namespace gpa::io
