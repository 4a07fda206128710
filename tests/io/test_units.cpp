// Quantities with units: every dimension converts to SI, decimal units without round-off of their
// own, and wrong or unknown units fail with a message that lists what the dimension accepts.

#include <cstdlib>
#include <numbers>
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
    // Also where the letters would read as a compound of another size: a listed unit mistyped.
    EXPECT_NE(unit_error("200 mPa", D::Pressure).find("did you mean \"MPa\""), std::string::npos);
    EXPECT_NE(unit_error("1 mbar", D::Pressure).find("did you mean \"Mbar\""), std::string::npos);
    EXPECT_NE(unit_error("10 Mm", D::Length).find("did you mean \"mm\""), std::string::npos);
    EXPECT_NE(unit_error("1 Ms", D::Time).find("did you mean \"ms\""), std::string::npos);
    EXPECT_NE(unit_error("3 mJ/kg", D::SpecificEnergy).find("did you mean \"MJ/kg\""), std::string::npos);
    EXPECT_THROW(parse_any_quantity("200 mPa"), UnitError);
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

// Angles (body and scene rotations) are a dimension of their own: degrees convert by pi/180 once,
// a plain number is radians, and neither a plain number's key nor a length's takes an angle.
TEST(Units, AnglesAreADimensionOfTheirOwn) {
    const double degree = std::numbers::pi / 180.0;
    EXPECT_EQ(parse_quantity("0.5 rad", D::Angle), 0.5);
    EXPECT_EQ(parse_quantity("30 deg", D::Angle), 30.0 * degree);
    EXPECT_EQ(parse_quantity("30\u00B0", D::Angle), 30.0 * degree);
    EXPECT_EQ(parse_quantity("-45 \u00B0", D::Angle), -45.0 * degree);
    EXPECT_EQ(parse_quantity("90 degrees", D::Angle), 90.0 * degree);
    EXPECT_EQ(parse_quantity("1 degree", D::Angle), degree);
    EXPECT_EQ(parse_quantity("2 radians", D::Angle), 2.0);
    EXPECT_EQ(parse_any_quantity("30 deg").dimension, D::Angle);
    EXPECT_EQ(accepted_units(D::Angle), "rad, deg");
    EXPECT_EQ(si_unit_of(D::Angle), "rad");

    const std::string length = unit_error("30 deg", D::Length);
    EXPECT_NE(length.find("\"30 deg\" is an angle, not a length"), std::string::npos) << length;
    const std::string number = unit_error("30 deg", D::Dimensionless);
    EXPECT_NE(number.find("is an angle, not a plain number"), std::string::npos) << number;
    const std::string percent = unit_error("5 %", D::Angle);
    EXPECT_NE(percent.find("is a plain number, not an angle; an angle takes rad, deg, or a plain number in rad"), std::string::npos)
        << percent;
    const std::string bare = unit_error("30", D::Angle);
    EXPECT_NE(bare.find("has no unit: write an angle as a plain number in rad or as a string with one of rad, deg"), std::string::npos)
        << bare;
    EXPECT_NE(unit_error("30 Deg", D::Angle).find("did you mean \"deg\""), std::string::npos);
    // An angular speed is no quantity of a scene.
    EXPECT_NE(unit_error("30 deg/s", D::Angle).find("which no scene value is"), std::string::npos);
    EXPECT_FALSE(compound_unit_value("deg/s").has_value());
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

// Compound and customary units (issue 25, item 4): LS-DYNA's mm-ms-kg velocities, GN/m^2,
// pound-force and inch units, spelt-out words, powers and products written with spaces.
// Decimal compounds are exact (the prefixes join the exponent); customary ones are within one
// rounding of their defining constants (1 ft = 0.3048 m, 1 lb = 0.45359237 kg, 1 lbf = 4.4482216152605 N,
// all exact by definition): one rounding per factor and power (up to four), hence the relative
// 1e-15 (about nine roundings of 1.1e-16) on those.
TEST(Units, CompoundAndCustomaryUnits) {
    const Case exact[] = {
        {"1 mm/ms", D::Velocity, 1.0},
        {"190 mm/ms", D::Velocity, 190.0},
        {"0.5 m s^-1", D::Velocity, 0.5},
        {"0.5 m*s^-1", D::Velocity, 0.5},
        {"2 GN/m^2", D::Pressure, 2e9},
        {"2 GN/m²", D::Pressure, 2e9},
        {"3 N/mm^2", D::Pressure, 3e6},
        {"3 kN/mm2", D::Pressure, 3e9},
        {"7.85 g/mm^3", D::Density, 7.85e6},
        {"7.85 mg/mm^3", D::Density, 7850.0},
        {"40 microseconds", D::Time, 40e-6},
        {"1 microsecond", D::Time, 1e-6},
        {"2 milliseconds", D::Time, 0.002},
        {"5 minutes", D::Time, 300.0},
        {"1 hour", D::Time, 3600.0},
        {"25 millimetres", D::Length, 0.025},
        {"25 millimeters", D::Length, 0.025},
        {"1 ft", D::Length, 0.3048},
        {"1 foot", D::Length, 0.3048},
        {"1 inch", D::Length, 0.0254},
        {"1 ft/s", D::Velocity, 0.3048},
        {"452 J kg^-1 K^-1", D::SpecificHeat, 452.0},
        {"452 J/kg.K", D::SpecificHeat, 452.0},
        {"452 m^2/s^2/K", D::SpecificHeat, 452.0},
        {"2 kJ/g", D::SpecificEnergy, 2e6},
        {"2 ms^-1", D::StrainRate, 2000.0},
        {"0.5 %", D::Dimensionless, 0.005},
        {"0.5 mm/m", D::Dimensionless, 0.0005},
    };
    for (const Case& c : exact) {
        EXPECT_EQ(parse_quantity(c.text, c.dimension), c.si) << c.text;
    }
    const double lbf = 4.4482216152605, in = 0.0254;
    const Case customary[] = {
        {"1 psi", D::Pressure, lbf / (in * in)},
        {"1 lbf/in^2", D::Pressure, lbf / (in * in)},
        {"1 ksi", D::Pressure, 1000.0 * lbf / (in * in)},
        {"1 lb/in^3", D::Density, 0.45359237 / (in * in * in)},
        {"1 lb/ft^3", D::Density, 0.45359237 / (0.3048 * 0.3048 * 0.3048)},
        {"1000 ft/s", D::Velocity, 304.8},
        {"60 ksi", D::Pressure, 60000.0 * lbf / (in * in)},
        {"0.284 lb/in^3", D::Density, 0.284 * 0.45359237 / (in * in * in)},
        {"3 feet", D::Length, 0.9144},
    };
    for (const Case& c : customary) {
        EXPECT_NEAR(parse_quantity(c.text, c.dimension), c.si, 1e-15 * c.si) << c.text;
    }
    EXPECT_NEAR(parse_quantity("1 ksi", D::Pressure), 6.894757293168361e6, 1e-15 * 6.894757293168361e6)
        << "the ksi of the handbooks";
    // A customary factor that takes a number below the smallest normal double is out of range, as
    // the decimal units are (not 0 or a subnormal).
    for (const char* text : {"3e-324 ft", "5e-324 in", "1e-320 in"}) {
        EXPECT_THROW(parse_quantity(text, D::Length), UnitError) << text;
    }
    EXPECT_EQ(parse_quantity("0 ft", D::Length), 0.0);
}

// The unit table: every listed unit that is a compound of base units reads the same as that
// compound, value and dimension, so the table and the compound reader cannot drift apart.
TEST(Units, EveryListedUnitReadsTheSameAsItsCompound) {
    std::size_t compared = 0;
    for (const Unit& u : known_units()) {
        if (u.symbol == "%") continue;
        const auto compound = compound_unit_value(u.symbol);
        ASSERT_TRUE(compound.has_value()) << u.symbol << " is no compound of the base units";
        const double listed = parse_quantity(fmt::format("1 {}", u.symbol), u.dimension);
        EXPECT_EQ(compound->dimension, u.dimension) << u.symbol;
        EXPECT_NEAR(compound->value, listed, 1e-15 * listed) << u.symbol;  // customary: as above
        if (u.factor == 1.0) {
            EXPECT_EQ(compound->value, listed) << u.symbol << ": decimal units are exact both ways";
        }
        ++compared;
    }
    EXPECT_GT(compared, 40u);
}

TEST(Units, CompoundsOfNoQuantityAndMalformedCompoundsAreRefused) {
    const std::string acceleration = unit_error("9.8 m/s^2", D::Velocity);
    EXPECT_NE(acceleration.find("which no scene value is"), std::string::npos) << acceleration;
    EXPECT_NE(acceleration.find("m s^-2"), std::string::npos) << acceleration;
    EXPECT_NE(acceleration.find("mm/ms"), std::string::npos) << acceleration << " (the compound hint)";
    EXPECT_NE(acceleration.find("plain number in m/s"), std::string::npos) << acceleration;
    for (const char* text : {"3 mm/", "3 /mm", "3 mm//s", "3 mm^", "3 mm^x", "3 mm^0", "3 kg/(m s", "3 (kg)/m",
                             "3 kg/(m)(s)", "3 kK", "3 kin", "3 mft", "3 m..s", "3 1/", "3 1.m", "3 mm^99"}) {
        EXPECT_THROW(parse_quantity(text, D::Length), UnitError) << text;
        EXPECT_THROW(parse_any_quantity(text), UnitError) << text;
    }
    // A space between two names multiplies: "m s" is no millisecond.
    EXPECT_NE(unit_error("3 m s", D::Time).find("which no scene value is"), std::string::npos);
    EXPECT_EQ(parse_quantity("3 ms", D::Time), 0.003);
    EXPECT_FALSE(compound_unit_value("m/s^2").has_value());
    // Customary factors that overflow the product, cancelling in dimension: refused, not NaN.
    std::string many_feet = "ft";
    for (int k = 0; k < 700; ++k) many_feet += ".ft";
    const std::string overflow = many_feet + "/" + many_feet;
    EXPECT_FALSE(compound_unit_value(overflow).has_value());
    EXPECT_THROW(parse_quantity("1 " + overflow, D::Dimensionless), UnitError);
    EXPECT_THROW(parse_quantity("1e305 ksi", D::Pressure), UnitError);  // 1e308 as written, infinite in Pa
    EXPECT_FALSE(compound_unit_value("furlong").has_value());
    EXPECT_FALSE(compound_unit_value("Gm^9.Gm^9/nm^9/nm^9").has_value()) << "one of it is beyond a double: none, no throw";
    EXPECT_EQ(compound_unit_value("mm/ms")->dimension, D::Velocity);
    // A compound of another dimension still says which it is.
    EXPECT_NE(unit_error("3 lbf/in^2", D::Length).find("is a pressure, not a length"), std::string::npos);
}

}  // namespace
}  // namespace gpa::io
