// docs/scene-format.md documents every option of SolverOptions (every row of the table of solver
// options), StopCriteria and OutputOptions with the default that scene.hpp gives it. When a
// default changes in the code, this test says which line of the documentation to change.

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/scene.hpp"
#include "gpa/engine/solver_options.hpp"

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

// The type column of each row of the page's [solver] table: "| `key` | type | ...".
std::map<std::string, std::string> documented_solver_types() {
    std::ifstream in(GPA_SCENE_FORMAT_DOC);
    std::map<std::string, std::string> out;
    std::string section, line;
    while (std::getline(in, line)) {
        if (line.rfind("## ", 0) == 0) section = line.substr(3);
        if (section != "`[solver]`" || line.rfind("| `", 0) != 0) continue;
        const auto key_end = line.find('`', 3);
        const auto type_begin = line.find('|', key_end) + 1;
        out[line.substr(3, key_end - 3)] = line.substr(type_begin, line.find('|', type_begin) - type_begin);
    }
    return out;
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
    // [solver]: every row of the table of solver options, its default as the table prints it
    // (numbers compared as numbers, so that 1.0 and 1 agree; a time's unit left off).
    for (const SolverOption& option : solver_option_table()) {
        const std::string value = option_default_text(option);
        if (std::holds_alternative<NumberOption>(option.kind) || std::holds_alternative<WholeNumberOption>(option.kind)) {
            expect_number(doc, std::string(option.key), std::strtod(value.c_str(), nullptr));
        } else {
            expect_word(doc, std::string(option.key), value);
        }
    }

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

    // fields: "every field but `initial_position` and `plastic_work`" (the first quoted word is
    // what the reader sees here), and those two are what the default leaves out.
    expect_word(doc, "fields", "initial_position");
    std::vector<SnapshotField> all_but_two = all_snapshot_fields();
    std::erase(all_but_two, SnapshotField::InitialPosition);
    std::erase(all_but_two, SnapshotField::PlasticWork);
    EXPECT_EQ(o.snapshot_format.fields, all_but_two);
    expect_word(doc, "precision", o.snapshot_format.precision == SnapshotPrecision::Float64 ? "\"float64\"" : "\"float32\"");

    // The table's solver options, 4 stop criteria, 7 output options, and no row for an option
    // that does not exist.
    EXPECT_EQ(doc.size(), solver_option_table().size() + 4u + 7u) << "rows in [solver], [stop] and [output] of docs/scene-format.md";
}

// The type column of a [solver] row says what the table's row takes: its words (each quoted, no
// other), a time, a whole number, a boolean or a number.
TEST(SceneFormatDoc, SolverTypesAreThoseOfTheTable) {
    const auto types = documented_solver_types();
    for (const SolverOption& option : solver_option_table()) {
        const auto it = types.find(std::string(option.key));
        ASSERT_NE(it, types.end()) << "docs/scene-format.md has no [solver] row for " << option.key;
        const std::string& type = it->second;
        if (const auto* choice = std::get_if<ChoiceOption>(&option.kind)) {
            std::size_t quotes = 0;
            for (const char c : type) quotes += c == '"';
            EXPECT_EQ(quotes, 2 * choice->words.size()) << option.key << ": " << type;
            for (const auto& w : choice->words) {
                EXPECT_NE(type.find(fmt::format("`\"{}\"`", w.word)), std::string::npos) << option.key << ": " << type;
            }
        } else if (const auto* number = std::get_if<NumberOption>(&option.kind)) {
            const bool time = type.find("time") != std::string::npos;
            EXPECT_EQ(time, number->unit == OptionUnit::Time) << option.key << ": " << type;
        } else if (std::holds_alternative<WholeNumberOption>(option.kind)) {
            EXPECT_NE(type.find("integer"), std::string::npos) << option.key << ": " << type;
        } else {
            EXPECT_NE(type.find("boolean"), std::string::npos) << option.key << ": " << type;
        }
    }
}

}  // namespace
}  // namespace gpa
