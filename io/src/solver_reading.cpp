#include "solver_reading.hpp"

#include <cmath>
#include <limits>
#include <type_traits>
#include <variant>
#include <vector>

namespace gpa::io::detail {

namespace {

// The whole-number limits of a row's range for TableReader::whole_number (an infinite end is
// no limit).
long long lower_whole(const OptionRange& r) {
    if (std::isinf(r.lowest)) return std::numeric_limits<long long>::min();
    return static_cast<long long>(r.lowest_included ? std::ceil(r.lowest) : std::floor(r.lowest) + 1.0);
}

long long upper_whole(const OptionRange& r) {
    if (std::isinf(r.highest)) return std::numeric_limits<long long>::max();
    return static_cast<long long>(r.highest_included ? std::floor(r.highest) : std::ceil(r.highest) - 1.0);
}

// True for text that the TOML parser may be given as a value: printable ASCII on one line
// (check_text's rules for scene files, which this text never passed through).
bool plain_ascii(std::string_view text) {
    for (const char c : text) {
        if (c < 0x20 || c > 0x7e) return false;
    }
    return true;
}

// A variant's value as the TOML node a scene file would hold for it: a number, a boolean or a
// quoted string if the text is one of those in TOML, else the text itself as a string. The new
// node carries no source position, so that messages print no line number of this pseudo-file.
toml::table value_table(std::string_view key, std::string_view value) {
    toml::table out;
    if (plain_ascii(value)) {
        try {
            const toml::table parsed = toml::parse(std::string("v = ") + std::string(value));
            const toml::node* node = parsed.get("v");
            if (parsed.size() == 1 && node) {
                if (const auto* i = node->as_integer()) {
                    out.insert(key, i->get());
                    return out;
                }
                if (const auto* f = node->as_floating_point()) {
                    out.insert(key, f->get());
                    return out;
                }
                if (const auto* b = node->as_boolean()) {
                    out.insert(key, b->get());
                    return out;
                }
                if (const auto* s = node->as_string()) {
                    out.insert(key, s->get());
                    return out;
                }
            }
        } catch (const toml::parse_error&) {
            // Not a TOML value (a bare word such as sph-nsf, or "10 ns"): taken as a string below.
        }
    }
    out.insert(key, std::string(value));
    return out;
}

}  // namespace

Dimension dimension_of(OptionUnit unit) {
    switch (unit) {
        case OptionUnit::Dimensionless: return Dimension::Dimensionless;
        case OptionUnit::Time: return Dimension::Time;
    }
    return Dimension::Dimensionless;
}

void read_solver_option(const TableReader& reader, const SolverOption& option, SolverOptions& s) {
    const std::string_view key = option.key;
    std::visit(
        [&](const auto& k) {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                // Infinity is refused as a number unless the range holds it (max_time_step = inf).
                const Limit limit = k.range.allows_infinity() ? Limit::PositiveOrInfinite : Limit::Any;
                if (const auto v = reader.quantity(key, dimension_of(k.unit), limit)) s.*k.member = *v;
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                if (const auto v = reader.whole_number(key, lower_whole(k.range), upper_whole(k.range))) {
                    s.*k.member = static_cast<std::size_t>(*v);
                }
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                if (const auto v = reader.boolean(key)) s.*k.member = *v;
            } else {
                std::vector<std::string_view> words;
                for (const auto& w : k.words) words.push_back(w.word);
                if (const auto i = reader.word_index(key, words)) k.set(s, k.words[*i].value);
            }
        },
        option.kind);
}

void read_solver_option_text(const SolverOption& option, std::string_view value, const std::string& source,
                             SolverOptions& s) {
    const Reporter reporter(source);
    const toml::table table = value_table(option.key, value);
    const TableReader reader(reporter, table, "solver", "a variant", {option.key});
    read_solver_option(reader, option, s);
}

}  // namespace gpa::io::detail
