// Quantities with units: every dimension converts to SI, decimal units without round-off of their
// own, and wrong or unknown units fail with a message that lists what the dimension accepts.

#include <cstdlib>
#include <set>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/io/units.hpp"

namespace gpa::io {
namespace {

using D = Dimension;

std::string unit_error(std::string_view text, Dimension d) {
    try {
        parse_quantity(text, d);
    } catch (const UnitError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no UnitError for \"" << text << "\"";
    return {};
}

struct Case {
    const char* text;
    Dimension dimension;
    double si;
};

TEST(Units, EveryDimensionConvertsToSi) {
    const Case cases[] = {
        {"0.5", D::Dimensionless, 0.5},
        {"1 %", D::Dimensionless, 0.01},
        {"15.2 mm", D::Length, 0.0152},
        {"15.2mm", D::Length, 0.0152},
        {"2.54 cm", D::Length, 0.0254},
        {"1 in", D::Length, 0.0254},
        {"3 um", D::Length, 3e-6},
        {"3 µm", D::Length, 3e-6},
        {"1.5e-3 m", D::Length, 0.0015},
        {"+3 mm", D::Length, 0.003},
        {".5 mm", D::Length, 0.0005},
        {"40 us", D::Time, 40e-6},
        {"40 μs", D::Time, 40e-6},
        {"2 ms", D::Time, 0.002},
        {"150 ns", D::Time, 150e-9},
        {"1 s", D::Time, 1.0},
        {"305 m/s", D::Velocity, 305.0},
        {"-305 m/s", D::Velocity, -305.0},
        {"4 km/s", D::Velocity, 4000.0},
        {"0.19 mm/us", D::Velocity, 190.0},
        {"0.019 cm/us", D::Velocity, 190.0},
        {"19000 cm/s", D::Velocity, 190.0},
        {"7.89 g/cc", D::Density, 7890.0},
        {"7.89 g/cm^3", D::Density, 7890.0},
        {"7.89 g/cm³", D::Density, 7890.0},
        {"7890 kg/m^3", D::Density, 7890.0},
        {"7890 kg/m3", D::Density, 7890.0},
        {"175 MPa", D::Pressure, 175e6},
        {"165 GPa", D::Pressure, 165e9},
        {"101.325 kPa", D::Pressure, 101325.0},
        {"1.5 Mbar", D::Pressure, 1.5e11},
        {"10 kbar", D::Pressure, 1e9},
        {"1 bar", D::Pressure, 1e5},
        {"3 Pa", D::Pressure, 3.0},
        {"294 K", D::Temperature, 294.0},
        {"452 J/kg/K", D::SpecificHeat, 452.0},
        {"452 J/(kg K)", D::SpecificHeat, 452.0},
        {"452 J/(kg*K)", D::SpecificHeat, 452.0},
        {"0.452 kJ/kg/K", D::SpecificHeat, 452.0},
        {"2 J/kg", D::SpecificEnergy, 2.0},
        {"2 kJ/kg", D::SpecificEnergy, 2000.0},
        {"2 MJ/kg", D::SpecificEnergy, 2e6},
        {"1 1/s", D::StrainRate, 1.0},
        {"1e3 s^-1", D::StrainRate, 1000.0},
        {"2 1/ms", D::StrainRate, 2000.0},
        {"2 1/us", D::StrainRate, 2e6},
    };
    for (const Case& c : cases) {
        EXPECT_EQ(parse_quantity(c.text, c.dimension), c.si) << c.text;
    }
}

// "x mm" is exactly the double nearest to x / 1000, as if 0.00x had been written: the power of
// ten joins the exponent of the number before a single rounding.
TEST(Units, DecimalUnitsAreRoundOffExact) {
    for (int i = 0; i < 2000; ++i) {
        const std::string digits = fmt::format("{}.{:03d}", (i * 7919) % 1000, (i * 104729) % 1000);
        EXPECT_EQ(parse_quantity(digits + " mm", D::Length), std::strtod((digits + "e-3").c_str(), nullptr)) << digits;
        EXPECT_EQ(parse_quantity(digits + " us", D::Time), std::strtod((digits + "e-6").c_str(), nullptr)) << digits;
        EXPECT_EQ(parse_quantity(digits + " GPa", D::Pressure), std::strtod((digits + "e9").c_str(), nullptr)) << digits;
        EXPECT_EQ(parse_quantity(digits + " g/cc", D::Density), std::strtod((digits + "e3").c_str(), nullptr)) << digits;
    }
    EXPECT_EQ(parse_quantity("15.2 mm", D::Length), 0.0152);
    EXPECT_EQ(parse_quantity("1.52e1 mm", D::Length), 0.0152);
    EXPECT_EQ(parse_quantity("0.1 um", D::Length), 1e-7);
}

TEST(Units, WrongDimensionNamesBothAndListsAcceptedUnits) {
    const std::string m = unit_error("3 m/s", D::Length);
    EXPECT_NE(m.find("velocity"), std::string::npos) << m;
    EXPECT_NE(m.find("not a length"), std::string::npos) << m;
    EXPECT_NE(m.find("m, cm, mm, um, in"), std::string::npos) << m;
    EXPECT_NE(unit_error("3 GPa", D::Density).find("kg/m^3, g/cc, g/cm^3"), std::string::npos);
    EXPECT_NE(unit_error("3 mm", D::Dimensionless).find("plain number"), std::string::npos);
    EXPECT_NE(unit_error("3 K", D::Time).find("s, ms, us, ns"), std::string::npos);
}

TEST(Units, UnknownUnitListsAcceptedUnits) {
    const std::string m = unit_error("3 furlong", D::Length);
    EXPECT_NE(m.find("unknown unit \"furlong\""), std::string::npos) << m;
    EXPECT_NE(m.find("m, cm, mm, um, in"), std::string::npos) << m;
    EXPECT_NE(unit_error("20 C", D::Temperature).find("takes K"), std::string::npos);
}

TEST(Units, LetterCaseMattersAndIsHinted) {
    const std::string m = unit_error("3 MM", D::Length);
    EXPECT_NE(m.find("did you mean \"mm\""), std::string::npos) << m;
    EXPECT_NE(unit_error("3 mpa", D::Pressure).find("did you mean \"MPa\""), std::string::npos);
}

TEST(Units, MissingUnitIsAnErrorExceptForPlainNumbers) {
    const std::string m = unit_error("15.2", D::Length);
    EXPECT_NE(m.find("no unit"), std::string::npos) << m;
    EXPECT_EQ(parse_quantity("15.2", D::Dimensionless), 15.2);
}

TEST(Units, TextThatIsNotANumberFails) {
    for (const char* text : {"", "   ", "mm", "abc mm", "nan mm", "inf m", "- 3 mm", "3..2 mm", "1e400 m", "10001/s"}) {
        EXPECT_THROW(parse_quantity(text, D::Length), UnitError) << text;
    }
    EXPECT_NE(unit_error("1e400 m", D::Length).find("range"), std::string::npos);
    EXPECT_THROW(parse_quantity("10001/s", D::StrainRate), UnitError);  // "/s" is not a unit: write "1000 1/s"
}

TEST(Units, AnyDimensionComesFromTheUnit) {
    const Quantity length = parse_any_quantity("16.21 mm");
    EXPECT_EQ(length.dimension, D::Length);
    EXPECT_EQ(length.value, 0.01621);
    const Quantity plain = parse_any_quantity("0.42");
    EXPECT_EQ(plain.dimension, D::Dimensionless);
    EXPECT_EQ(plain.value, 0.42);
    EXPECT_EQ(parse_any_quantity("40 us").dimension, D::Time);
    EXPECT_EQ(parse_any_quantity("1 Mbar").value, 1e11);
    EXPECT_THROW(parse_any_quantity("3 parsec"), UnitError);
}

TEST(Units, EverySpellingBelongsToOneDimension) {
    std::set<std::string> seen;
    for (const Unit& u : known_units()) {
        EXPECT_TRUE(seen.insert(std::string(u.symbol)).second) << u.symbol;
        // Each unit reads back as its own dimension.
        EXPECT_EQ(parse_any_quantity(fmt::format("1 {}", u.symbol)).dimension, u.dimension) << u.symbol;
    }
    for (const Dimension d : all_dimensions()) {
        EXPECT_FALSE(accepted_units(d).empty()) << name_of(d);
    }
}

}  // namespace
}  // namespace gpa::io
