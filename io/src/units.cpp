#include "gpa/io/units.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <system_error>

#include <fmt/format.h>

namespace gpa::io {

namespace {

constexpr std::array dimensions{
    Dimension::Dimensionless, Dimension::Length,       Dimension::Time,           Dimension::Velocity,
    Dimension::Density,       Dimension::Pressure,     Dimension::Temperature,    Dimension::SpecificHeat,
    Dimension::SpecificEnergy, Dimension::StrainRate,
};

using D = Dimension;

// The preferred spelling of each unit comes first within its dimension; aliases follow.
constexpr std::array units{
    Unit{"%", D::Dimensionless, -2},

    Unit{"m", D::Length, 0},
    Unit{"cm", D::Length, -2},
    Unit{"mm", D::Length, -3},
    Unit{"um", D::Length, -6},
    Unit{"in", D::Length, 0, 0.0254},

    Unit{"s", D::Time, 0},
    Unit{"ms", D::Time, -3},
    Unit{"us", D::Time, -6},
    Unit{"ns", D::Time, -9},
    Unit{"min", D::Time, 0, 60.0},
    Unit{"h", D::Time, 0, 3600.0},

    Unit{"m/s", D::Velocity, 0},
    Unit{"km/s", D::Velocity, 3},
    Unit{"mm/us", D::Velocity, 3},
    Unit{"cm/us", D::Velocity, 4},
    Unit{"cm/s", D::Velocity, -2},

    Unit{"kg/m^3", D::Density, 0},
    Unit{"g/cc", D::Density, 3},
    Unit{"g/cm^3", D::Density, 3},
    Unit{"kg/m3", D::Density, 0, 1.0, true},
    Unit{"g/cm3", D::Density, 3, 1.0, true},

    Unit{"Pa", D::Pressure, 0},
    Unit{"kPa", D::Pressure, 3},
    Unit{"MPa", D::Pressure, 6},
    Unit{"GPa", D::Pressure, 9},
    Unit{"bar", D::Pressure, 5},
    Unit{"kbar", D::Pressure, 8},
    Unit{"Mbar", D::Pressure, 11},

    Unit{"K", D::Temperature, 0},

    Unit{"J/kg/K", D::SpecificHeat, 0},
    Unit{"J/(kg K)", D::SpecificHeat, 0},
    Unit{"kJ/kg/K", D::SpecificHeat, 3},
    Unit{"kJ/(kg K)", D::SpecificHeat, 3},
    Unit{"J/(kg.K)", D::SpecificHeat, 0, 1.0, true},
    Unit{"kJ/(kg.K)", D::SpecificHeat, 3, 1.0, true},
    Unit{"J/kg.K", D::SpecificHeat, 0, 1.0, true},

    Unit{"J/kg", D::SpecificEnergy, 0},
    Unit{"kJ/kg", D::SpecificEnergy, 3},
    Unit{"MJ/kg", D::SpecificEnergy, 6},

    Unit{"1/s", D::StrainRate, 0},
    Unit{"1/ms", D::StrainRate, 3},
    Unit{"1/us", D::StrainRate, 6},
    Unit{"s^-1", D::StrainRate, 0, 1.0, true},
};

// The form units are compared in: no white space; '*' and the middle dot become '.'; the micro
// sign and the Greek mu become 'u'; superscript three becomes "^3".
std::string canonical(std::string_view unit) {
    std::string out;
    for (std::size_t i = 0; i < unit.size(); ++i) {
        const char c = unit[i];
        if (c == ' ' || c == '\t') continue;
        if (c == '*') {
            out += '.';
            continue;
        }
        const auto next = [&](std::size_t k) { return i + k < unit.size() ? unit[i + k] : '\0'; };
        if (c == '\xC2' && next(1) == '\xB7') {  // middle dot
            out += '.';
            ++i;
        } else if (c == '\xC2' && next(1) == '\xB5') {  // micro sign
            out += 'u';
            ++i;
        } else if (c == '\xCE' && next(1) == '\xBC') {  // Greek small mu
            out += 'u';
            ++i;
        } else if (c == '\xC2' && next(1) == '\xB3') {  // superscript three
            out += "^3";
            ++i;
        } else {
            out += c;
        }
    }
    return out;
}

const Unit* find_unit(std::string_view written) {
    const std::string key = canonical(written);
    for (const Unit& u : units) {
        if (canonical(u.symbol) == key) return &u;
    }
    return nullptr;
}

char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

bool equal_ignoring_case(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (lower(a[i]) != lower(b[i])) return false;
    }
    return true;
}

// A unit of `d` spelt like `written` but for letter case ("MM" for "mm"), if there is one.
const Unit* case_insensitive_match(std::string_view written, Dimension d) {
    const std::string key = canonical(written);
    for (const Unit& u : units) {
        if (u.dimension == d && equal_ignoring_case(canonical(u.symbol), key)) return &u;
    }
    return nullptr;
}

// A number as written: its digits with an optional sign and decimal point, and its exponent.
struct WrittenNumber {
    std::string significand;  // e.g. "-15.2" (no '+', no exponent)
    long exponent = 0;
    std::size_t length = 0;   // characters of the text taken by the number
};

bool is_digit(char c) { return c >= '0' && c <= '9'; }

std::optional<WrittenNumber> scan_number(std::string_view text) {
    WrittenNumber n;
    std::size_t i = 0;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
        if (text[i] == '-') n.significand += '-';
        ++i;
    }
    std::size_t digits = 0;
    while (i < text.size() && is_digit(text[i])) {
        n.significand += text[i++];
        ++digits;
    }
    if (i < text.size() && text[i] == '.') {
        n.significand += text[i++];
        while (i < text.size() && is_digit(text[i])) {
            n.significand += text[i++];
            ++digits;
        }
    }
    if (digits == 0) return std::nullopt;
    // An exponent only when it is complete ("3e" leaves "e" to the unit, which then fails).
    if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
        std::size_t j = i + 1;
        bool negative = false;
        if (j < text.size() && (text[j] == '+' || text[j] == '-')) negative = text[j++] == '-';
        if (j < text.size() && is_digit(text[j])) {
            long e = 0;
            while (j < text.size() && is_digit(text[j])) {
                if (e < 100000) e = e * 10 + (text[j] - '0');  // saturate: far out of range anyway
                ++j;
            }
            n.exponent = negative ? -e : e;
            i = j;
        }
    }
    n.length = i;
    return n;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

std::string article_name(Dimension d) {
    if (d == Dimension::Dimensionless) return "a plain number";
    return fmt::format("a {}", name_of(d));
}

std::string takes(Dimension d) {
    if (d == Dimension::Dimensionless) return "a plain number takes no unit (or %)";
    return fmt::format("{} takes {}", article_name(d), accepted_units(d));
}

struct Split {
    WrittenNumber number;
    std::string_view unit;
};

Split split(std::string_view text) {
    const std::string_view t = trim(text);
    const auto number = scan_number(t);
    if (!number) {
        throw UnitError(fmt::format("\"{}\" is not a number with a unit (write e.g. \"15.2 mm\")", text));
    }
    return {*number, trim(t.substr(number->length))};
}

double to_double(const WrittenNumber& n, const Unit* unit, std::string_view text) {
    const long exponent = n.exponent + (unit ? unit->decimal_exponent : 0);
    const std::string composed = fmt::format("{}e{}", n.significand, exponent);
    double value = 0.0;
    const char* first = composed.data();
    const char* last = composed.data() + composed.size();
    const auto [end, ec] = std::from_chars(first, last, value);
    if (ec == std::errc::result_out_of_range || (ec == std::errc{} && !std::isfinite(value))) {
        throw UnitError(fmt::format("\"{}\" is outside the range of a double", text));
    }
    if (ec != std::errc{} || end != last) {
        throw UnitError(fmt::format("\"{}\" is not a number with a unit (write e.g. \"15.2 mm\")", text));
    }
    if (unit && unit->factor != 1.0) value *= unit->factor;
    return value;
}

}  // namespace

std::span<const Dimension> all_dimensions() { return dimensions; }

std::string_view name_of(Dimension d) {
    switch (d) {
        case Dimension::Dimensionless: return "dimensionless number";
        case Dimension::Length: return "length";
        case Dimension::Time: return "time";
        case Dimension::Velocity: return "velocity";
        case Dimension::Density: return "density";
        case Dimension::Pressure: return "pressure";
        case Dimension::Temperature: return "temperature";
        case Dimension::SpecificHeat: return "specific heat";
        case Dimension::SpecificEnergy: return "specific energy";
        case Dimension::StrainRate: return "strain rate";
    }
    return "?";
}

std::string_view si_unit_of(Dimension d) {
    switch (d) {
        case Dimension::Dimensionless: return "";
        case Dimension::Length: return "m";
        case Dimension::Time: return "s";
        case Dimension::Velocity: return "m/s";
        case Dimension::Density: return "kg/m^3";
        case Dimension::Pressure: return "Pa";
        case Dimension::Temperature: return "K";
        case Dimension::SpecificHeat: return "J/(kg K)";
        case Dimension::SpecificEnergy: return "J/kg";
        case Dimension::StrainRate: return "1/s";
    }
    return "";
}

std::span<const Unit> known_units() { return units; }

std::string accepted_units(Dimension d) {
    std::string list;
    for (const Unit& u : units) {
        if (u.dimension != d || u.alias) continue;
        if (!list.empty()) list += ", ";
        list += u.symbol;
    }
    return list;
}

double parse_quantity(std::string_view text, Dimension expected) {
    const Split s = split(text);
    if (s.unit.empty()) {
        if (expected == Dimension::Dimensionless) return to_double(s.number, nullptr, text);
        throw UnitError(fmt::format("\"{}\" has no unit: write {} as a plain number in {} or as a string with one of {}",
                                    text, article_name(expected), si_unit_of(expected), accepted_units(expected)));
    }
    const Unit* unit = find_unit(s.unit);
    if (!unit) {
        if (const Unit* near = case_insensitive_match(s.unit, expected)) {
            throw UnitError(fmt::format("unknown unit \"{}\" in \"{}\" (units are case-sensitive: did you mean \"{}\"?)",
                                        s.unit, text, near->symbol));
        }
        throw UnitError(fmt::format("unknown unit \"{}\" in \"{}\"; {}", s.unit, text, takes(expected)));
    }
    if (unit->dimension != expected) {
        throw UnitError(fmt::format("\"{}\" is {}, not {}; {}", text, article_name(unit->dimension),
                                    article_name(expected), takes(expected)));
    }
    return to_double(s.number, unit, text);
}

Quantity parse_any_quantity(std::string_view text) {
    const Split s = split(text);
    if (s.unit.empty()) return {to_double(s.number, nullptr, text), Dimension::Dimensionless};
    const Unit* unit = find_unit(s.unit);
    if (!unit) {
        std::string all;
        for (const Dimension d : dimensions) {
            if (d == Dimension::Dimensionless) continue;
            if (!all.empty()) all += "; ";
            all += fmt::format("{}: {}", name_of(d), accepted_units(d));
        }
        throw UnitError(fmt::format("unknown unit \"{}\" in \"{}\" (known units: {}; %)", s.unit, text, all));
    }
    return {to_double(s.number, unit, text), unit->dimension};
}

}  // namespace gpa::io
