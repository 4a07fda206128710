// The table of solver options (gpa/engine/solver_options.hpp) is the one list of [solver] keys:
// for every row, a scene file and a `gpa study` variant accept the same value into the same
// SolverOptions, refuse the same bad value naming the key, and leave the default when the key is
// absent; and the table has a row for every member of SolverOptions that a scene file can set.

#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/solver_options.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"

namespace gpa::io {
namespace {

// A scene with no [solver] table; tests append one.
const std::string base_scene = R"toml(
geometry = "plane-strain"
[[material]]
name = "rubber"
density = 1000
shear_modulus = "1 MPa"
eos = { model = "linear", bulk_modulus = "10 MPa" }
strength = "elastic"
[[body]]
shape = "rectangle"
material = "rubber"
size = ["4 mm", "4 mm"]
spacing = "1 mm"
[stop]
end_time = "10 us"
)toml";

// One value of a row, as a scene file writes it (TOML) and as a variant writes it.
struct Written {
    std::string toml;
    std::string variant;
};

Written number_written(double v, OptionUnit unit) {
    if (unit == OptionUnit::Time) return {fmt::format("\"{:g} ns\"", v * 1e9), fmt::format("{:g} ns", v * 1e9)};
    return {fmt::format("{}", v), fmt::format("{}", v)};
}

// A valid value of the row that is not its default.
Written valid_value(const SolverOption& option) {
    const SolverOptions defaults;
    return std::visit(
        [&](const auto& k) -> Written {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                const OptionRange& r = k.range;
                // A time of 7 ns, or a number inside the range away from its ends and the default.
                double v = k.unit == OptionUnit::Time ? 7e-9
                           : std::isinf(r.highest)   ? r.lowest + 2.5
                                                     : r.lowest + 0.375 * (r.highest - r.lowest);
                if (v == defaults.*k.member) v = std::isinf(r.highest) ? r.lowest + 4.5 : r.lowest + 0.625 * (r.highest - r.lowest);
                return number_written(v, k.unit);
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                const std::string v = fmt::format("{}", defaults.*k.member + 1);
                return {v, v};
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                const std::string v = defaults.*k.member ? "false" : "true";
                return {v, v};
            } else {
                const int current = k.get(defaults);
                for (const auto& w : k.words) {
                    if (w.value != current) return {fmt::format("\"{}\"", w.word), std::string(w.word)};
                }
                ADD_FAILURE() << option.key << " has a single word";
                return {};
            }
        },
        option.kind);
}

// A value the row refuses: below its range, or a word (or boolean) it does not take.
Written refused_value(const SolverOption& option) {
    return std::visit(
        [&](const auto& k) -> Written {
            using K = std::decay_t<decltype(k)>;
            if constexpr (std::is_same_v<K, NumberOption>) {
                return number_written(k.range.lowest - (k.unit == OptionUnit::Time ? 1e-9 : 1.0), k.unit);
            } else if constexpr (std::is_same_v<K, WholeNumberOption>) {
                const std::string v = fmt::format("{}", k.range.lowest - 1.0);
                return {v, v};
            } else if constexpr (std::is_same_v<K, BooleanOption>) {
                return {"\"maybe\"", "maybe"};
            } else {
                return {"\"no-such-word\"", "no-such-word"};
            }
        },
        option.kind);
}

// Values above a range with a finite top (or the excluded end itself), refused alike.
std::vector<Written> refused_above(const SolverOption& option) {
    std::vector<Written> out;
    if (const auto* k = std::get_if<NumberOption>(&option.kind); k && std::isfinite(k->range.highest)) {
        out.push_back(number_written(k->range.highest + 1.0, k->unit));
        if (!k->range.highest_included) out.push_back(number_written(k->range.highest, k->unit));
    }
    if (const auto* k = std::get_if<NumberOption>(&option.kind); k && !k->range.lowest_included) {
        out.push_back(number_written(k->range.lowest, k->unit));
    }
    return out;
}

// A row whose value needs another key set (the rules across keys of check_solver): that key and
// its value, set beside it in both forms; empty for the others.
std::pair<std::string, std::string> needed_beside(const SolverOption& option) {
    if (std::string_view(option.key) == "hourglass_stiffness_relaxation") return {"hourglass_stiffness", "0.05"};
    return {};
}

std::string scene_with(const SolverOption& option, const std::string& toml_value) {
    const auto [key, value] = needed_beside(option);
    const std::string beside = key.empty() ? "" : fmt::format("{} = {}\n", key, value);
    return base_scene + fmt::format("[solver]\n{}{} = {}\n", beside, option.key, toml_value);
}

SolverOptions from_scene(const SolverOption& option, const std::string& toml_value) {
    return parse_scene(scene_with(option, toml_value), "options.toml").solver;
}

SolverOptions from_variant(const SolverOption& option, const std::string& value) {
    Scene scene = parse_scene(base_scene, "base.toml");
    const auto [key, beside] = needed_beside(option);
    apply_variant(parse_variant(key.empty() ? fmt::format("v:{}={}", option.key, value)
                                            : fmt::format("v:{}={},{}={}", key, beside, option.key, value)),
                  scene);
    return scene.solver;
}

// The InputError message of `f`, or "" with a test failure when it does not throw one.
template <class F>
std::string input_error(F&& f, const std::string& what) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << what << ": no InputError";
    return {};
}

TEST(SolverOptionTable, EveryRowIsAcceptedAlikeByASceneFileAndAVariant) {
    for (const SolverOption& option : solver_option_table()) {
        SCOPED_TRACE(option.key);
        const Written v = valid_value(option);
        const SolverOptions scene = from_scene(option, v.toml);
        const SolverOptions variant = from_variant(option, v.variant);
        EXPECT_EQ(scene, variant) << option.key << " = " << v.toml << " / " << v.variant;
        EXPECT_NE(option_value_text(option, scene), option_default_text(option)) << "the value did not arrive";
        // Only this row's member changed (and the key set beside it: needed_beside).
        SolverOptions expected;
        for (const SolverOption& other : solver_option_table()) {
            if (&other != &option && needed_beside(option).first != other.key) {
                EXPECT_EQ(option_value_text(other, scene), option_default_text(other)) << other.key;
            }
        }
        EXPECT_TRUE(scene != expected);
    }
}

TEST(SolverOptionTable, EveryRowRefusesTheSameValuesInASceneFileAndAVariant) {
    for (const SolverOption& option : solver_option_table()) {
        SCOPED_TRACE(option.key);
        std::vector<Written> refused = refused_above(option);
        refused.push_back(refused_value(option));
        const std::string key = fmt::format("solver.{}", option.key);
        for (const Written& v : refused) {
            const std::string in_scene = input_error([&] { from_scene(option, v.toml); }, "scene " + v.toml);
            EXPECT_NE(in_scene.find(key), std::string::npos) << in_scene;
            EXPECT_NE(in_scene.find("options.toml"), std::string::npos) << in_scene;
            // parse_variant refuses before anything runs; apply_variant refuses settings that
            // were not parsed (a Variant built in code) as well.
            const std::string text = fmt::format("v:{}={}", option.key, v.variant);
            const std::string parsed = input_error([&] { parse_variant(text); }, "variant " + text);
            EXPECT_NE(parsed.find(key), std::string::npos) << parsed;
            EXPECT_NE(parsed.find(fmt::format("--variant '{}'", text)), std::string::npos) << parsed;
            Scene scene = parse_scene(base_scene, "base.toml");
            const Variant unparsed{"v", {{std::string(option.key), v.variant}}, std::nullopt};
            const std::string applied = input_error([&] { apply_variant(unparsed, scene); }, "apply " + text);
            EXPECT_NE(applied.find(key), std::string::npos) << applied;
        }
    }
}

// The relaxing reference belongs to the stiffness form: a time constant without a stiffness would
// change nothing, and is refused naming both keys, in a scene file and in a variant.
TEST(SolverOptionTable, ARelaxationWithoutAStiffnessIsRefused) {
    const std::string scene = base_scene + "[solver]\nhourglass_stiffness_relaxation = \"5 us\"\n";
    const std::string message = input_error([&] { parse_scene(scene, "s.toml"); }, "relaxation alone");
    EXPECT_NE(message.find("hourglass_stiffness_relaxation"), std::string::npos) << message;
    EXPECT_NE(message.find("needs solver.hourglass_stiffness > 0"), std::string::npos) << message;
    Scene variant = parse_scene(base_scene, "base.toml");
    const std::string applied =
        input_error([&] { apply_variant(parse_variant("v:hourglass_stiffness_relaxation=5 us"), variant); }, "variant");
    EXPECT_NE(applied.find("needs solver.hourglass_stiffness > 0"), std::string::npos) << applied;
    EXPECT_NO_THROW(parse_scene(base_scene + "[solver]\nhourglass_stiffness = 0.01\nhourglass_stiffness_relaxation = \"5 us\"\n", "s.toml"));
}

TEST(SolverOptionTable, AnAbsentKeyKeepsItsDefault) {
    const SolverOptions defaults;
    EXPECT_EQ(parse_scene(base_scene, "base.toml").solver, defaults);
    Scene plain = parse_scene(base_scene, "base.toml");
    apply_variant(parse_variant("v"), plain);
    EXPECT_EQ(plain.solver, defaults);
    // With another row's key set, each row keeps its default in both.
    const auto table = solver_option_table();
    for (std::size_t i = 0; i < table.size(); ++i) {
        const SolverOption& option = table[i];
        const SolverOption& other = table[(i + 1) % table.size()];
        SCOPED_TRACE(option.key);
        if (needed_beside(other).first == option.key) continue;  // set beside the other row, on purpose
        const Written v = valid_value(other);
        EXPECT_EQ(option_value_text(option, from_scene(other, v.toml)), option_default_text(option));
        EXPECT_EQ(option_value_text(option, from_variant(other, v.variant)), option_default_text(option));
    }
}

// The number of members of an aggregate: the most initialisers that brace-initialisation takes.
struct AnyValue {
    template <class T>
    operator T() const;  // declared only: used in unevaluated requires-expressions
};

template <class T, class... Values>
constexpr std::size_t member_count() {
    if constexpr (requires { T{Values{}..., AnyValue{}}; }) {
        return member_count<T, Values..., AnyValue>();
    } else {
        return sizeof...(Values);
    }
}

TEST(SolverOptionTable, CoversEveryMemberThatASceneFileCanSet) {
    // Every member of SolverOptions but check_neighbour_lists (for tests, not read from scene
    // files) has a row; a new member without one fails here.
    EXPECT_EQ(member_count<SolverOptions>(), solver_option_table().size() + 1);
    // Keys are unique, and each names a [solver] key the scene reader accepts (all at once).
    std::string solver = "[solver]\n";
    for (const SolverOption& option : solver_option_table()) {
        EXPECT_EQ(find_solver_option(option.key), &option) << option.key << " is listed twice";
        solver += fmt::format("{} = {}\n", option.key, valid_value(option).toml);
    }
    // Every row set at once: each member takes the row's value, as the rows act one by one.
    const SolverOptions all = parse_scene(base_scene + solver, "all.toml").solver;
    for (const SolverOption& option : solver_option_table()) {
        EXPECT_EQ(option_value_text(option, all), option_value_text(option, from_scene(option, valid_value(option).toml)))
            << option.key;
    }
    // A key outside the table is refused by both, and a near miss is named.
    EXPECT_NE(input_error([&] { parse_scene(base_scene + "[solver]\nneighbor_skin = 0.3\n", "s.toml"); }, "neighbor_skin")
                  .find("did you mean \"neighbour_skin\""),
              std::string::npos);
    EXPECT_NE(input_error([&] { parse_variant("v:check_neighbour_lists=true"); }, "check_neighbour_lists").find("unknown key"),
              std::string::npos);
}

TEST(SolverOptionTable, VariantHelpListsEveryRow) {
    const std::string help = variant_keys_help();
    for (const SolverOption& option : solver_option_table()) {
        EXPECT_NE(help.find(fmt::format("{}=", option.key)), std::string::npos) << option.key;
    }
    EXPECT_NE(help.find("weight=gpa|sph-nsf,"), std::string::npos) << help;
    EXPECT_NE(help.find("max_time_step=TIME"), std::string::npos) << help;
    EXPECT_NE(help.find("discretisation=particles|elements"), std::string::npos) << help;
    EXPECT_NE(help.find("threads=N"), std::string::npos) << help;
}

TEST(SolverOptionTable, RangesPrintAndHoldTheirEnds) {
    const auto* cfl = find_solver_option("cfl");
    ASSERT_TRUE(cfl);
    EXPECT_EQ(option_allowed_text(*cfl), "(0, 1]");
    const auto* max_dt = find_solver_option("max_time_step");
    ASSERT_TRUE(max_dt);
    EXPECT_EQ(option_allowed_text(*max_dt), "(0, inf] s");
    EXPECT_EQ(option_default_text(*max_dt), "inf");
    const auto& range = std::get<NumberOption>(max_dt->kind).range;
    EXPECT_TRUE(range.contains(std::numeric_limits<double>::infinity()));
    EXPECT_FALSE(range.contains(0.0));
    EXPECT_FALSE(range.contains(std::nan("")));
    SolverOptions s;
    s.cfl = 0.0;
    EXPECT_EQ(option_error(*cfl, s).value_or(""), "solver.cfl = 0 is outside (0, 1]");
    // A value that is no listed enumerator (a Scene built in code) is refused, naming the words.
    s.weight = static_cast<WeightKind>(17);
    const auto* weight = find_solver_option("weight");
    ASSERT_TRUE(weight);
    EXPECT_EQ(option_error(*weight, s).value_or(""), "solver.weight: 17 is not a known value; the words are \"gpa\", \"sph-nsf\"");
}

}  // namespace
}  // namespace gpa::io
