// validate() (header: material.hpp): bad parameters are rejected with std::invalid_argument whose
// message names the material and the offending field.

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "material_fixtures.hpp"

namespace gpa::materials {
namespace {

Material full_material() {
    Material m = test::copper();
    m.failure.johnson_cook = JohnsonCookFailure{0.54, 4.89, -3.03, 0.014, 1.12, 1.0, 0.01};
    m.failure.spall_pressure = 1.5e9;
    return m;
}

TEST(Validate, AcceptsTheTestMaterials) {
    EXPECT_NO_THROW(validate(full_material()));
    EXPECT_NO_THROW(validate(test::copper_linear()));
    EXPECT_NO_THROW(validate(test::von_mises_aluminium()));
    Material no_melt = test::copper();
    no_melt.melt_temperature = std::numeric_limits<double>::infinity();
    EXPECT_NO_THROW(validate(no_melt));
    Material poly = test::copper();
    poly.eos = PolynomialEos{1.39e11, 1.36e11, 3.3e10, 2.0};
    poly.strength = ElasticStrength{};
    EXPECT_NO_THROW(validate(poly));
}

TEST(Validate, MessageNamesMaterialAndField) {
    Material m = test::copper();
    m.density = -1.0;
    try {
        validate(m);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_EQ(what.rfind("material \"OFHC copper\": density -1 kg/m^3 must be positive", 0), 0u) << what;
    }
}

struct BadCase {
    const char* field;  // expected in the message
    std::function<void(Material&)> spoil;
};

std::vector<BadCase> bad_cases() {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    auto mg = [](Material& m) -> MieGruneisenEos& { return std::get<MieGruneisenEos>(m.eos); };
    auto jc = [](Material& m) -> JohnsonCookStrength& { return std::get<JohnsonCookStrength>(m.strength); };
    return {
        {"name", [](Material& m) { m.name.clear(); }},
        {"density", [](Material& m) { m.density = 0.0; }},
        {"density", [=](Material& m) { m.density = nan; }},
        {"shear_modulus", [](Material& m) { m.shear_modulus = -1e9; }},
        {"specific_heat", [](Material& m) { m.specific_heat = -383.0; }},
        {"taylor_quinney", [](Material& m) { m.taylor_quinney = 1.2; }},
        {"taylor_quinney", [](Material& m) { m.taylor_quinney = -0.1; }},
        {"room_temperature", [](Material& m) { m.room_temperature = 0.0; }},
        {"melt_temperature", [](Material& m) { m.melt_temperature = 250.0; }},
        {"melt_temperature", [](Material& m) { m.melt_temperature = m.room_temperature; }},
        {"eos.bulk_modulus", [](Material& m) { m.eos = LinearEos{-1e9, false}; }},
        {"eos.k1", [](Material& m) { m.eos = PolynomialEos{0.0, 1e9, 1e9, 2.0}; }},
        {"eos.k2", [=](Material& m) { m.eos = PolynomialEos{1e11, nan, 1e9, 2.0}; }},
        {"eos.gruneisen", [](Material& m) { m.eos = PolynomialEos{1e11, 1e9, 1e9, -2.0}; }},
        {"eos.sound_speed", [=](Material& m) { mg(m).sound_speed = 0.0; }},
        {"eos.slope", [=](Material& m) { mg(m).slope = -1.0; }},
        {"eos.gruneisen", [=](Material& m) { mg(m).gruneisen = -0.5; }},
        {"strength.yield_stress", [](Material& m) { m.strength = VonMisesStrength{-3e8}; }},
        {"strength.a", [=](Material& m) { jc(m).a = -1.0; }},
        {"strength.b", [=](Material& m) { jc(m).b = -1.0; }},
        {"strength.n", [=](Material& m) { jc(m).n = -0.3; }},
        {"strength.n", [=](Material& m) { jc(m).n = 0.0; }},
        {"strength.c", [=](Material& m) { jc(m).c = -0.01; }},
        {"strength.m", [=](Material& m) { jc(m).m = 0.0; }},
        {"strength.reference_strain_rate", [=](Material& m) { jc(m).reference_strain_rate = 0.0; }},
        {"failure.johnson_cook.d3", [=](Material& m) { m.failure.johnson_cook->d3 = nan; }},
        {"failure.johnson_cook.reference_strain_rate",
         [](Material& m) { m.failure.johnson_cook->reference_strain_rate = -1.0; }},
        {"failure.johnson_cook.min_failure_strain", [](Material& m) { m.failure.johnson_cook->min_failure_strain = 0.0; }},
        {"failure.spall_pressure", [](Material& m) { m.failure.spall_pressure = -1e9; }},
    };
}

TEST(Validate, RejectsBadValuesNamingMaterialAndField) {
    for (const BadCase& c : bad_cases()) {
        Material m = full_material();
        m.name = "Test copper";
        c.spoil(m);
        try {
            validate(m);
            ADD_FAILURE() << c.field << ": no exception";
        } catch (const std::invalid_argument& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(fmt::format("material \"{}\"", m.name)), std::string::npos) << what;
            EXPECT_NE(what.find(std::string(c.field) + (c.field == std::string("name") ? "" : " ")), std::string::npos)
                << c.field << ": " << what;
        }
    }
}

}  // namespace
}  // namespace gpa::materials
