// gpa's unit reader against UDUNITS-2 (Unidata's maintained unit database, Debian's
// libudunits2-dev), an independent reference for every conversion factor: each listed unit and
// each compound spelling below reads as UDUNITS-2's value, in the same dimension, decimal units
// within two roundings and customary ones within a few (below). (gpa keeps its own reader: UDUNITS-2 converts "x mm" by multiplying, so 560 of the
// 2000 values of Units.DecimalUnitsAreRoundOffExact come out one rounding off the decimal value;
// it reads "J/kg.K" as J K / kg where engineers mean J/(kg K); and it needs its XML database at
// run time, a file a program embedding gpa would have to ship. Measured 2026-12-03, UDUNITS 2.2.28.)
// UDUNITS-2 has no symbol "deg": the degree is its "degree" (or the sign), and gpa's is compared
// with that.

#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <udunits2.h>

#include "gpa/io/units.hpp"

namespace gpa::io {
namespace {

struct System {
    ut_system* system = nullptr;
    System() {
        ut_set_error_message_handler(ut_ignore);
        system = ut_read_xml(nullptr);
    }
    ~System() { ut_free_system(system); }
};

// UDUNITS-2's value of one `unit` in the SI unit of `d`; NaN when it cannot read or convert it.
double reference_value(ut_system* system, const std::string& unit, Dimension d) {
    const std::string si = d == Dimension::Dimensionless ? "1" : std::string(si_unit_of(d));
    std::unique_ptr<ut_unit, decltype(&ut_free)> from(ut_parse(system, unit.c_str(), UT_UTF8), ut_free);
    std::unique_ptr<ut_unit, decltype(&ut_free)> to(ut_parse(system, si.c_str(), UT_UTF8), ut_free);
    if (!from || !to || !ut_are_convertible(from.get(), to.get())) return std::nan("");
    cv_converter* convert = ut_get_converter(from.get(), to.get());
    const double value = cv_convert_double(convert, 1.0);
    cv_free(convert);
    return value;
}

TEST(UnitsAgainstUdunits, EveryListedAndCompoundSpellingHasTheReferenceValue) {
    const System reference;
    ASSERT_NE(reference.system, nullptr) << "UDUNITS-2 could not read its unit database";
    std::vector<std::string> spellings;
    for (const Unit& u : known_units()) {
        // "%" is UDUNITS-2's too, but as 1/100 of nothing; the "J/kg.K" family is read the engineers'
        // way here (see above).
        if (u.symbol == "%" || std::string(u.symbol).find("kg.K") != std::string::npos) continue;
        spellings.emplace_back(u.symbol);
    }
    std::vector<bool> decimal;  // a decimal unit: no customary factor
    for (const Unit& u : known_units()) {
        if (u.symbol == "%" || std::string(u.symbol).find("kg.K") != std::string::npos) continue;
        decimal.push_back(u.factor == 1.0 && u.symbol != "min" && u.symbol != "h");
    }
    for (const char* compound : {"mm/ms", "GN/m^2", "N/mm^2", "g/mm^3", "kJ/g", "m s^-1", "J kg^-1 K^-1", "m^2/s^2/K",
                                 "kbar", "km/s", "1/us", "microseconds", "milliseconds"}) {
        spellings.emplace_back(compound);
        decimal.push_back(true);
    }
    for (const char* compound : {"lbf/in^2", "ksi", "psi", "ft/s", "lb/in^3", "lb/ft^3", "feet", "inches"}) {
        spellings.emplace_back(compound);
        decimal.push_back(false);
    }
    for (const char* compound : {"degrees", "degree", "\u00B0"}) {
        spellings.emplace_back(compound);
        decimal.push_back(false);
    }
    for (const char* compound : {"radians", "rad"}) {
        spellings.emplace_back(compound);
        decimal.push_back(true);
    }
    for (std::size_t k = 0; k < spellings.size(); ++k) {
        const std::string& unit = spellings[k];
        const auto ours = parse_any_quantity("1 " + unit);
        const double theirs = reference_value(reference.system, unit == "deg" ? "degree" : unit, ours.dimension);
        ASSERT_FALSE(std::isnan(theirs)) << unit << ": UDUNITS-2 does not read it as a " << name_of(ours.dimension);
        // Decimal units: ours is the correctly rounded power of ten, theirs a product of rounded
        // factors: two roundings (4.5e-16). Customary ones: one rounding per factor or power on
        // either side (up to four here) and one for the number; 1e-15 is about nine of 1.1e-16.
        EXPECT_NEAR(ours.value, theirs, (decimal[k] ? 4.5e-16 : 1e-15) * std::abs(theirs)) << unit;
    }
    EXPECT_GT(spellings.size(), 60u);
}

}  // namespace
}  // namespace gpa::io
