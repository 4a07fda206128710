#pragma once
// Quantities with units, as scene files write them: a plain number is SI; a string is a number
// followed by a unit, "15.2 mm", "-305 m/s", "7.89 g/cc", "175 MPa". Every scene key has one
// dimension, and a unit of another dimension is an error, never a silent conversion.
//
// Decimal units convert without round-off of their own: the power of ten of the unit is added
// to the exponent of the number as written and the result is rounded once, so "15.2 mm" gives
// exactly the double nearest to 0.0152 (the same as writing 0.0152).

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
};

// Every dimension, in the order of the enum (for documentation and tests).
std::span<const Dimension> all_dimensions();

// "length", "time", "velocity", ... as used in messages.
std::string_view name_of(Dimension d);

// The SI unit a plain number is read in: "m", "s", "m/s", "kg/m^3", "Pa", "K", "J/(kg K)",
// "J/kg", "1/s"; empty for dimensionless numbers.
std::string_view si_unit_of(Dimension d);

struct Unit {
    std::string_view symbol;  // as written in a file, e.g. "mm", "g/cc", "J/(kg K)"
    Dimension dimension;
    int decimal_exponent;     // SI value = number * 10^decimal_exponent * factor
    double factor = 1.0;      // 1 for every decimal unit (all but the inch)
    bool alias = false;       // another spelling of a listed unit (not shown in messages)
};

// Every unit a scene may use. A symbol belongs to one dimension only. Spellings are matched
// after removing spaces and reading '*' and the middle dot as '.', 'µ' and 'μ' as 'u', '³' as '^3'.
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

}  // namespace gpa::io
