// docs/scene-format.md documents every option of SolverOptions, StopCriteria and OutputOptions
// with the default that scene.hpp gives it. When a default changes in the code, this test says
// which line of the documentation to change.

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/scene.hpp"

namespace gpa {
namespace {

// The default column of each option row of the page: "| `key` | type | default | ...".
std::map<std::string, std::string> documented_defaults() {
    std::ifstream in(GPA_SCENE_FORMAT_DOC);
    EXPECT_TRUE(in) << GPA_SCENE_FORMAT_DOC;
    std::map<std::string, std::string> out;
    std::string section, line;
    while (std::getline(in, line)) {
        if (line.rfind("## ", 0) == 0) section = line.substr(3);
        if (section != "`[solver]`" && section != "`[stop]`" && section != "`[output]`") continue;
        if (line.rfind("| `", 0) != 0) continue;
        std::vector<std::string> cells;
        std::size_t start = 1;
        for (std::size_t bar = line.find('|', start); bar != std::string::npos; bar = line.find('|', start)) {
            cells.push_back(line.substr(start, bar - start));
            start = bar + 1;
        }
        if (cells.size() < 3) continue;
        const auto key_begin = cells[0].find('`') + 1;
        const std::string key = cells[0].substr(key_begin, cells[0].find('`', key_begin) - key_begin);
        // The default is the first `...` of the third cell.
        const auto first = cells[2].find('`');
        const auto last = cells[2].find('`', first + 1);
        out[key] = first == std::string::npos ? cells[2] : cells[2].substr(first + 1, last - first - 1);
    }
    return out;
}

std::string word(ConnectivityMode c) {
    return c == ConnectivityMode::Fixed ? "\"fixed\"" : c == ConnectivityMode::Variable ? "\"variable\"" : "\"automatic\"";
}
std::string word(ViscosityKind v) {
    return v == ViscosityKind::None ? "\"none\"" : v == ViscosityKind::Nodal ? "\"nodal\"" : "\"bond\"";
}
std::string word(SmoothingMode s) {
    return s == SmoothingMode::Off ? "\"off\"" : s == SmoothingMode::Everywhere ? "\"everywhere\"" : "\"tension\"";
}
std::string word(WeightKind w) { return w == WeightKind::Gpa ? "\"gpa\"" : "\"sph-nsf\""; }
std::string word(Normalisation n) {
    return n == Normalisation::PerDirection ? "\"per-direction\"" : "\"moment-matrix\"";
}
std::string word(ScatterScheme s) {
    switch (s) {
        case ScatterScheme::Slabs: return "\"slabs\"";
        case ScatterScheme::Cells: return "\"cells\"";
        case ScatterScheme::Graph: return "\"graph\"";
        case ScatterScheme::Serial: return "\"serial\"";
    }
    return "?";
}

void expect_number(const std::map<std::string, std::string>& doc, const std::string& key, double value) {
    const auto it = doc.find(key);
    ASSERT_NE(it, doc.end()) << "docs/scene-format.md has no row for " << key;
    const double documented = it->second == "inf" ? std::numeric_limits<double>::infinity() : std::strtod(it->second.c_str(), nullptr);
    EXPECT_EQ(documented, value) << key << ": documented " << it->second << ", scene.hpp says " << value;
}

void expect_word(const std::map<std::string, std::string>& doc, const std::string& key, const std::string& value) {
    const auto it = doc.find(key);
    ASSERT_NE(it, doc.end()) << "docs/scene-format.md has no row for " << key;
    EXPECT_EQ(it->second, value) << key;
}

TEST(SceneFormatDoc, DefaultsAreThoseOfSceneHpp) {
    const auto doc = documented_defaults();
    const SolverOptions s;
    expect_word(doc, "connectivity", word(s.connectivity));
    expect_number(doc, "switch_plastic_strain", s.switch_plastic_strain);
    expect_number(doc, "influence_distance", s.influence_distance);
    expect_word(doc, "node_diameter", s.node_diameter == NodeDiameter::Hoop     ? "\"hoop\""
                                      : s.node_diameter == NodeDiameter::Volume ? "\"volume\""
                                                                                : "\"section\"");
    expect_word(doc, "weight", word(s.weight));
    expect_word(doc, "normalisation", word(s.normalisation));
    expect_word(doc, "viscosity", word(s.viscosity));
    expect_number(doc, "viscosity_linear", s.viscosity_linear);
    expect_number(doc, "viscosity_quadratic", s.viscosity_quadratic);
    expect_number(doc, "bond_viscosity_eps0", s.bond_viscosity_eps0);
    expect_word(doc, "smoothing", word(s.smoothing));
    expect_number(doc, "hourglass_coefficient", s.hourglass_coefficient);
    expect_number(doc, "hourglass_stiffness", s.hourglass_stiffness);
    expect_number(doc, "smoothing_coefficient", s.smoothing_coefficient);
    expect_number(doc, "cfl", s.cfl);
    expect_number(doc, "alpha_limit", s.alpha_limit);
    expect_number(doc, "max_time_step", s.max_time_step);
    expect_number(doc, "time_step_growth", s.time_step_growth);
    expect_word(doc, "failure", s.failure ? "true" : "false");
    expect_word(doc, "separate_failed", s.separate_failed ? "true" : "false");
    expect_word(doc, "sliding_contact", s.sliding_contact ? "true" : "false");
    expect_word(doc, "energy_update", s.energy_update == EnergyUpdate::Compatible ? "\"compatible\"" : "\"point\"");
    expect_word(doc, "scatter", word(s.scatter));
    expect_number(doc, "reorder_interval", static_cast<double>(s.reorder_interval));
    expect_number(doc, "neighbour_skin", s.neighbour_skin);

    const StopCriteria stop;
    expect_number(doc, "end_time", stop.end_time);
    expect_number(doc, "kinetic_energy_fraction", stop.kinetic_energy_fraction);
    expect_number(doc, "max_steps", static_cast<double>(stop.max_steps));
    expect_number(doc, "energy_error", stop.energy_error);

    const OutputOptions o;
    expect_number(doc, "snapshots", static_cast<double>(o.snapshots));
    expect_number(doc, "snapshot_interval", o.snapshot_interval);
    expect_number(doc, "history_every", static_cast<double>(o.history_every));
    // checkpoint_every: a wall-clock time by default, documented with its unit.
    EXPECT_EQ(o.checkpoint_every_steps, 0u);
    expect_word(doc, "checkpoint_every", fmt::format("\"{:g} min\"", o.checkpoint_every_seconds / 60.0));
    // peak_radius: 0 in scene.hpp, which the scene reader replaces by twice the first body's spacing.
    EXPECT_EQ(o.peak_radius, 0.0);
    expect_word(doc, "peak_radius", " twice the first body's spacing as written ");  // a cell without a `value`: as written

    // 24 solver options, 4 stop criteria, 5 output options, and no row for an option that does
    // not exist.
    EXPECT_EQ(doc.size(), 35u) << "rows in [solver], [stop] and [output] of docs/scene-format.md";
}

}  // namespace
}  // namespace gpa
