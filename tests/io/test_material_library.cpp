// The built-in material library holds the constants of shared/spec/materials.md, with sources,
// and is embedded in the program (it equals materials/data/library.toml).

#include <fstream>
#include <sstream>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
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

TEST(MaterialLibrary, HoldsTheFourSpecMaterialsInOrder) {
    const auto& library = builtin_materials();
    ASSERT_EQ(library.size(), 4u);
    for (std::size_t i = 0; i < library.size(); ++i) EXPECT_EQ(library[i].name, johnson_cook_table[i].name);
    EXPECT_EQ(builtin_material_names(), "OFHC copper, Armco iron, 4340 steel, 2024-T351 aluminium");
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
    for (const auto& mat : builtin_materials()) {
        SCOPED_TRACE(mat.name);
        EXPECT_NE(mat.source.find("Johnson and Cook (1983)"), std::string::npos);
        EXPECT_NE(mat.source.find("Shear modulus"), std::string::npos);
        EXPECT_NE(mat.source.find("NOT CHECKED"), std::string::npos);
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

}  // namespace
}  // namespace gpa::io
