#pragma once
// Private to io/: reading TOML tables with dimensions, limits and messages that name the file,
// the line and the key. Used by the scene reader and the material library.

#include <cstddef>
#include <initializer_list>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "toml_include.hpp"

#include "gpa/io/units.hpp"

namespace gpa::io::detail {

// Where messages point: the file as the user named it. Every error leaves through fail(), which
// builds the one-line message "file:line: key: what is wrong" and throws SceneError.
class Reporter {
public:
    explicit Reporter(std::string file) : file_(std::move(file)) {}
    const std::string& file() const { return file_; }

    // `line` 0 = unknown; `key` empty = the file as a whole.
    [[noreturn]] void fail(std::size_t line, std::string_view key, std::string_view message) const;

private:
    std::string file_;
};

// Replaces control characters (new lines among them) by escapes and shortens long text, so that
// anything quoted from a file keeps a message on one line.
std::string printable(std::string_view text, std::size_t max_length = 80);

// `"text"` with printable() applied.
std::string in_quotes(std::string_view text);

// Rejects text that is not a TOML document before the TOML parser sees it: NUL bytes and other
// control characters (binary data) and invalid UTF-8, naming the line.
void check_text(std::string_view text, const Reporter& reporter);

// Part of check_text: non-ASCII characters only inside strings and comments, as TOML 1.0 says
// (toml++ 3.3.0 has undefined behaviour on some of them elsewhere; see the definition).
void check_non_ascii_placement(std::string_view text, const Reporter& reporter);

// Parses TOML text, turning syntax errors into "file:line:column: TOML syntax error: ...".
toml::table parse_toml(std::string_view text, const Reporter& reporter);

// Any other TOML file a user can hand gpa (an element reference, the scene.toml a renderer reads
// in a run folder), read through the same guards as a scene (size, check_text) before toml++
// sees it: SceneError naming the file (and line) for what they or the parser refuse.
toml::table read_guarded_toml(const std::filesystem::path& file);

// The closest of `candidates` to `word` (edit distance, letter case ignored), if close enough
// to be a likely typo.
std::optional<std::string_view> closest(std::string_view word, const std::vector<std::string_view>& candidates);

// Limits a quantity must respect; the range checks of options are validate_scene's.
enum class Limit {
    Any,
    Positive,              // > 0, finite
    NonNegative,           // >= 0, finite
    PositiveOrInfinite,    // > 0, +inf allowed (means "no limit")
    BelowLightSpeed,       // |value| < the speed of light (a velocity component)
};

// The speed no velocity of a scene reaches (m/s): the mechanics is Newtonian, and a value at or
// beyond it is a slip (1e300 for 300), better refused where it is written than as an impossible
// time step or disk estimate later.
inline constexpr double speed_of_light = 299792458.0;

// A pair of a word in the file and the value it stands for.
template <class T>
using Choices = std::initializer_list<std::pair<std::string_view, T>>;

// One table of the file with its allowed keys. The constructor rejects unknown keys (suggesting
// the closest allowed one); the readers below check type, unit, dimension and limit.
class TableReader {
public:
    // `path`: the table as messages name it ("solver", `body "bar" (body[0])`); empty for the
    // top level. `what`: the table in words for the list of allowed keys ("a body").
    TableReader(const Reporter& reporter, const toml::table& table, std::string path, std::string what,
                std::vector<std::string_view> allowed);

    const toml::table& table() const { return table_; }
    const std::string& path() const { return path_; }
    const Reporter& reporter() const { return reporter_; }
    bool has(std::string_view key) const { return table_.contains(key); }
    const toml::node* find(std::string_view key) const { return table_.get(key); }

    // "solver.cfl", `body "bar" (body[0]).radius`, "geometry".
    std::string key_path(std::string_view key) const;

    // Errors at a key (its line) or at the table (its header's line).
    [[noreturn]] void fail_at(std::string_view key, std::string_view message) const;
    [[noreturn]] void fail_table(std::string_view message) const;
    [[noreturn]] void fail_missing(std::string_view key, std::string_view what) const;

    // Readers: nullopt when the key is absent; the required_ forms fail instead, saying what the
    // key should hold.
    std::optional<double> quantity(std::string_view key, Dimension d, Limit limit = Limit::Any) const;
    double required_quantity(std::string_view key, Dimension d, Limit limit = Limit::Any) const;
    std::optional<std::string> string(std::string_view key) const;
    std::string required_string(std::string_view key, std::string_view what) const;
    std::optional<bool> boolean(std::string_view key) const;
    std::optional<long long> whole_number(std::string_view key, long long min, long long max) const;
    // An array of exactly `count` quantities ("origin = [0, \"15 mm\"]").
    std::optional<std::vector<double>> quantities(std::string_view key, Dimension d, std::size_t count,
                                                  Limit limit, std::string_view components) const;

    template <class T>
    std::optional<T> choice(std::string_view key, Choices<T> choices) const {
        const auto word = string(key);
        if (!word) return std::nullopt;
        for (const auto& [name, value] : choices) {
            if (*word == name) return value;
        }
        std::vector<std::string_view> names;
        for (const auto& c : choices) names.push_back(c.first);
        fail_choice(key, *word, names);
    }

    // The index in `words` of the key's word, for lists built at run time (the solver option
    // table's choices); fails like choice() for a word that is not listed.
    std::optional<std::size_t> word_index(std::string_view key, const std::vector<std::string_view>& words) const;

private:
    [[noreturn]] void fail_choice(std::string_view key, std::string_view word,
                                  const std::vector<std::string_view>& names) const;

    const Reporter& reporter_;
    const toml::table& table_;
    std::string path_;
};

// The line a node starts on (0 if unknown).
std::size_t line_of(const toml::node& node);

// "a string", "an integer", "a table", ... for messages about wrong types.
std::string_view type_name(const toml::node& node);

// Reads one quantity node (number or string with unit); `key_path` only names it in messages.
double read_quantity(const Reporter& reporter, const toml::node& node, const std::string& key_path, Dimension d,
                     Limit limit);

// The value of a node as written, for messages: strings quoted, numbers as TOML prints them.
std::string as_written(const toml::node& node);

}  // namespace gpa::io::detail
