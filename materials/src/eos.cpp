// Equations of state (materials.md, "Equation of state"). Every model is linear in the specific
// internal energy at fixed density, P = a(rho) + b(rho) e, with mu = rho / rho0 - 1.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "internal.hpp"

namespace gpa::materials {
namespace detail {
namespace {

// The Hugoniot-referenced factor that removes the Hugoniot energy from the reference curve:
// P = P_ref (1 - Gamma0 mu / (2 (1 + mu))) + Gamma0 rho0 e (materials.md, Mie-Grueneisen), so
// that on the Hugoniot, e = e_H = P_ref mu / (2 rho0 (1 + mu)), P = P_ref. Returns g and dg/dmu.
struct HugoniotFactor {
    double g = 1.0;
    double dg_dmu = 0.0;
};

HugoniotFactor hugoniot_factor(double gruneisen, double mu) {
    const double one_plus_mu = 1.0 + mu;
    return {1.0 - gruneisen * mu / (2.0 * one_plus_mu), -gruneisen / (2.0 * one_plus_mu * one_plus_mu)};
}

}  // namespace

// P = K mu (or K ln(rho / rho0)); no energy dependence (materials.md, "linear").
EosTerms model_terms(const LinearEos& eos, double rho0, double rho) {
    EosTerms t;
    if (eos.logarithmic) {
        t.a = eos.bulk_modulus * std::log(rho / rho0);
        t.da_drho = eos.bulk_modulus / rho;
    } else {
        t.a = eos.bulk_modulus * (rho / rho0 - 1.0);
        t.da_drho = eos.bulk_modulus / rho0;
    }
    return t;
}

// EPIC polynomial: compression P = (K1 mu + K2 mu^2 + K3 mu^3) g(mu) + Gamma0 rho0 e;
// tension P = K1 mu + Gamma0 rho0 e (materials.md, "polynomial"; header PolynomialEos).
EosTerms model_terms(const PolynomialEos& eos, double rho0, double rho) {
    const double mu = rho / rho0 - 1.0;
    EosTerms t;
    t.b = eos.gruneisen * rho0;
    if (mu > 0.0) {
        const double p_ref = mu * (eos.k1 + mu * (eos.k2 + mu * eos.k3));
        const double dp_ref = eos.k1 + mu * (2.0 * eos.k2 + 3.0 * mu * eos.k3);
        const HugoniotFactor h = hugoniot_factor(eos.gruneisen, mu);
        t.a = p_ref * h.g;
        t.da_drho = (dp_ref * h.g + p_ref * h.dg_dmu) / rho0;
    } else {
        t.a = eos.k1 * mu;
        t.da_drho = eos.k1 / rho0;
    }
    return t;
}

// Mie-Grueneisen on a linear Us = c0 + s up Hugoniot (materials.md):
//   compression P = P_H g(mu) + Gamma0 rho0 e, P_H = rho0 c0^2 mu (1 + mu) / (1 - (s - 1) mu)^2;
//   tension     P = rho0 c0^2 mu + Gamma0 rho0 e.
// Pole guard: P_H diverges at mu = 1/(s - 1). Compression is refused once (s - 1) mu >= 0.9, that
// is mu >= 0.9 / (s - 1) (kPoleMargin = 0.1). There P_H is already 100 mu (1 + mu) rho0 c0^2
// (for copper, s = 1.489: mu = 1.84, P_H ~ 520 rho0 c0^2 ~ 70 TPa), two orders of magnitude beyond
// the shock data any linear Us-up fit comes from; a node that gets there has tangled, and a loud
// error beats an overflowing pressure (EosTerms::beyond_limit, eos_limit_message).
EosTerms model_terms(const MieGruneisenEos& eos, double rho0, double rho) {
    const double mu = rho / rho0 - 1.0;
    const double k0 = rho0 * eos.sound_speed * eos.sound_speed;
    EosTerms t;
    t.b = eos.gruneisen * rho0;
    if (mu > 0.0) {
        const double sm1 = eos.slope - 1.0;
        if (sm1 > 0.0 && !(sm1 * mu < 1.0 - kPoleMargin)) {
            t.beyond_limit = true;
            return t;
        }
        const double eta = 1.0 - sm1 * mu;  // > 0.1 when s > 1; >= 1 when s <= 1
        const double p_h = k0 * mu * (1.0 + mu) / (eta * eta);
        const double dp_h = k0 * ((1.0 + 2.0 * mu) / (eta * eta) + 2.0 * sm1 * mu * (1.0 + mu) / (eta * eta * eta));
        const HugoniotFactor h = hugoniot_factor(eos.gruneisen, mu);
        t.a = p_h * h.g;
        t.da_drho = (dp_h * h.g + p_h * h.dg_dmu) / rho0;
    } else {
        t.a = k0 * mu;
        t.da_drho = k0 / rho0;
    }
    return t;
}

std::string eos_limit_message(const MieGruneisenEos& eos, double rho0, double rho) {
    const double mu = rho / rho0 - 1.0;
    const double sm1 = eos.slope - 1.0;
    return fmt::format(
        "Mie-Gruneisen EOS: compression mu = {:.6g} (rho = {:.6g} kg/m^3) is at or beyond the limit "
        "mu = {:.6g}, {:g} % short of the Hugoniot pole mu = 1/(s - 1) = {:.6g} (s = {:g})",
        mu, rho, (1.0 - kPoleMargin) / sm1, 100.0 * kPoleMargin, 1.0 / sm1, eos.slope);
}

// P = a(rho) + b(rho) e for the model held by `eos` (materials.md, "Equation of state").
EosTerms eos_terms(const EquationOfState& eos, double reference_density, double density) {
    if (!(density > 0.0) || !std::isfinite(density)) {
        throw std::domain_error(fmt::format("equation of state evaluated at density {} kg/m^3 (must be positive)",
                                            density));
    }
    return std::visit(
        [&](const auto& model) -> EosTerms {
            const EosTerms t = model_terms(model, reference_density, density);
            if constexpr (std::is_same_v<std::decay_t<decltype(model)>, MieGruneisenEos>) {
                if (t.beyond_limit) throw std::domain_error(eos_limit_message(model, reference_density, density));
            }
            return t;
        },
        eos);
}

// dP/drho at mu = 0 times rho0: K, K1 or rho0 c0^2.
double reference_bulk_modulus(const EquationOfState& eos, double reference_density) {
    return std::visit(
        [&](const auto& model) -> double {
            using T = std::decay_t<decltype(model)>;
            if constexpr (std::is_same_v<T, LinearEos>) {
                return model.bulk_modulus;
            } else if constexpr (std::is_same_v<T, PolynomialEos>) {
                return model.k1;
            } else {
                return reference_density * model.sound_speed * model.sound_speed;
            }
        },
        eos);
}

// Isentropic bulk modulus K_s = rho dP/drho|_e + (P / rho) dP/de (header EosResult; the second
// term follows from de = P / rho^2 drho along an isentrope).
// Floor: in deep tension the tension branches give K_s -> 0 and below (e.g. Mie-Grueneisen,
// K_s = rho0 c0^2 (1 + mu) + Gamma0 P / (1 + mu) < 0 for mu < -0.3 when Gamma0 = 2). K_s only
// feeds sound speeds (time step, artificial viscosity), so it is floored at 1 % of the reference
// bulk modulus (bulk sound speed >= 10 % of c0): raising c there only shortens the time step.
double isentropic_bulk_modulus(const EosTerms& t, double reference_bulk, double density, double energy) {
    const double pressure = t.a + t.b * energy;
    const double k_s = density * (t.da_drho + t.db_drho * energy) + pressure / density * t.b;
    const double floor = kBulkModulusFloorFraction * reference_bulk;
    return std::max(k_s, floor);  // a NaN (from a NaN energy) passes through, visibly
}

}  // namespace detail

// Public EOS evaluation (materials.md, "Equation of state"): P, dP/de and K_s (floored, see
// detail::isentropic_bulk_modulus).
EosResult evaluate_eos(const EquationOfState& eos, double reference_density, double density,
                       double specific_internal_energy) {
    const detail::EosTerms t = detail::eos_terms(eos, reference_density, density);
    EosResult r;
    r.pressure = t.a + t.b * specific_internal_energy;
    r.energy_coefficient = t.b;
    r.bulk_modulus = detail::isentropic_bulk_modulus(t, detail::reference_bulk_modulus(eos, reference_density),
                                                     density, specific_internal_energy);
    return r;
}

}  // namespace gpa::materials
