#pragma once
// The table of solver options: one row per key of a scene file's [solver] table, saying which
// member of SolverOptions it sets, what kind of value it takes, its range and one line of help.
// The scene reader, `gpa study` variants, validate_scene and the docs test all read this one
// table, so that a key cannot be accepted in one place and refused in another. Defaults are not
// written here: they are read from a default-constructed SolverOptions (scene.hpp).
//
// The engine knows nothing of TOML or unit spellings: a row only says whether a number is
// dimensionless or a time; io/ maps that to its own Dimension.

#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include "gpa/engine/scene.hpp"

namespace gpa {

// What a number measures; values are SI (a time in s).
enum class OptionUnit { Dimensionless, Time };

// An interval of allowed values; either end may be infinite. A closed infinite end means that
// the infinity itself is allowed (max_time_step = inf: no limit).
struct OptionRange {
    double lowest = 0.0;
    double highest = 0.0;
    bool lowest_included = true;
    bool highest_included = true;

    bool contains(double value) const;
    bool allows_infinity() const;
    // "[0, 1)", "(0, inf]": the interval as the messages and help print it.
    std::string text() const;
};

// A real number held in a double member.
struct NumberOption {
    double SolverOptions::* member;
    OptionUnit unit;
    OptionRange range;
};

// A whole number held in a std::size_t member (its range's ends are whole numbers or infinite).
struct WholeNumberOption {
    std::size_t SolverOptions::* member;
    OptionRange range;
};

struct BooleanOption {
    bool SolverOptions::* member;
};

// A word of a choice and the enumerator it stands for, as an int (the row's accessors convert).
struct ChoiceWord {
    std::string_view word;
    int value;
};

// One of a fixed list of words, held in an enum member. The accessors are typed by the row that
// makes them (solver_options.cpp, `choice_of`): they read and write that one enum member.
struct ChoiceOption {
    std::vector<ChoiceWord> words;
    std::function<int(const SolverOptions&)> get;
    std::function<void(SolverOptions&, int)> set;

    // The word of the member's value in `s`; nullopt for a value that is no listed enumerator.
    std::optional<std::string_view> word_of(const SolverOptions& s) const;
    // The value of `word`; nullopt for a word that is not listed.
    std::optional<int> value_of(std::string_view word) const;
    // "\"fixed\", \"variable\", \"automatic\"" (quoted = true) or "fixed, variable, automatic".
    std::string list(bool quoted) const;
};

using OptionKind = std::variant<NumberOption, WholeNumberOption, BooleanOption, ChoiceOption>;

struct SolverOption {
    std::string_view key;  // the [solver] key, also the SolverOptions member's name
    OptionKind kind;
    std::string_view help;        // one line for help texts
    std::string_view range_note;  // what special values mean, e.g. "0 = no limit"; may be empty
};

// Every [solver] key, in the order of docs/scene-format.md. SolverOptions::check_neighbour_lists
// is not here: it is for tests and not read from scene files.
std::span<const SolverOption> solver_option_table();

// The row of `key`; nullptr for a key that is not a solver option.
const SolverOption* find_solver_option(std::string_view key);

// The keys of the table, in its order (for the scene reader's list of allowed keys).
std::vector<std::string_view> solver_option_keys();

// The value of the row's member in `s` as a scene file writes it: 0.4, "variable" (quoted),
// true, 200, inf; a time in s with its unit ("1e-09 s").
std::string option_value_text(const SolverOption& option, const SolverOptions& s);

// The row's default, option_value_text of a default-constructed SolverOptions.
std::string option_default_text(const SolverOption& option);

// What the row allows, for help and messages: "(0, 1]", "[0, inf) s", or "gpa, sph-nsf";
// "true or false" for booleans.
std::string option_allowed_text(const SolverOption& option);

// Whether the row's member in `s` is allowed: nullopt if so, else the message that
// validate_scene throws, "solver.cfl = 2 is outside (0, 1]".
std::optional<std::string> option_error(const SolverOption& option, const SolverOptions& s);

// A named set of solver settings ([solver] preset = "NAME" in a scene file, preset=NAME in a `gpa
// study` variant): its keys are rows of the table, their values written as a scene file writes
// them (words, plain numbers). A preset applies first; the table's keys given beside it override
// it. Presets name measured choices, so that a scene states which one it makes and keeps it if a
// default changes (docs/scene-format.md, "Presets").
struct SolverPreset {
    std::string_view name;
    std::string_view meaning;  // one line for help and docs
    std::vector<std::pair<std::string_view, std::string_view>> settings;
};

std::span<const SolverPreset> solver_presets();

// The preset called `name`; nullptr for none.
const SolverPreset* find_solver_preset(std::string_view name);

// "\"paper\", \"taylor-bar\"" (quoted = true) or "paper, taylor-bar".
std::string solver_preset_list(bool quoted);

// Sets the preset's options in `s` (the others are left as they are).
void apply_solver_preset(const SolverPreset& preset, SolverOptions& s);

}  // namespace gpa
