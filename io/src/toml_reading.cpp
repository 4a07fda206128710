#include "toml_reading.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>

#include "gpa/io/scene_file.hpp"

namespace gpa::io::detail {

namespace {

using D = Dimension;

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

// Edit distance with adjacent transpositions counted as one edit ("raduis" -> "radius": 1).
std::size_t edit_distance(std::string_view a, std::string_view b) {
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1, 0));
    for (std::size_t i = 0; i <= n; ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i) {
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1])) {
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
            }
        }
    }
    return d[n][m];
}

std::string join_quoted(const std::vector<std::string_view>& words) {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i > 0) out += i + 1 == words.size() ? " or " : ", ";
        out += fmt::format("\"{}\"", words[i]);
    }
    return out;
}

std::string join(const std::vector<std::string_view>& words) {
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (i > 0) out += ", ";
        out += words[i];
    }
    return out;
}

// The noun with its indefinite article: "a length", "an angle".
std::string a_or_an(std::string_view noun) {
    const bool vowel = !noun.empty() && std::string_view("aeiou").find(noun.front()) != std::string_view::npos;
    return fmt::format("{} {}", vowel ? "an" : "a", noun);
}

std::string_view example_of(Dimension d) {
    switch (d) {
        case Dimension::Dimensionless: return "0.5";
        case Dimension::Length: return "\"15.2 mm\"";
        case Dimension::Time: return "\"40 us\"";
        case Dimension::Velocity: return "\"305 m/s\"";
        case Dimension::Density: return "\"7.89 g/cc\"";
        case Dimension::Pressure: return "\"175 MPa\"";
        case Dimension::Temperature: return "\"294 K\"";
        case Dimension::SpecificHeat: return "\"452 J/kg/K\"";
        case Dimension::SpecificEnergy: return "\"1 kJ/kg\"";
        case Dimension::StrainRate: return "\"1 1/s\"";
        case Dimension::Angle: return "\"30 deg\"";
    }
    return "";
}

std::string expected_quantity(Dimension d) {
    if (d == Dimension::Dimensionless) return "a number";
    return fmt::format("{} (a number in {} or a string such as {})", a_or_an(name_of(d)), si_unit_of(d), example_of(d));
}

std::string noun_of(Dimension d) { return d == Dimension::Dimensionless ? "number" : std::string(name_of(d)); }

}  // namespace

void Reporter::fail(std::size_t line, std::string_view key, std::string_view message) const {
    std::string text = file_;
    if (line > 0) text += fmt::format(":{}", line);
    text += ": ";
    if (!key.empty()) {
        text += key;
        text += ": ";
    }
    text += message;
    throw SceneError(printable(text, std::numeric_limits<std::size_t>::max()));
}

std::string printable(std::string_view text, std::size_t max_length) {
    std::string out;
    std::size_t i = 0;
    for (; i < text.size() && out.size() < max_length; ++i) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c == '\n') {
            out += "\\n";
        } else if (c == '\r') {
            out += "\\r";
        } else if (c == '\t') {
            out += "\\t";
        } else if (c < 0x20 || c == 0x7F) {
            out += fmt::format("\\x{:02X}", static_cast<unsigned>(c));
        } else {
            out += static_cast<char>(c);
        }
    }
    if (i < text.size()) {
        // Do not cut a UTF-8 sequence in two.
        while (!out.empty() && (static_cast<unsigned char>(out.back()) & 0xC0) == 0x80) out.pop_back();
        if (!out.empty() && static_cast<unsigned char>(out.back()) >= 0xC0) out.pop_back();
        out += "...";
    }
    return out;
}

std::string in_quotes(std::string_view text) { return fmt::format("\"{}\"", printable(text)); }

void check_text(std::string_view text, const Reporter& reporter) {
    std::size_t line = 1;
    std::size_t i = 0;
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const auto not_text = [&](unsigned char b) {
        reporter.fail(line, "",
                      fmt::format("byte 0x{:02X} is a control character: this is not a text file (a scene file is "
                                  "UTF-8 TOML text)",
                                  static_cast<unsigned>(b)));
    };
    const auto bad_utf8 = [&](std::size_t at) {
        reporter.fail(line, "",
                      fmt::format("invalid UTF-8 (byte 0x{:02X}): a scene file must be UTF-8 text",
                                  static_cast<unsigned>(byte(at))));
    };
    while (i < text.size()) {
        const unsigned char b = byte(i);
        if (b < 0x80) {
            if (b == '\n') ++line;
            else if ((b < 0x20 && b != '\t' && b != '\r') || b == 0x7F) not_text(b);
            ++i;
            continue;
        }
        // The well-formed UTF-8 sequences (Unicode 15, table 3-7).
        std::size_t continuation = 0;
        unsigned char low = 0x80, high = 0xBF;  // range of the first continuation byte
        if (b >= 0xC2 && b <= 0xDF) {
            continuation = 1;
        } else if (b == 0xE0) {
            continuation = 2, low = 0xA0;
        } else if ((b >= 0xE1 && b <= 0xEC) || b == 0xEE || b == 0xEF) {
            continuation = 2;
        } else if (b == 0xED) {
            continuation = 2, high = 0x9F;
        } else if (b == 0xF0) {
            continuation = 3, low = 0x90;
        } else if (b >= 0xF1 && b <= 0xF3) {
            continuation = 3;
        } else if (b == 0xF4) {
            continuation = 3, high = 0x8F;
        } else {
            bad_utf8(i);
        }
        for (std::size_t k = 1; k <= continuation; ++k) {
            if (i + k >= text.size()) bad_utf8(i);
            const unsigned char c = byte(i + k);
            const unsigned char lo = k == 1 ? low : 0x80, hi = k == 1 ? high : 0xBF;
            if (c < lo || c > hi) bad_utf8(i + k);
        }
        i += continuation + 1;
    }
    check_non_ascii_placement(text, reporter);
}

void check_non_ascii_placement(std::string_view text, const Reporter& reporter) {
    // toml++ 3.3.0 tests characters outside strings and comments against Unicode tables that,
    // for many code points (U+00A1-U+0499 among them: the bytes CF BB are U+03FB), reach
    // __builtin_unreachable: undefined behaviour before it can report a syntax error. TOML 1.0
    // allows non-ASCII characters only in strings and comments, so one anywhere else is an error
    // anyway, reported here before toml++ sees it. toml++ reaches the same tables for the
    // character after a backslash in a multi-line basic string and for the first character
    // after the line break that a line-ending backslash skips, and for one after the blanks that
    // follow a backslash (toml++ skips them looking for the line break); a non-ASCII character in
    // these places is refused too (an escape such as \u03FB says the same).
    //
    // Where a quote opens a string is decided as toml++ decides it: only where a key or a value
    // begins (after whitespace, =, [, {, or a comma, and after the dot of a dotted key). A quote
    // inside a bare token (`geometry = 2"...`) is part of that token for toml++, which tests
    // what follows against the same tables, so what follows is checked as outside a string.
    // Keys and values are told apart by a small bracket stack: after = and inside an array a
    // value comes, at a line's start (outside brackets) and after { or a comma of an inline
    // table a key.
    enum class In { Nothing, Comment, Basic, Literal, MultiBasic, MultiLiteral };
    In in = In::Nothing;
    std::size_t line = 1;
    std::string brackets;  // the open [ (array) and { (inline table) of values, innermost last
    bool key = true;       // a key (not a value) would begin here
    const auto opens_string = [&](std::size_t k) {
        if (k == 0) return true;
        const unsigned char before = static_cast<unsigned char>(text[k - 1]);
        if (before == ' ' || before == '\t' || before == '\n' || before == '\r' || before == '=' || before == '[' ||
            before == '{' || before == ',') {
            return true;
        }
        return before == '.' && key;  // a dotted key: a."b"; in a value the dot belongs to a bare token (2.)
    };
    const std::size_t n = text.size();
    const auto at = [&](std::size_t k) { return k < n ? static_cast<unsigned char>(text[k]) : 0u; };
    const auto run_of = [&](std::size_t k, unsigned char quote) {
        std::size_t r = 0;
        while (at(k + r) == quote) ++r;
        return r;
    };
    std::size_t i = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;  // a byte-order mark
    while (i < n) {
        const unsigned char c = at(i);
        if (c == '\n') ++line;
        switch (in) {
            case In::Nothing:
                if (c == '#') {
                    in = In::Comment;
                } else if ((c == '"' || c == '\'') && opens_string(i)) {
                    const bool multi = run_of(i, c) >= 3;
                    in = c == '"' ? (multi ? In::MultiBasic : In::Basic) : (multi ? In::MultiLiteral : In::Literal);
                    i += multi ? 3 : 1;
                    continue;
                } else if (c == '\n') {
                    if (brackets.empty()) key = true;
                } else if (c == '=') {
                    key = false;
                } else if (c == '{') {
                    brackets += '{';
                    key = true;
                } else if (c == '[') {
                    if (!(key && brackets.empty())) {  // a table header's brackets ([a], [[a]]) hold a key
                        brackets += '[';
                        key = false;
                    }
                } else if (c == ']' || c == '}') {
                    if (!brackets.empty() && brackets.back() == (c == ']' ? '[' : '{')) brackets.pop_back();
                    if (!brackets.empty() || c == '}') key = false;
                } else if (c == ',') {
                    key = !brackets.empty() && brackets.back() == '{';
                } else if (c >= 0x80) {
                    reporter.fail(line, "",
                                  "a non-ASCII character outside a quoted string or a comment: TOML allows them only "
                                  "there (keys with such characters must be quoted)");
                }
                break;
            case In::Comment:
                if (c == '\n') {
                    in = In::Nothing;
                    if (brackets.empty()) key = true;
                }
                break;
            case In::Literal:
                if (c == '\'' || c == '\n') in = In::Nothing;
                break;
            case In::Basic:
            case In::MultiBasic:
                if (c == '\\') {
                    std::size_t k = i + 1;
                    if (in == In::MultiBasic) {
                        while (at(k) == ' ' || at(k) == '\t') ++k;
                        if (at(k) == '\n' || (at(k) == '\r' && at(k + 1) == '\n')) {
                            // A line-ending backslash: toml++ skips the whitespace that follows.
                            while (k < n && (at(k) == ' ' || at(k) == '\t' || at(k) == '\r' || at(k) == '\n')) {
                                if (at(k) == '\n') ++line;
                                ++k;
                            }
                            if (at(k) >= 0x80) {
                                reporter.fail(line, "",
                                              "a non-ASCII character right after the line break of a line-ending "
                                              "backslash (toml++ 3.3 mishandles it): put an ASCII character or an "
                                              "escape such as \\u00E9 first");
                            }
                            i = k;
                            continue;
                        }
                        if (at(k) >= 0x80 && k > i + 1) {
                            // A backslash, blanks and a non-ASCII character: toml++ skips the blanks
                            // looking for the line break and tests the character against the same tables.
                            reporter.fail(line, "",
                                          "a backslash followed by blanks and a non-ASCII character: a line-ending "
                                          "backslash must be the last character on its line, and nothing else is an "
                                          "escape TOML knows");
                        }
                        k = i + 1;
                    }
                    if (at(k) >= 0x80) {
                        reporter.fail(line, "", "a backslash before a non-ASCII character: not an escape TOML knows");
                    }
                    if (at(k) == '\n') ++line;
                    i = k + 1;
                    continue;
                }
                if (in == In::Basic && (c == '"' || c == '\n')) {
                    in = In::Nothing;
                } else if (in == In::MultiBasic && c == '"') {
                    const std::size_t r = run_of(i, '"');
                    if (r >= 3) in = In::Nothing;
                    i += r;
                    continue;
                }
                break;
            case In::MultiLiteral:
                if (c == '\'') {
                    const std::size_t r = run_of(i, '\'');
                    if (r >= 3) in = In::Nothing;
                    i += r;
                    continue;
                }
                break;
        }
        ++i;
    }
}

toml::table parse_toml(std::string_view text, const Reporter& reporter) {
    try {
        return toml::parse(text, reporter.file());
    } catch (const toml::parse_error& e) {
        const auto& where = e.source().begin;
        reporter.fail(where.line, "",
                      fmt::format("TOML syntax error (column {}): {}", where.column, e.description()));
    }
}

toml::table read_guarded_toml(const std::filesystem::path& file) {
    const std::string text = read_scene_text(file);
    const Reporter reporter(file.string());
    check_text(text, reporter);
    return parse_toml(text, reporter);
}

std::optional<std::string_view> closest(std::string_view word, const std::vector<std::string_view>& candidates) {
    std::optional<std::string_view> best;
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    for (const std::string_view c : candidates) {
        const std::size_t d = edit_distance(word, c);
        if (d < best_distance) best_distance = d, best = c;
    }
    // A few edits for a long word, and never a whole word replaced ("y" is no typo of "x").
    const std::size_t length = std::min(word.size(), best ? best->size() : 0);
    const std::size_t allowed = std::min(length <= 4 ? std::size_t{1} : length <= 8 ? std::size_t{2} : std::size_t{3},
                                         length > 0 ? length - 1 : 0);
    if (best && best_distance <= allowed) return best;
    return std::nullopt;
}

std::size_t line_of(const toml::node& node) { return node.source().begin.line; }

std::string_view type_name(const toml::node& node) {
    switch (node.type()) {
        case toml::node_type::table: return "a table";
        case toml::node_type::array: return "an array";
        case toml::node_type::string: return "a string";
        case toml::node_type::integer: return "an integer";
        case toml::node_type::floating_point: return "a number";
        case toml::node_type::boolean: return "a boolean";
        case toml::node_type::date: return "a date";
        case toml::node_type::time: return "a time";
        case toml::node_type::date_time: return "a date-time";
        case toml::node_type::none: break;
    }
    return "nothing";
}

std::string as_written(const toml::node& node) {
    if (const auto* s = node.as_string()) return in_quotes(s->get());
    if (const auto* i = node.as_integer()) return fmt::format("{}", i->get());
    if (const auto* f = node.as_floating_point()) {
        const double v = f->get();
        if (std::isnan(v)) return "nan";
        if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
        return fmt::format("{}", v);
    }
    if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
    return std::string(type_name(node));
}

double read_quantity(const Reporter& reporter, const toml::node& node, const std::string& key_path, Dimension d,
                     Limit limit) {
    const std::size_t line = line_of(node);
    double value = 0.0;
    if (const auto* i = node.as_integer()) {
        value = static_cast<double>(i->get());
    } else if (const auto* f = node.as_floating_point()) {
        value = f->get();
        if (std::isnan(value)) reporter.fail(line, key_path, fmt::format("nan is not allowed: {} must be finite", a_or_an(noun_of(d))));
        if (std::isinf(value) && !(limit == Limit::PositiveOrInfinite && value > 0)) {
            reporter.fail(line, key_path, fmt::format("{} is not allowed: {} must be finite", as_written(node), a_or_an(noun_of(d))));
        }
    } else if (const auto* s = node.as_string()) {
        try {
            value = parse_quantity(s->get(), d);
        } catch (const UnitError& e) {
            reporter.fail(line, key_path, e.what());
        }
    } else {
        reporter.fail(line, key_path, fmt::format("expected {}, got {}", expected_quantity(d), type_name(node)));
    }
    switch (limit) {
        case Limit::Any: break;
        case Limit::Positive:
        case Limit::PositiveOrInfinite:
            if (!(value > 0.0)) {
                reporter.fail(line, key_path, fmt::format("{} must be a positive {}", as_written(node), noun_of(d)));
            }
            break;
        case Limit::NonNegative:
            if (!(value >= 0.0)) {
                reporter.fail(line, key_path, fmt::format("{} must not be negative", as_written(node)));
            }
            break;
        case Limit::BelowLightSpeed:
            if (!(std::abs(value) < speed_of_light)) {
                reporter.fail(line, key_path,
                              fmt::format("{} is out of range: a velocity must be below the speed of light, {} m/s", as_written(node),
                                          speed_of_light));
            }
            break;
    }
    return value;
}

TableReader::TableReader(const Reporter& reporter, const toml::table& table, std::string path, std::string what,
                         std::vector<std::string_view> allowed)
    : reporter_(reporter), table_(table), path_(std::move(path)) {
    for (const auto& [key, node] : table_) {
        const std::string_view k = key.str();
        if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
        std::size_t line = key.source().begin.line;
        if (line == 0) line = line_of(node);
        if (const auto suggestion = closest(k, allowed)) {
            reporter_.fail(line, key_path(k), fmt::format("unknown key; did you mean \"{}\"?", *suggestion));
        }
        reporter_.fail(line, key_path(k), fmt::format("unknown key; {} takes {}", what, join(allowed)));
    }
}

std::string TableReader::key_path(std::string_view key) const {
    // Keys that are not bare words are quoted, as TOML would write them.
    const bool bare = !key.empty() && std::all_of(key.begin(), key.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
    });
    const std::string k = bare ? std::string(key) : in_quotes(key);
    return path_.empty() ? k : path_ + "." + k;
}

void TableReader::fail_at(std::string_view key, std::string_view message) const {
    const toml::node* node = find(key);
    reporter_.fail(node ? line_of(*node) : line_of(table_), key_path(key), message);
}

void TableReader::fail_table(std::string_view message) const { reporter_.fail(line_of(table_), path_, message); }

void TableReader::fail_missing(std::string_view key, std::string_view what) const {
    // The top level has no header line to point at.
    reporter_.fail(path_.empty() ? 0 : line_of(table_), path_, fmt::format("missing required key \"{}\": {}", key, what));
}

std::optional<double> TableReader::quantity(std::string_view key, Dimension d, Limit limit) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    return read_quantity(reporter_, *node, key_path(key), d, limit);
}

double TableReader::required_quantity(std::string_view key, Dimension d, Limit limit) const {
    const auto value = quantity(key, d, limit);
    if (!value) fail_missing(key, expected_quantity(d));
    return *value;
}

std::optional<std::string> TableReader::string(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const auto* s = node->as_string();
    if (!s) fail_at(key, fmt::format("expected a string, got {} ({})", type_name(*node), as_written(*node)));
    return s->get();
}

std::string TableReader::required_string(std::string_view key, std::string_view what) const {
    auto value = string(key);
    if (!value) fail_missing(key, what);
    return *value;
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const auto* b = node->as_boolean();
    if (!b) fail_at(key, fmt::format("expected true or false, got {} ({})", type_name(*node), as_written(*node)));
    return b->get();
}

std::optional<long long> TableReader::whole_number(std::string_view key, long long min, long long max) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const std::string range = max == std::numeric_limits<long long>::max()
                                  ? fmt::format("a whole number of at least {}", min)
                                  : fmt::format("a whole number from {} to {}", min, max);
    long long value = 0;
    if (const auto* i = node->as_integer()) {
        value = i->get();
    } else if (const auto* f = node->as_floating_point()) {
        // 1e6 is a fine way to write a step count.
        const double v = f->get();
        if (!(std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 9.0e15)) {
            fail_at(key, fmt::format("{} is not {}", as_written(*node), range));
        }
        value = static_cast<long long>(v);
    } else {
        fail_at(key, fmt::format("expected {}, got {} ({})", range, type_name(*node), as_written(*node)));
    }
    if (value < min || value > max) fail_at(key, fmt::format("{} is not {}", as_written(*node), range));
    return value;
}

std::optional<std::vector<double>> TableReader::quantities(std::string_view key, Dimension d, std::size_t count,
                                                           Limit limit, std::string_view components) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const auto* array = node->as_array();
    const std::string expected =
        fmt::format("an array of {} {} {}", count, d == D::Dimensionless ? "numbers" : fmt::format("{} values", name_of(d)),
                    components);
    if (!array) fail_at(key, fmt::format("expected {}, got {} ({})", expected, type_name(*node), as_written(*node)));
    if (array->size() != count) {
        fail_at(key, fmt::format("expected {}, got {} value{}", expected, array->size(), array->size() == 1 ? "" : "s"));
    }
    std::vector<double> values;
    for (std::size_t i = 0; i < count; ++i) {
        values.push_back(read_quantity(reporter_, (*array)[i], fmt::format("{}[{}]", key_path(key), i), d, limit));
    }
    return values;
}

std::optional<std::size_t> TableReader::word_index(std::string_view key, const std::vector<std::string_view>& words) const {
    const auto word = string(key);
    if (!word) return std::nullopt;
    for (std::size_t i = 0; i < words.size(); ++i) {
        if (*word == words[i]) return i;
    }
    fail_choice(key, *word, words);
}

void TableReader::fail_choice(std::string_view key, std::string_view word,
                              const std::vector<std::string_view>& names) const {
    std::string message = fmt::format("{} is not one of {}", in_quotes(word), join_quoted(names));
    if (const auto suggestion = closest(word, names)) message += fmt::format(" (did you mean \"{}\"?)", *suggestion);
    fail_at(key, message);
}

}  // namespace gpa::io::detail
