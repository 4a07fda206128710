#pragma once
// Quantities with units, as scene files write them: a plain number is SI; a string is a number
// followed by a unit, "15.2 mm", "-305 m/s", "7.89 g/cc", "175 MPa". Every scene key has one
// dimension, and a unit of another dimension is an error, never a silent conversion.
//
// Decimal units convert without round-off of their own: the power of ten of the unit is added
// to the exponent of the number as written and the result is rounded once, so "15.2 mm" gives
// exactly the double nearest to 0.0152 (the same as writing 0.0152).

#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>

namespace gpa::io {

enum class Dimension {
    Dimensionless,   // plain numbers; "%" allowed
    Length,          // m
    Time,            // s
    Velocity,        // m/s
    Density,         // kg/m^3
    Pressure,        // Pa: pressures, stresses, moduli
    Temperature,     // K
    SpecificHeat,    // J/(kg K)
    SpecificEnergy,  // J/kg
    StrainRate,      // 1/s
    Angle,           // rad: a plane angle (body and scene rotations)
};

// Every dimension, in the order of the enum (for documentation and tests).
std::span<const Dimension> all_dimensions();

// "length", "time", "velocity", ... as used in messages.
std::string_view name_of(Dimension d);

// The SI unit a plain number is read in: "m", "s", "m/s", "kg/m^3", "Pa", "K", "J/(kg K)",
// "J/kg", "1/s", "rad"; empty for dimensionless numbers.
std::string_view si_unit_of(Dimension d);

struct Unit {
    std::string_view symbol;  // as written in a file, e.g. "mm", "g/cc", "J/(kg K)"
    Dimension dimension;
    int decimal_exponent;     // SI value = number * 10^decimal_exponent * factor
    double factor = 1.0;      // 1 for every decimal unit (all but the inch)
    bool alias = false;       // another spelling of a listed unit (not shown in messages)
};

// The units listed in messages and docs/scene-format.md. A symbol belongs to one dimension only.
// Spellings are matched after removing spaces and reading '*' and the middle dot as '.', 'µ' and
// 'μ' as 'u', '²' and '³' as '^2' and '^3'. A unit not listed is read as a compound of base units
// (compound_unit_value).
std::span<const Unit> known_units();

// The accepted spellings of one dimension for messages, e.g. "m, cm, mm, um, in".
std::string accepted_units(Dimension d);

// A unit string that cannot be read: the message says what was wrong without any file or key
// context (the scene reader adds that), and names the units the dimension accepts.
class UnitError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

// Reads "15.2 mm" as a length in m (3.0 mm -> 0.003). The number may carry a sign and an
// exponent ("1.5e-3 m"); spaces between number and unit are optional. A string without a unit
// is accepted only for Dimensionless. Throws UnitError for an unknown unit, a unit of another
// dimension, a missing unit, text that is not a number, or a value outside the range of double.
double parse_quantity(std::string_view text, Dimension expected);

struct Quantity {
    double value = 0.0;  // SI
    Dimension dimension = Dimension::Dimensionless;
};

// Reads a quantity of any dimension, taken from its unit; a bare number is dimensionless.
Quantity parse_any_quantity(std::string_view text);

// One unit read as a compound: products and quotients of the base units m, g, s, Pa, N, J, bar
// (each with an optional SI prefix n, u, m, c, k, M, G), K, cc, min, h, in, ft, lb, lbf, psi, ksi,
// rad, deg and the degree sign (and spelt-out words such as "microseconds", "feet" or "degrees"),
// each with an optional integer power
// ("m^3", "m3", "s^-1"); a space, '.', '*' or the middle dot multiplies, and everything after the
// first '/' divides ("J/kg.K" and "J/(kg K)" are both J/(kg K); parentheses may enclose the whole
// denominator only), with "1/s" for a numerator of one. Returns the SI value of one such unit and
// its dimension; nullopt when the text is no such compound or its dimension is none of
// Dimension's (an acceleration, "m/s^2"). The reader falls back on it for units known_units does
// not list, so "mm/ms", "GN/m^2" and "lbf/in^2" are read, and every listed unit that is a compound
// reads the same both ways (tests/io/test_units.cpp).
std::optional<Quantity> compound_unit_value(std::string_view unit);

}  // namespace gpa::io
