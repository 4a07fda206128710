// Material-level functions: validation, homologous temperature, reference wave speed
// (materials.md, "Models to provide").

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "internal.hpp"

namespace gpa::materials {
namespace {

// Builds the std::invalid_argument messages of validate(): they name the material and the field,
// `material "OFHC copper": density -1 kg/m^3 must be positive`. Field names follow the C++
// members (dotted for nested parameter structs); NaN fails every check.
class Checker {
public:
    explicit Checker(const Material& m) : material_(m) {}

    void positive(std::string_view field, double value, std::string_view unit) const {
        if (!(value > 0.0) || !std::isfinite(value)) {
            fail(field, value, unit, "must be positive and finite");
        }
    }
    void non_negative(std::string_view field, double value, std::string_view unit) const {
        if (!(value >= 0.0) || !std::isfinite(value)) {
            fail(field, value, unit, "must be non-negative and finite");
        }
    }
    void finite(std::string_view field, double value, std::string_view unit) const {
        if (!std::isfinite(value)) {
            fail(field, value, unit, "must be finite");
        }
    }
    void in_unit_interval(std::string_view field, double value) const {
        if (!(value >= 0.0 && value <= 1.0)) {
            fail(field, value, "", "must lie in [0, 1]");
        }
    }
    [[noreturn]] void fail(std::string_view field, double value, std::string_view unit,
                           std::string_view requirement) const {
        throw std::invalid_argument(fmt::format("material \"{}\": {} {}{}{} {}", material_.name, field, value,
                                                unit.empty() ? "" : " ", unit, requirement));
    }
    [[noreturn]] void fail(std::string_view what) const {
        throw std::invalid_argument(fmt::format("material \"{}\": {}", material_.name, what));
    }

private:
    const Material& material_;
};

void check_eos(const Checker& c, const EquationOfState& eos) {
    if (const auto* lin = std::get_if<LinearEos>(&eos)) {
        c.positive("eos.bulk_modulus", lin->bulk_modulus, "Pa");
    } else if (const auto* poly = std::get_if<PolynomialEos>(&eos)) {
        c.positive("eos.k1", poly->k1, "Pa");
        c.finite("eos.k2", poly->k2, "Pa");
        c.finite("eos.k3", poly->k3, "Pa");
        c.non_negative("eos.gruneisen", poly->gruneisen, "");
    } else {
        const auto& mg = std::get<MieGruneisenEos>(eos);
        c.positive("eos.sound_speed", mg.sound_speed, "m/s");
        c.non_negative("eos.slope", mg.slope, "");
        c.non_negative("eos.gruneisen", mg.gruneisen, "");
    }
}

void check_strength(const Checker& c, const Strength& strength) {
    if (const auto* vm = std::get_if<VonMisesStrength>(&strength)) {
        c.non_negative("strength.yield_stress", vm->yield_stress, "Pa");
        c.non_negative("strength.hardening_modulus", vm->hardening_modulus, "Pa");
    } else if (const auto* jc = std::get_if<JohnsonCookStrength>(&strength)) {
        c.non_negative("strength.a", jc->a, "Pa");
        c.non_negative("strength.b", jc->b, "Pa");
        c.non_negative("strength.n", jc->n, "");
        if (jc->b > 0.0 && !(jc->n > 0.0)) {
            c.fail("strength.n", jc->n, "", "must be positive when strength.b is not zero");
        }
        c.non_negative("strength.c", jc->c, "");
        c.positive("strength.m", jc->m, "");
        c.positive("strength.reference_strain_rate", jc->reference_strain_rate, "1/s");
    }
}

void check_failure(const Checker& c, const Failure& failure) {
    if (failure.johnson_cook) {
        const JohnsonCookFailure& f = *failure.johnson_cook;
        c.finite("failure.johnson_cook.d1", f.d1, "");
        c.finite("failure.johnson_cook.d2", f.d2, "");
        c.finite("failure.johnson_cook.d3", f.d3, "");
        c.finite("failure.johnson_cook.d4", f.d4, "");
        c.finite("failure.johnson_cook.d5", f.d5, "");
        c.positive("failure.johnson_cook.reference_strain_rate", f.reference_strain_rate, "1/s");
        c.positive("failure.johnson_cook.min_failure_strain", f.min_failure_strain, "");
    }
    if (failure.spall_pressure) {
        c.positive("failure.spall_pressure", *failure.spall_pressure, "Pa");
    }
}

}  // namespace

// Parameter checks (header: validate). Every field the models divide by or take a power or log of
// must be positive; moduli, heat capacity and strength constants non-negative; beta in [0, 1];
// the melt temperature above room temperature (it may be +infinity: no melting).
void validate(const Material& m) {
    const Checker c(m);
    if (m.name.empty()) {
        c.fail("name must not be empty");
    }
    c.positive("density", m.density, "kg/m^3");
    c.non_negative("shear_modulus", m.shear_modulus, "Pa");
    c.non_negative("specific_heat", m.specific_heat, "J/(kg K)");
    c.in_unit_interval("taylor_quinney", m.taylor_quinney);
    c.positive("room_temperature", m.room_temperature, "K");
    if (!(m.melt_temperature > m.room_temperature)) {
        c.fail("melt_temperature", m.melt_temperature, "K",
               fmt::format("must exceed room_temperature {} K", m.room_temperature));
    }
    check_eos(c, m.eos);
    check_strength(c, m.strength);
    check_failure(c, m.failure);
}

// T* = (T - T_room) / (T_melt - T_room), clamped to [0, 1] (materials.md, "Strength"); 0 for an
// infinite melt temperature.
double homologous_temperature(const Material& m, double temperature) {
    if (!std::isfinite(m.melt_temperature)) {
        return 0.0;
    }
    return std::clamp((temperature - m.room_temperature) / (m.melt_temperature - m.room_temperature), 0.0, 1.0);
}

// sqrt((K + 4 G / 3) / rho0) with K the EOS's K_s at (rho0, e = 0) (header: reference_wave_speed).
double reference_wave_speed(const Material& m) {
    const double k = evaluate_eos(m.eos, m.density, m.density, 0.0).bulk_modulus;
    return std::sqrt((k + 4.0 * m.shear_modulus / 3.0) / m.density);
}

}  // namespace gpa::materials
