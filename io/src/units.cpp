#include "gpa/io/units.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <system_error>

#include <fmt/format.h>

namespace gpa::io {

namespace {

constexpr std::array dimensions{
    Dimension::Dimensionless, Dimension::Length,       Dimension::Time,           Dimension::Velocity,
    Dimension::Density,       Dimension::Pressure,     Dimension::Temperature,    Dimension::SpecificHeat,
    Dimension::SpecificEnergy, Dimension::StrainRate,   Dimension::Angle,
};

using D = Dimension;

// The pound-force per square inch in Pa: 1 lbf = 4.4482216152605 N (0.45359237 kg times standard
// gravity 9.80665 m/s^2, both exact by definition), over (0.0254 m)^2.
constexpr double pound_force = 4.4482216152605;
constexpr double psi = pound_force / (0.0254 * 0.0254);
// The degree of arc in radians.
constexpr double degree = std::numbers::pi / 180.0;

// The preferred spelling of each unit comes first within its dimension; aliases follow.
constexpr std::array units{
    Unit{"%", D::Dimensionless, -2},

    Unit{"m", D::Length, 0},
    Unit{"cm", D::Length, -2},
    Unit{"mm", D::Length, -3},
    Unit{"um", D::Length, -6},
    Unit{"in", D::Length, 0, 0.0254},
    Unit{"ft", D::Length, 0, 0.3048},

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
    Unit{"mm/ms", D::Velocity, 0},
    Unit{"ft/s", D::Velocity, 0, 0.3048},

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
    Unit{"N/mm^2", D::Pressure, 6},
    Unit{"GN/m^2", D::Pressure, 9},
    Unit{"psi", D::Pressure, 0, psi},
    Unit{"ksi", D::Pressure, 3, psi},

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

    Unit{"rad", D::Angle, 0},
    Unit{"deg", D::Angle, 0, degree},
    Unit{"\u00B0", D::Angle, 0, degree, true},  // the degree sign
};

// The form units are compared in: '*' and the middle dot become '.', and so does white space
// between two names ("kg K", "m s^-1": a product); other white space goes ("kg / m^3"); the micro
// sign and the Greek mu become 'u'; superscripts two and three become "^2" and "^3".
std::string canonical(std::string_view unit) {
    std::string out;
    bool space = false;  // white space since the last character kept
    const auto separator = [](char c) { return c == '/' || c == '.' || c == '(' || c == ')' || c == '^'; };
    for (std::size_t i = 0; i < unit.size(); ++i) {
        const char c = unit[i];
        if (c == ' ' || c == '\t') {
            space = true;
            continue;
        }
        const auto next = [&](std::size_t k) { return i + k < unit.size() ? unit[i + k] : '\0'; };
        std::string_view piece = unit.substr(i, 1);
        if (c == '*') {
            piece = ".";
        } else if (c == '\xC2' && next(1) == '\xB7') {  // middle dot
            piece = ".";
            ++i;
        } else if ((c == '\xC2' && next(1) == '\xB5') || (c == '\xCE' && next(1) == '\xBC')) {  // micro, mu
            piece = "u";
            ++i;
        } else if (c == '\xC2' && next(1) == '\xB3') {  // superscript three
            piece = "^3";
            ++i;
        } else if (c == '\xC2' && next(1) == '\xB2') {  // superscript two
            piece = "^2";
            ++i;
        }
        if (space && !out.empty() && !separator(out.back()) && !separator(piece.front())) out += '.';
        space = false;
        out += piece;
    }
    return out;
}

bool is_digit(char c) { return c >= '0' && c <= '9'; }

// Compound units (mm/ms, GN/m^2, lbf/in^2, kg/(m s)...): products and quotients of the base units
// below, each with an optional SI prefix where the base takes one and an optional integer power.
// Everything after the first '/' is in the denominator ("J/kg.K" and "J/(kg K)" are J/(kg K), as
// engineers write them; "J/kg/K" too). The dimension follows from the exponents of length, mass,
// time and temperature; decimal prefixes and units join the number's exponent (no round-off of
// their own, as for the listed units), the customary ones multiply once.
// The plane angle counts as a base dimension of its own (SI calls it a number, m/m): so that an angle
// is never read where a plain number is meant, nor a percentage where an angle is.
struct Exponents {
    int length = 0, mass = 0, time = 0, temperature = 0, angle = 0;
    bool operator==(const Exponents&) const = default;
};

struct Base {
    std::string_view symbol;
    Exponents exponents;
    int decimal_exponent = 0;
    double factor = 1.0;
    bool prefixed = false;  // takes an SI prefix (mm, kg, MPa, kbar)
    bool plural = false;    // a word that may also end in s (seconds, metres)
};

constexpr Exponents length_e{1, 0, 0, 0}, mass_e{0, 1, 0, 0}, time_e{0, 0, 1, 0}, temperature_e{0, 0, 0, 1};
constexpr Exponents angle_e{0, 0, 0, 0, 1};
constexpr Exponents pressure_e{-1, 1, -2, 0}, force_e{1, 1, -2, 0}, energy_e{2, 1, -2, 0};

constexpr std::array bases{
    Base{"m", length_e, 0, 1.0, true},
    Base{"g", mass_e, -3, 1.0, true},
    Base{"s", time_e, 0, 1.0, true},
    Base{"K", temperature_e},
    Base{"Pa", pressure_e, 0, 1.0, true},
    Base{"N", force_e, 0, 1.0, true},
    Base{"J", energy_e, 0, 1.0, true},
    Base{"bar", pressure_e, 5, 1.0, true},
    Base{"cc", {3, 0, 0, 0}, -6},
    Base{"min", time_e, 0, 60.0},
    Base{"h", time_e, 0, 3600.0},
    Base{"in", length_e, 0, 0.0254},
    Base{"ft", length_e, 0, 0.3048},
    Base{"lb", mass_e, 0, 0.45359237},
    Base{"lbf", force_e, 0, pound_force},
    Base{"psi", pressure_e, 0, psi},
    Base{"ksi", pressure_e, 3, psi},
    Base{"rad", angle_e},
    Base{"deg", angle_e, 0, degree},
    Base{"\u00B0", angle_e, 0, degree},
    // Words, for those who spell units out (each also with a plural s: base_unit).
    Base{"second", time_e, 0, 1.0, false, true},
    Base{"millisecond", time_e, -3, 1.0, false, true},
    Base{"microsecond", time_e, -6, 1.0, false, true},
    Base{"nanosecond", time_e, -9, 1.0, false, true},
    Base{"minute", time_e, 0, 60.0, false, true},
    Base{"hour", time_e, 0, 3600.0, false, true},
    Base{"metre", length_e, 0, 1.0, false, true},
    Base{"meter", length_e, 0, 1.0, false, true},
    Base{"millimetre", length_e, -3, 1.0, false, true},
    Base{"millimeter", length_e, -3, 1.0, false, true},
    Base{"inch", length_e, 0, 0.0254},
    Base{"inches", length_e, 0, 0.0254},
    Base{"foot", length_e, 0, 0.3048},
    Base{"feet", length_e, 0, 0.3048},
    Base{"radian", angle_e, 0, 1.0, false, true},
    Base{"degree", angle_e, 0, degree, false, true},
};

struct Prefix {
    char symbol;
    int decimal_exponent;
};
constexpr std::array prefixes{Prefix{'n', -9}, Prefix{'u', -6}, Prefix{'m', -3}, Prefix{'c', -2},
                              Prefix{'k', 3},  Prefix{'M', 6},  Prefix{'G', 9}};

// What a unit string converts by: SI value = number * 10^decimal_exponent * factor.
struct Conversion {
    Exponents exponents;
    int decimal_exponent = 0;
    double factor = 1.0;
};

constexpr Exponents exponents_of(Dimension d) {
    switch (d) {
        case D::Dimensionless: return {};
        case D::Length: return length_e;
        case D::Time: return time_e;
        case D::Velocity: return {1, 0, -1, 0};
        case D::Density: return {-3, 1, 0, 0};
        case D::Pressure: return pressure_e;
        case D::Temperature: return temperature_e;
        case D::SpecificHeat: return {2, 0, -2, -1};
        case D::SpecificEnergy: return {2, 0, -2, 0};
        case D::StrainRate: return {0, 0, -1, 0};
        case D::Angle: return angle_e;
    }
    return {};
}

std::optional<Dimension> dimension_of(const Exponents& e) {
    for (const Dimension d : dimensions) {
        if (exponents_of(d) == e) return d;
    }
    return std::nullopt;
}

std::string describe(const Exponents& e) {
    std::string out;
    const auto part = [&](std::string_view symbol, int power) {
        if (power == 0) return;
        if (!out.empty()) out += ' ';
        out += symbol;
        if (power != 1) out += fmt::format("^{}", power);
    };
    part("m", e.length);
    part("kg", e.mass);
    part("s", e.time);
    part("K", e.temperature);
    part("rad", e.angle);
    return out.empty() ? std::string("1") : out;
}

std::optional<Conversion> base_unit(std::string_view word) {
    for (const Base& b : bases) {
        if (b.symbol == word || (b.plural && word.size() == b.symbol.size() + 1 && word.back() == 's' &&
                                 word.substr(0, b.symbol.size()) == b.symbol)) {
            return Conversion{b.exponents, b.decimal_exponent, b.factor};
        }
    }
    if (word.size() < 2) return std::nullopt;
    for (const Prefix& p : prefixes) {
        if (word.front() != p.symbol) continue;
        for (const Base& b : bases) {
            if (b.prefixed && b.symbol == word.substr(1)) {
                return Conversion{b.exponents, b.decimal_exponent + p.decimal_exponent, b.factor};
            }
        }
    }
    return std::nullopt;
}

// One factor of a compound unit: a base unit with an optional power ("mm^3", "m3", "s^-1").
std::optional<Conversion> unit_factor(std::string_view term) {
    std::string_view word = term;
    int power = 1;
    const auto read_power = [&](std::string_view digits) {
        int value = 0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        return ec == std::errc{} && end == digits.data() + digits.size() && value != 0 && value >= -9 && value <= 9
                   ? std::optional<int>(value)
                   : std::nullopt;
    };
    if (const auto caret = term.find('^'); caret != std::string_view::npos) {
        const auto p = read_power(term.substr(caret + 1));
        if (!p) return std::nullopt;
        word = term.substr(0, caret);
        power = *p;
    } else {
        std::size_t k = term.size();
        while (k > 0 && is_digit(term[k - 1])) --k;
        if (k > 0 && k < term.size()) {
            const auto p = read_power(term.substr(k));
            if (!p) return std::nullopt;
            word = term.substr(0, k);
            power = *p;
        }
    }
    auto c = base_unit(word);
    if (!c) return std::nullopt;
    Conversion out;
    out.exponents = {c->exponents.length * power, c->exponents.mass * power, c->exponents.time * power,
                     c->exponents.temperature * power, c->exponents.angle * power};
    out.decimal_exponent = c->decimal_exponent * power;
    for (int k = 0; k < std::abs(power); ++k) out.factor = power > 0 ? out.factor * c->factor : out.factor / c->factor;
    return out;
}

std::optional<Conversion> compound_unit(std::string_view written) {
    std::string text = canonical(written);
    // Parentheses only around the whole denominator: "J/(kg K)".
    if (const auto open = text.find('('); open != std::string::npos) {
        if (open == 0 || text[open - 1] != '/' || text.back() != ')' || text.find('(', open + 1) != std::string::npos ||
            text.find(')') != text.size() - 1) {
            return std::nullopt;
        }
        text = text.substr(0, open) + text.substr(open + 1, text.size() - open - 2);
    } else if (text.find(')') != std::string::npos) {
        return std::nullopt;
    }
    Conversion total;
    double divisor = 1.0;  // the denominator's customary factors, divided once at the end
    bool denominator = false;
    std::size_t start = 0;
    for (std::size_t k = 0; k <= text.size(); ++k) {
        if (k < text.size() && text[k] != '/' && text[k] != '.') continue;
        const std::string_view term = std::string_view(text).substr(start, k - start);
        if (term.empty()) return std::nullopt;
        if (term == "1" && start == 0 && k < text.size() && text[k] == '/') {
            // "1/s": a numerator of one
        } else {
            const auto f = unit_factor(term);
            if (!f) return std::nullopt;
            const int sign = denominator ? -1 : 1;
            total.exponents.length += sign * f->exponents.length;
            total.exponents.mass += sign * f->exponents.mass;
            total.exponents.time += sign * f->exponents.time;
            total.exponents.temperature += sign * f->exponents.temperature;
            total.exponents.angle += sign * f->exponents.angle;
            total.decimal_exponent += sign * f->decimal_exponent;
            (denominator ? divisor : total.factor) *= f->factor;
        }
        if (k < text.size() && text[k] == '/') denominator = true;
        start = k + 1;
    }
    if (divisor != 1.0) total.factor /= divisor;
    // Hundreds of customary factors overflow or underflow the product: no unit anyone writes.
    if (!std::isfinite(total.factor) || !(total.factor > 0.0)) return std::nullopt;
    return total;
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

// A listed unit spelt like `written` but for letter case ("MM" for "mm"), if there is one: of
// dimension d when there is such, else of any dimension (d nullopt: any).
const Unit* case_insensitive_match(std::string_view written, std::optional<Dimension> d) {
    const std::string key = canonical(written);
    const Unit* other = nullptr;
    for (const Unit& u : units) {
        if (!equal_ignoring_case(canonical(u.symbol), key)) continue;
        if (!d || u.dimension == *d) return &u;
        if (!other) other = &u;
    }
    return other;
}

// A number as written: its digits with an optional sign and decimal point, and its exponent.
struct WrittenNumber {
    std::string significand;  // e.g. "-15.2" (no '+', no exponent)
    long exponent = 0;
    std::size_t length = 0;   // characters of the text taken by the number
};

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

constexpr std::string_view compound_hint =
    ", or a compound of m, g, s, Pa, N, J, bar (with the prefixes n, u, m, c, k, M, G), K, cc, min, h, in, ft, "
    "lb, lbf, psi, ksi and powers (\"mm/ms\", \"GN/m^2\", \"lbf/in^2\")";
// Angles take their listed units and the words degree(s) and radian(s).
constexpr std::string_view angle_hint = " (also the words degrees and radians)";

std::string article_name(Dimension d) {
    if (d == Dimension::Dimensionless) return "a plain number";
    return fmt::format("{} {}", d == Dimension::Angle ? "an" : "a", name_of(d));
}

std::string takes(Dimension d) {
    if (d == Dimension::Dimensionless) return "a plain number takes no unit (or %)";
    std::string out = fmt::format("{} takes {}, or a plain number in {}", article_name(d), accepted_units(d), si_unit_of(d));
    if (d == Dimension::Angle) {
        out += angle_hint;
    } else if (d != Dimension::Temperature) {
        out += compound_hint;
    }
    return out;
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

double to_double(const WrittenNumber& n, const Conversion* unit, std::string_view text) {
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
    if (unit && unit->factor != 1.0) {
        const double written = value;
        value *= unit->factor;
        // Infinite, or a number that is not zero become zero or subnormal (as the decimal units refuse it).
        if (!std::isfinite(value) || (written != 0.0 && !std::isnormal(value))) {
            throw UnitError(fmt::format("\"{}\" is outside the range of a double", text));
        }
    }
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
        case Dimension::Angle: return "angle";
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
        case Dimension::Angle: return "rad";
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

namespace {

Conversion conversion_of(const Unit& u) { return {exponents_of(u.dimension), u.decimal_exponent, u.factor}; }

// A listed unit, else a compound one; nullopt when neither reads the text. A unit that is a listed
// one but for letter case is refused with the listed spelling, even where it would read as a
// compound: "mPa", "mbar", "Mm" and "Ms" are milli-pascal, millibar, megametre and megasecond,
// but in a scene of impacts they are MPa, Mbar, mm and ms mistyped.
std::optional<Conversion> read_unit(std::string_view written, std::string_view text, std::optional<Dimension> expected) {
    if (const Unit* listed = find_unit(written)) return conversion_of(*listed);
    if (const Unit* near = case_insensitive_match(written, expected)) {
        throw UnitError(fmt::format("unknown unit \"{}\" in \"{}\" (units are case-sensitive: did you mean \"{}\"?)", written,
                                    text, near->symbol));
    }
    return compound_unit(written);
}

}  // namespace

double parse_quantity(std::string_view text, Dimension expected) {
    const Split s = split(text);
    if (s.unit.empty()) {
        if (expected == Dimension::Dimensionless) return to_double(s.number, nullptr, text);
        throw UnitError(fmt::format("\"{}\" has no unit: write {} as a plain number in {} or as a string with one of {}",
                                    text, article_name(expected), si_unit_of(expected), accepted_units(expected)));
    }
    const auto unit = read_unit(s.unit, text, expected);
    if (!unit) {
        throw UnitError(fmt::format("unknown unit \"{}\" in \"{}\"; {}", s.unit, text, takes(expected)));
    }
    const auto dimension = dimension_of(unit->exponents);
    if (!dimension) {
        throw UnitError(fmt::format("\"{}\" is in {} (SI {}), which no scene value is; {}", text, s.unit,
                                    describe(unit->exponents), takes(expected)));
    }
    if (*dimension != expected) {
        throw UnitError(fmt::format("\"{}\" is {}, not {}; {}", text, article_name(*dimension),
                                    article_name(expected), takes(expected)));
    }
    return to_double(s.number, &*unit, text);
}

Quantity parse_any_quantity(std::string_view text) {
    const Split s = split(text);
    if (s.unit.empty()) return {to_double(s.number, nullptr, text), Dimension::Dimensionless};
    const auto unit = read_unit(s.unit, text, std::nullopt);
    const auto dimension = unit ? dimension_of(unit->exponents) : std::nullopt;
    if (!dimension) {
        std::string all;
        for (const Dimension d : dimensions) {
            if (d == Dimension::Dimensionless) continue;
            if (!all.empty()) all += "; ";
            all += fmt::format("{}: {}", name_of(d), accepted_units(d));
        }
        throw UnitError(fmt::format("{} \"{}\" in \"{}\" (known units: {}; %{})", unit ? "no quantity of gpa's is in" : "unknown unit",
                                    s.unit, text, all, compound_hint));
    }
    return {to_double(s.number, &*unit, text), *dimension};
}

std::optional<Quantity> compound_unit_value(std::string_view unit) {
    const auto c = compound_unit(unit);
    if (!c) return std::nullopt;
    const auto dimension = dimension_of(c->exponents);
    if (!dimension) return std::nullopt;
    try {
        return Quantity{to_double(WrittenNumber{"1", 0, 1}, &*c, unit), *dimension};
    } catch (const UnitError&) {
        return std::nullopt;  // one such unit is beyond the range of a double ("Gm^9.Gm^9/nm^9/nm^9")
    }
}

}  // namespace gpa::io
