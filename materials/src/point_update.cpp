// The point update: one material point over one time step (gpa-method.md section 4; the models
// of materials.md; the header comment of update_point is the contract).

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include <fmt/format.h>

#include "internal.hpp"

namespace gpa::materials {
namespace {

// sigma* = -P / sigma_vm (materials.md, "Fracture"), defined as 0 where sigma_vm is ~0: below a
// billionth of the reference bulk modulus (~0.1 Pa for metals), far below any flow stress, where
// the ratio would only be round-off divided by round-off.
double triaxiality(double pressure, double von_mises_stress, double reference_bulk) {
    if (!(von_mises_stress > 1e-9 * reference_bulk)) {
        return 0.0;
    }
    return -pressure / von_mises_stress;
}

bool valid_increment(const PointIncrement& inc) {
    return inc.density_old > 0.0 && inc.density_new > 0.0 && std::isfinite(inc.density_old) &&
           std::isfinite(inc.density_new) && inc.dt >= 0.0 && std::isfinite(inc.dt);
}

std::string increment_message(const PointIncrement& inc) {
    if (!(inc.density_old > 0.0) || !(inc.density_new > 0.0) || !std::isfinite(inc.density_old) ||
        !std::isfinite(inc.density_new)) {
        return fmt::format("point update: densities {} -> {} kg/m^3 must be positive and finite", inc.density_old,
                           inc.density_new);
    }
    return fmt::format("point update: time step {} s must be non-negative and finite", inc.dt);
}

// 1 + b dv / 2 of the energy solve in step 4 below.
double energy_solve_denominator(double b, const PointIncrement& inc) {
    return 1.0 + 0.5 * b * (1.0 / inc.density_new - 1.0 / inc.density_old);
}

PointResult fault(PointFault what) {
    PointResult r;
    r.fault = what;
    return r;
}

// Spec section 4 (hypoelastic-plastic update "in the standard manner") with the models of
// materials.md. Steps, in order:
//  1. D = (L + L^T)/2, Omega = (L - L^T)/2, D' = D - tr(D)/3 I.
//  2. Trial deviator by the Jaumann rate: s* = s + dt (2 G D' + Omega s - s Omega), made exactly
//     symmetric and traceless (both hold in exact arithmetic; this removes round-off drift).
//  3. Radial return to the flow stress (strength.cpp). The strain rate of the Johnson-Cook
//     strength (and of its fracture strain) is the equivalent plastic strain rate d eps_p / dt of
//     the step, as Johnson and Cook (1983, 1985) define epsdot*; the return solves for it with
//     the plastic increment. (An earlier version used the total deviatoric rate; with GPA's
//     node-to-node velocity noise it made OFHC copper at 190 m/s some 7 % too long.) The
//     temperature for thermal softening (and for damage) is the start-of-step T.
//  4. Energy, with mid-step values (average of start and end):
//       e_new = e + dt / rho_mid s_mid : D' - (P_mid + Q_mid) (1/rho_new - 1/rho_old),
//     and P_new = a(rho_new) + b(rho_new) e_new; the equation is linear in e_new and is solved
//     exactly. A point failed at the start of the step carries no tension, so there
//     P_new = max(a + b e_new, 0) and, if that clamps, e_new follows from P_new = 0.
//  5. Plastic work: the plastic part of the mid-step stress power in step 4,
//       dW_p = s_mid : d eps_p / rho_mid,  d eps_p = d eps_p_eq (3/2) s* / sigma_eq*
//     (the return's flow direction). In proportional loading from the yield surface it equals
//     (Y_start + Y_end)/2 d eps_p_eq / rho_mid; it makes the deviatoric work split exactly into
//     dW_p plus the change of the stored elastic energy s:s / (4 G rho) when rho and the axes stay
//     fixed. It is clamped at zero: only a strain reversal within a single step beyond twice the
//     yield strain can make it negative, and heat is not withdrawn.
//  6. Temperature (adiabatic): T += beta dW_p / c_p (materials.md, "Temperature"; W_p per unit
//     mass, so this is beta dW_p / (rho c_p) with W_p per unit volume); none when c_p = 0.
//  7. Failure, only when inc.failure_enabled: Johnson-Cook damage D += d eps_p / eps_f with
//     sigma* = -P_new / sigma_vm(s_new) (0 where sigma_vm ~ 0), the step's rate and start T*;
//     failure at D >= 1; spall when P_new < -P_spall. Damage accumulates only when failure is
//     enabled. A failed point (now or before) keeps no deviator and no tension: s = 0,
//     P = max(P, 0). Energy booked over this step is kept (the released elastic energy stays in e).
//  8. Sound speed sqrt((K_s + 4 G / 3) / rho_new), K_s from the EOS at (rho_new, e_new) floored as
//     in eos.cpp; G = 0 when failed or molten (a plastic model whose strength saw T >= T_melt this
//     step, so its deviator is zero). An elastic material has no melting: it keeps G.
// A fault (PointFault) returns before the state is touched. The models are template arguments:
// PointModel picks the instantiation once per material.
template <class Eos, class StrengthModel>
PointResult update_with(const PointModel& model, PointState& state, const PointIncrement& inc) noexcept {
    const Material& m = model.material();
    const Eos& eos_model = *std::get_if<Eos>(&m.eos);
    const StrengthModel& strength = *std::get_if<StrengthModel>(&m.strength);
    if (!valid_increment(inc)) return fault(PointFault::bad_increment);
    const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();

    // 1. Rates.
    const Eigen::Matrix3d& l = inc.velocity_gradient;
    const Eigen::Matrix3d d = 0.5 * (l + l.transpose());
    const Eigen::Matrix3d omega = 0.5 * (l - l.transpose());
    const Eigen::Matrix3d d_dev = d - (d.trace() / 3.0) * identity;

    const double t_star = homologous_temperature(m, state.temperature);
    constexpr bool plastic_model = !std::is_same_v<StrengthModel, ElasticStrength>;
    const bool molten = plastic_model && t_star >= 1.0;

    // 2-3. Deviator: Jaumann trial and radial return.
    const Eigen::Matrix3d s_old = detail::to_matrix(state.deviatoric_stress);
    Eigen::Matrix3d s_new = Eigen::Matrix3d::Zero();
    double plastic_increment = 0.0;
    double plastic_rate = 0.0;  // d eps_p / dt: the rate of the Johnson-Cook strength and fracture models
    double plastic_power = 0.0;  // s_mid : d eps_p, J/m^3
    int return_iterations = 0;
    if (!state.failed) {
        // Omega s - s Omega = X + X^T with X = Omega s: Omega is antisymmetric and s symmetric bit
        // for bit (both made so above and in to_matrix), so s Omega = -X^T bit for bit and one
        // product serves (the same numbers as the two products).
        const Eigen::Matrix3d spin = omega * s_old;
        Eigen::Matrix3d trial = s_old + inc.dt * (2.0 * m.shear_modulus * d_dev + spin + spin.transpose());
        trial = (0.5 * (trial + trial.transpose())).eval();  // eval: no aliasing with transpose
        trial -= (trial.trace() / 3.0) * identity;
        const detail::ReturnResult r =
            detail::model_return(strength, trial, m.shear_modulus, state.plastic_strain, inc.dt, t_star,
                                 state.plastic_strain_rate);
        s_new = r.deviator;
        return_iterations = r.iterations;
        plastic_increment = r.plastic_strain_increment;
        plastic_rate = inc.dt > 0.0 ? plastic_increment / inc.dt : 0.0;
        if (plastic_increment > 0.0) {
            const Eigen::Matrix3d s_mid = 0.5 * (s_old + s_new);
            plastic_power = plastic_increment * 1.5 * s_mid.cwiseProduct(trial).sum() / r.trial_equivalent;
        }
    }

    // 4. Energy and pressure, the linear equation in e_new solved exactly.
    const double rho_old = inc.density_old;
    const double rho_new = inc.density_new;
    const double rho_mid = 0.5 * (rho_old + rho_new);
    const double dv = 1.0 / rho_new - 1.0 / rho_old;
    const double q_mid = 0.5 * (inc.viscous_pressure_old + inc.viscous_pressure_new);

    const detail::EosTerms eos = detail::model_terms(eos_model, m.density, rho_new);
    if (eos.beyond_limit) return fault(PointFault::eos_limit);
    double energy = state.specific_internal_energy;
    double pressure = 0.0;
    if (inc.energy_booked_by_caller) {
        // The caller books this step's work into e (the compatible update, docs/energy.md): the
        // pressure follows from the EOS at the new density and the energy as it stands; no energy
        // equation is solved here, so no step is too large for one.
        pressure = eos.a + eos.b * energy;
        if (state.failed && pressure < 0.0) pressure = 0.0;
    } else {
        // e_new = known - (a + b e_new) dv / 2  =>  e_new (1 + b dv / 2) = known - a dv / 2.
        const double deviatoric_work = inc.dt / rho_mid * (0.5 * (s_old + s_new)).cwiseProduct(d_dev).sum();
        const double known = state.specific_internal_energy + deviatoric_work - (0.5 * state.pressure + q_mid) * dv;
        const double denominator = energy_solve_denominator(eos.b, inc);
        // b = Gamma0 rho0 (Mie-Grueneisen), so 1 + b dv / 2 falls to 1/2 when one step shrinks the
        // specific volume by v0 / Gamma0: half the initial specific volume for Gamma0 = 2, out of
        // reach of an explicit step at about the initial density, but only a sixth of the volume of
        // a failed node expanded to a third of it (a fragment cloud of a hypervelocity impact).
        // The trapezoidal solve is then no longer a fair approximation: refuse it, naming the step.
        if (!(denominator > 0.5)) return fault(PointFault::energy_solve);
        energy = (known - 0.5 * eos.a * dv) / denominator;
        pressure = eos.a + eos.b * energy;
        if (state.failed && pressure < 0.0) {
            pressure = 0.0;
            energy = known;
        }
    }
    // A Johnson-Cook return that did not converge is reported after the faults of the equation of
    // state and the energy solve, as the engine reported them before these were PointFaults.
    if (return_iterations > johnson_cook_max_iterations) {
        PointResult not_converged = fault(PointFault::return_not_converged);
        not_converged.return_iterations = return_iterations;
        return not_converged;
    }

    // 5-6. Plastic work and temperature.
    const double plastic_work = std::max(plastic_power, 0.0) / rho_mid;
    if (m.specific_heat > 0.0) {
        state.temperature += m.taylor_quinney * plastic_work / m.specific_heat;
    }

    // 7. Damage and failure.
    const double reference_bulk = model.reference_bulk_modulus();
    PointResult result;
    if (inc.failure_enabled && !state.failed) {
        if (m.failure.johnson_cook && plastic_increment > 0.0) {
            const double sigma_star = triaxiality(pressure, detail::von_mises(s_new), reference_bulk);
            const double eps_f = johnson_cook_failure_strain(*m.failure.johnson_cook, sigma_star, plastic_rate, t_star);
            state.damage += plastic_increment / eps_f;
            result.failed_now = state.damage >= 1.0;
        }
        if (m.failure.spall_pressure && pressure < -*m.failure.spall_pressure) {
            result.failed_now = true;
        }
        state.failed = result.failed_now;
    }
    if (state.failed) {
        s_new.setZero();
        pressure = std::max(pressure, 0.0);
    }

    state.deviatoric_stress = detail::to_sym3(s_new);
    state.pressure = pressure;
    state.specific_internal_energy = energy;
    state.plastic_strain += plastic_increment;
    state.plastic_strain_rate = plastic_rate;

    // 8. Sound speed.
    const double k_s = detail::isentropic_bulk_modulus(eos, reference_bulk, rho_new, energy);
    const double shear = (state.failed || molten) ? 0.0 : m.shear_modulus;
    result.sound_speed = std::sqrt((k_s + 4.0 * shear / 3.0) / rho_new);
    result.plastic_work = plastic_work;
    result.viscous_work = inc.energy_booked_by_caller ? 0.0 : -q_mid * dv;
    result.plastic_strain_rate = plastic_rate;
    result.return_iterations = return_iterations;
    return result;
}

}  // namespace

PointModel::PointModel(const Material& material)
    : material_(&material),
      reference_bulk_(detail::reference_bulk_modulus(material.eos, material.density)),
      update_(std::visit(
          [](const auto& eos, const auto& strength) -> Update {
              return &update_with<std::decay_t<decltype(eos)>, std::decay_t<decltype(strength)>>;
          },
          material.eos, material.strength)) {}

std::string PointModel::fault_message(const PointState& state, const PointIncrement& inc, const PointResult& result) const {
    const Material& m = *material_;
    switch (result.fault) {
        case PointFault::none:
            return {};
        case PointFault::bad_increment:
            return increment_message(inc);
        case PointFault::eos_limit:
            return detail::eos_limit_message(std::get<MieGruneisenEos>(m.eos), m.density, inc.density_new);
        case PointFault::energy_solve:
            return fmt::format(
                "point update: compression {} -> {} kg/m^3 in one step is too large for the energy solve "
                "(1 + b dv / 2 = {}); the compatible energy update (solver.energy_update) has no such limit",
                inc.density_old, inc.density_new,
                energy_solve_denominator(detail::eos_terms(m.eos, m.density, inc.density_new).b, inc));
        case PointFault::return_not_converged:
            return fmt::format(
                "the Johnson-Cook return did not converge in {} iterations (plastic strain {:.6g}, temperature {:.6g} K, "
                "time step {:.3g} s)",
                johnson_cook_max_iterations, state.plastic_strain, state.temperature, inc.dt);
    }
    return "point update: unknown fault";
}

PointResult update_point(const Material& m, PointState& state, const PointIncrement& inc) {
    const PointModel model(m);
    const PointResult result = model.update(state, inc);
    if (result.fault != PointFault::none) throw std::domain_error(model.fault_message(state, inc, result));
    return result;
}

}  // namespace gpa::materials
