// The built-in material library holds the constants of shared/spec/materials.md, with sources,
// and is embedded in the program (it equals materials/data/library.toml).

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <tuple>
#include <sstream>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa::io {
namespace {

namespace m = gpa::materials;

struct JohnsonCookRow {
    const char* name;
    double a_mpa, b_mpa, n, c, m, melt_k, density, specific_heat, shear_gpa;
    double d1, d2, d3, d4, d5;
};

// materials.md, "Johnson-Cook constants".
const JohnsonCookRow johnson_cook_table[] = {
    {"OFHC copper", 90, 292, 0.31, 0.025, 1.09, 1356, 8960, 383, 46, 0.54, 4.89, -3.03, 0.014, 1.12},
    {"Armco iron", 175, 380, 0.32, 0.060, 0.55, 1811, 7890, 452, 80, -2.20, 5.43, -0.47, 0.016, 0.63},
    {"4340 steel", 792, 510, 0.26, 0.014, 1.03, 1793, 7830, 477, 77, 0.05, 3.44, -2.12, 0.002, 0.61},
    {"2024-T351 aluminium", 265, 426, 0.34, 0.015, 1.00, 775, 2770, 875, 27.6, 0.13, 0.13, -1.5, 0.011, 0.0},
};

TEST(MaterialLibrary, HoldsTheFourSpecMaterialsFirstThenTheOthers) {
    const auto& library = builtin_materials();
    ASSERT_EQ(library.size(), 9u);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ(library[i].name, johnson_cook_table[i].name);
    EXPECT_EQ(builtin_material_names(), "OFHC copper, Armco iron, 4340 steel, 2024-T351 aluminium, Weldox 460 E, "
                                        "6061-T6 aluminium, 7075-T6 aluminium, Ti-6Al-4V, tungsten heavy alloy");
}

TEST(MaterialLibrary, JohnsonCookConstantsMatchTheSpec) {
    for (const JohnsonCookRow& row : johnson_cook_table) {
        SCOPED_TRACE(row.name);
        const m::Material& mat = builtin_material(row.name);
        const auto& jc = std::get<m::JohnsonCookStrength>(mat.strength);
        EXPECT_EQ(jc.a, row.a_mpa * 1e6);
        EXPECT_EQ(jc.b, row.b_mpa * 1e6);
        EXPECT_EQ(jc.n, row.n);
        EXPECT_EQ(jc.c, row.c);
        EXPECT_EQ(jc.m, row.m);
        EXPECT_EQ(jc.reference_strain_rate, 1.0);
        EXPECT_EQ(mat.melt_temperature, row.melt_k);
        EXPECT_EQ(mat.density, row.density);  // the Johnson-Cook table's density, also the EOS rho0
        EXPECT_EQ(mat.specific_heat, row.specific_heat);
        EXPECT_EQ(mat.shear_modulus, row.shear_gpa * 1e9);
        EXPECT_EQ(mat.room_temperature, 294.0);
        EXPECT_EQ(mat.taylor_quinney, 0.9);
        ASSERT_TRUE(mat.failure.johnson_cook.has_value());
        const m::JohnsonCookFailure& f = *mat.failure.johnson_cook;
        EXPECT_EQ(f.d1, row.d1);
        EXPECT_EQ(f.d2, row.d2);
        EXPECT_EQ(f.d3, row.d3);
        EXPECT_EQ(f.d4, row.d4);
        EXPECT_EQ(f.d5, row.d5);
        EXPECT_FALSE(mat.failure.spall_pressure.has_value());
        EXPECT_NO_THROW(m::validate(mat));
    }
}

TEST(MaterialLibrary, EquationsOfStateMatchTheSpec) {
    const auto shock = [](const char* name) { return std::get<m::MieGruneisenEos>(builtin_material(name).eos); };
    EXPECT_EQ(shock("OFHC copper").sound_speed, 3940.0);
    EXPECT_EQ(shock("OFHC copper").slope, 1.489);
    EXPECT_EQ(shock("OFHC copper").gruneisen, 2.02);
    EXPECT_EQ(shock("4340 steel").sound_speed, 4578.0);
    EXPECT_EQ(shock("4340 steel").slope, 1.33);
    EXPECT_EQ(shock("4340 steel").gruneisen, 1.67);
    EXPECT_EQ(shock("2024-T351 aluminium").sound_speed, 5328.0);
    EXPECT_EQ(shock("2024-T351 aluminium").slope, 1.338);
    EXPECT_EQ(shock("2024-T351 aluminium").gruneisen, 2.0);
    // Armco iron: K1 = 165 GPa and Gamma0 1.7, not the shock fit of the epsilon phase.
    const auto& iron = std::get<m::PolynomialEos>(builtin_material("Armco iron").eos);
    EXPECT_EQ(iron.k1, 165e9);
    EXPECT_EQ(iron.k2, 0.0);
    EXPECT_EQ(iron.k3, 0.0);
    EXPECT_EQ(iron.gruneisen, 1.7);
}

TEST(MaterialLibrary, SourcesCiteAndMarkWhatWasNotChecked) {
    for (std::size_t i = 0; i < 4; ++i) {
        const auto& mat = builtin_materials()[i];
        SCOPED_TRACE(mat.name);
        EXPECT_NE(mat.source.find("Johnson and Cook (1983)"), std::string::npos);
        EXPECT_NE(mat.source.find("Shear modulus"), std::string::npos);
        EXPECT_NE(mat.source.find("NOT CHECKED"), std::string::npos);
    }
    // The five added later: each names where its strength constants were read, and says what was
    // not checked against a primary paper.
    for (std::size_t i = 4; i < builtin_materials().size(); ++i) {
        const auto& mat = builtin_materials()[i];
        SCOPED_TRACE(mat.name);
        EXPECT_NE(mat.source.find("Johnson-Cook strength"), std::string::npos);
        EXPECT_NE(mat.source.find("NOT CHECKED"), std::string::npos);
        EXPECT_TRUE(mat.source.find("EOS") != std::string::npos || mat.source.find("Mie-Grueneisen") != std::string::npos);
    }
    // Two densities in the spec: the source says which one rho0 is.
    EXPECT_NE(builtin_material("OFHC copper").source.find("8930"), std::string::npos);
    EXPECT_NE(builtin_material("4340 steel").source.find("7810"), std::string::npos);
    EXPECT_NE(builtin_material("2024-T351 aluminium").source.find("2785"), std::string::npos);
    EXPECT_NE(builtin_material("2024-T351 aluminium").source.find("Holmquist"), std::string::npos);
    EXPECT_NE(builtin_material("Armco iron").source.find("165 GPa"), std::string::npos);
}

TEST(MaterialLibrary, LookupIgnoresLetterCaseAndListsNamesWhenUnknown) {
    EXPECT_EQ(&builtin_material("ofhc COPPER"), &builtin_materials()[0]);
    EXPECT_EQ(find_builtin_material("unobtainium"), nullptr);
    try {
        builtin_material("unobtainium");
        FAIL() << "no error";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("unobtainium"), std::string::npos) << what;
        EXPECT_NE(what.find("OFHC copper, Armco iron, 4340 steel, 2024-T351 aluminium"), std::string::npos) << what;
    }
}

TEST(MaterialLibrary, IsEmbeddedFromTheDataFile) {
    std::ifstream in(GPA_MATERIAL_LIBRARY_FILE, std::ios::binary);
    ASSERT_TRUE(in) << GPA_MATERIAL_LIBRARY_FILE;
    std::ostringstream text;
    text << in.rdbuf();
    EXPECT_EQ(builtin_library_text(), text.str());
}

TEST(MaterialLibrary, OtherLibrariesUseTheSameFormat) {
    const auto materials = parse_material_library(R"toml(
[[material]]
name = "warm copper"
base = "OFHC copper"
room_temperature = "400 K"
[[material]]
name = "warmer copper"
base = "warm copper"
room_temperature = "500 K"
)toml",
                                                  "mine.toml");
    ASSERT_EQ(materials.size(), 2u);
    EXPECT_EQ(materials[1].room_temperature, 500.0);
    EXPECT_EQ(materials[1].density, 8960.0);
    EXPECT_THROW(parse_material_library("[[material]]\nname = \"x\"\nbase = \"y\"\n", "mine.toml"), SceneError);
}

// Bit for bit: a printed number must read back as the same double (its unit's power of ten is
// moved into the decimal point, never multiplied).
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_same_material(const m::Material& a, const m::Material& b) {
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.source, b.source);
    for (const auto& [x, y, what] : {std::tuple{a.density, b.density, "density"},
                                     std::tuple{a.shear_modulus, b.shear_modulus, "shear modulus"},
                                     std::tuple{a.specific_heat, b.specific_heat, "specific heat"},
                                     std::tuple{a.taylor_quinney, b.taylor_quinney, "Taylor-Quinney"},
                                     std::tuple{a.room_temperature, b.room_temperature, "room temperature"},
                                     std::tuple{a.melt_temperature, b.melt_temperature, "melt temperature"}}) {
        EXPECT_TRUE(same_bits(x, y)) << what << ": " << x << " printed and read back as " << y;
    }
    ASSERT_EQ(a.eos.index(), b.eos.index());
    ASSERT_EQ(a.strength.index(), b.strength.index());
    const auto bits = [](const auto& v) {
        std::vector<double> out;
        std::visit([&](const auto& model) {
            if constexpr (std::is_same_v<std::decay_t<decltype(model)>, m::LinearEos>) {
                out = {model.bulk_modulus, model.logarithmic ? 1.0 : 0.0};
            } else if constexpr (std::is_same_v<std::decay_t<decltype(model)>, m::PolynomialEos>) {
                out = {model.k1, model.k2, model.k3, model.gruneisen};
            } else if constexpr (std::is_same_v<std::decay_t<decltype(model)>, m::MieGruneisenEos>) {
                out = {model.sound_speed, model.slope, model.gruneisen};
            } else if constexpr (std::is_same_v<std::decay_t<decltype(model)>, m::VonMisesStrength>) {
                out = {model.yield_stress, model.hardening_modulus};
            } else if constexpr (std::is_same_v<std::decay_t<decltype(model)>, m::JohnsonCookStrength>) {
                out = {model.a, model.b, model.n, model.c, model.m, model.reference_strain_rate};
            }
        }, v);
        return out;
    };
    const auto compare = [&](const std::vector<double>& x, const std::vector<double>& y, const char* what) {
        ASSERT_EQ(x.size(), y.size()) << what;
        for (std::size_t k = 0; k < x.size(); ++k) EXPECT_TRUE(same_bits(x[k], y[k])) << what << " constant " << k << ": " << x[k] << " vs " << y[k];
    };
    compare(bits(a.eos), bits(b.eos), "equation of state");
    compare(bits(a.strength), bits(b.strength), "strength");
    ASSERT_EQ(a.failure.johnson_cook.has_value(), b.failure.johnson_cook.has_value());
    if (a.failure.johnson_cook) {
        const auto& f = *a.failure.johnson_cook;
        const auto& g = *b.failure.johnson_cook;
        compare({f.d1, f.d2, f.d3, f.d4, f.d5, f.reference_strain_rate, f.min_failure_strain},
                {g.d1, g.d2, g.d3, g.d4, g.d5, g.reference_strain_rate, g.min_failure_strain}, "Johnson-Cook fracture");
    }
    ASSERT_EQ(a.failure.spall_pressure.has_value(), b.failure.spall_pressure.has_value());
    if (a.failure.spall_pressure) {
        EXPECT_TRUE(same_bits(*a.failure.spall_pressure, *b.failure.spall_pressure));
    }
}

// `gpa materials NAME` prints every constant as a [[material]] table; read back, it is the same
// material bit for bit: every library material, and made-up ones with every model, awkward
// numbers (17 significant digits, tiny and huge, negative) and quotes in their text.
TEST(MaterialLibrary, EveryMaterialPrintsAsATableThatReadsBackBitForBit) {
    std::vector<m::Material> materials = builtin_materials();
    m::Material odd;
    odd.name = "odd \"quoted\" \\ name";
    odd.source = "line one\nline two, with a tab\tand \"quotes\"";
    odd.density = 1234.5678901234567;
    odd.shear_modulus = 0.1 + 0.2;  // 0.30000000000000004 Pa
    odd.specific_heat = 0.0;
    odd.taylor_quinney = 1.0 / 3.0;
    odd.room_temperature = 293.15;
    odd.eos = m::LinearEos{2.5e10 / 3.0, true};
    odd.strength = m::VonMisesStrength{7.0e8 / 3.0, 1e-3};
    odd.failure.spall_pressure = 1.5e9;
    materials.push_back(odd);
    m::Material poly = odd;
    poly.name = "polynomial";
    poly.melt_temperature = 1e4 / 7.0;
    poly.eos = m::PolynomialEos{165e9, -1.23456789e11, 9.87654321e12, -0.0};  // a plain -0.0 keeps its sign
    poly.strength = m::ElasticStrength{};
    poly.failure = {};
    materials.push_back(poly);
    m::Material jc = builtin_material("4340 steel");
    jc.name = "johnson-cook at odd rates";
    std::get<m::JohnsonCookStrength>(jc.strength).reference_strain_rate = 5e-4;
    jc.failure.johnson_cook->reference_strain_rate = 1.0 / 3.0;
    jc.failure.johnson_cook->d4 = -0.015;
    jc.failure.johnson_cook->min_failure_strain = 1e-9;
    jc.failure.spall_pressure = 2.9e9;
    materials.push_back(jc);
    for (const auto& material : materials) {
        const std::string text = material_as_toml(material);
        std::vector<m::Material> read;
        ASSERT_NO_THROW(read = parse_material_library(text, "printed.toml")) << text;
        ASSERT_EQ(read.size(), 1u);
        expect_same_material(material, read.front());
    }
    // The library's own units, as a reader of the table expects them.
    const std::string copper = material_as_toml(builtin_material("OFHC copper"));
    EXPECT_NE(copper.find("a = \"90 MPa\""), std::string::npos) << copper;
    EXPECT_NE(copper.find("shear_modulus = \"46 GPa\""), std::string::npos) << copper;
    EXPECT_NE(copper.find("sound_speed = \"3940 m/s\""), std::string::npos) << copper;
    // Zero is 0 in any unit (Armco iron's K2 and K3), not 0.000000 MPa.
    const std::string iron = material_as_toml(builtin_material("Armco iron"));
    EXPECT_NE(iron.find("k2 = \"0 MPa\", k3 = \"0 MPa\""), std::string::npos) << iron;
}

// `gpa check` shows what a material derived with `base` changes: exactly the constants the table
// sets to other values, a changed model's constants, and the base's that are gone.
TEST(MaterialLibrary, ADerivedMaterialListsWhatItChanges) {
    const auto derived = parse_material_library(R"(
[[material]]
name = "hot copper"
base = "OFHC copper"
strength = { a = "120 MPa", n = 0.31 }
room_temperature = "400 K"

[[material]]
name = "copper, linear"
base = "hot copper"
eos = { model = "linear", bulk_modulus = "140 GPa" }
failure = "none"
)", "derived.toml");
    ASSERT_EQ(derived.size(), 2u);
    EXPECT_EQ(derived[0].base, "OFHC copper");
    EXPECT_EQ(derived[1].base, "hot copper");
    EXPECT_TRUE(builtin_material("OFHC copper").base.empty());
    // n = 0.31 is the base's value: no change.
    EXPECT_EQ(material_changes(derived[0], builtin_material("OFHC copper")),
              (std::vector<std::string>{"room_temperature = \"400 K\" (base: \"294 K\")",
                                        "strength.a = \"120 MPa\" (base: \"90 MPa\")"}));
    const auto second = material_changes(derived[1], derived[0]);
    const std::vector<std::string> expected{
        "eos.model = \"linear\" (base: \"mie-gruneisen\")", "eos.bulk_modulus = \"140 GPa\" (base: none)",
        "eos.logarithmic = false (base: none)",             "failure = \"none\" (base: none)",
        "no eos.sound_speed (base: \"3940 m/s\")",          "no eos.slope (base: 1.489)",
        "no eos.gruneisen (base: 2.02)",                    "no failure.johnson_cook.d1 (base: 0.54)",
    };
    for (const auto& line : expected) {
        EXPECT_NE(std::find(second.begin(), second.end(), line), second.end()) << line << " missing from " << testing::PrintToString(second);
    }
    EXPECT_EQ(second.size(), 4u + 3u + 7u) << testing::PrintToString(second);  // the model and 3 new keys; 3 EOS and 7 fracture constants gone
    EXPECT_TRUE(material_changes(derived[0], derived[0]).empty());
}

// Every library material runs: a small axisymmetric bar of it (2 mm radius, 8 cells across) strikes
// a rigid plane at 200 m/s and takes 40 steps under the default solver, with finite fields and its
// energy balance closed (the compatible update: to 1e-9 of the energy given, far above round-off
// and far below any lost work).
TEST(MaterialLibrary, EveryMaterialRunsASmallImpact) {
    for (const auto& mat : builtin_materials()) {
        SCOPED_TRACE(mat.name);
        Scene s;
        s.geometry = GeometryKind::Axisymmetric;
        s.materials = {mat};
        BodySpec bar;
        bar.name = "bar";
        bar.shape = ShapeKind::Cylinder;
        bar.material = mat.name;
        bar.radius = 2e-3;
        bar.length = 6e-3;
        bar.spacing = 0.25e-3;
        bar.velocity = {0.0, -200.0, 0.0};
        s.bodies = {bar};
        PlaneSpec anvil;
        anvil.name = "anvil";
        anvil.axis = 1;
        s.planes = {anvil};
        s.stop.end_time = 1.0;
        Simulation sim(s, 2);
        for (int k = 0; k < 40; ++k) sim.step();
        const auto& t = sim.totals();
        EXPECT_TRUE(std::isfinite(t.kinetic_energy) && std::isfinite(t.internal_energy));
        EXPECT_LT(t.kinetic_energy, t.initial_kinetic_energy) << "the bar met the plane";
        EXPECT_LT(std::abs(t.energy_error), 1e-9);
        for (std::size_t i = 0; i < sim.real_count(); ++i) {
            ASSERT_TRUE(std::isfinite(sim.nodes().pressure[i]) && std::isfinite(sim.nodes().velocity[1][i])) << "node " << i;
        }
    }
}

}  // namespace
}  // namespace gpa::io
