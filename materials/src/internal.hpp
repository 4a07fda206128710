#pragma once
// Helpers shared by the material model sources; not part of the public API.

#include <cmath>
#include <string>

#include <Eigen/Core>

#include "gpa/materials/material.hpp"

namespace gpa::materials::detail {

// Every equation of state here is linear in e at fixed rho: P = a(rho) + b(rho) e
// (materials.md, "Equation of state"). The terms and their density derivatives give the
// pressure, the exact energy solve of the point update and the isentropic bulk modulus.
struct EosTerms {
    double a = 0.0;        // P at e = 0, Pa
    double b = 0.0;        // dP/de at fixed rho, kg/m^3
    double da_drho = 0.0;  // m^2/s^2
    double db_drho = 0.0;  // 1 (zero for every model here: Gamma rho = Gamma0 rho0)
    // Mie-Grueneisen only: the density is at or beyond the compression guard short of the Hugoniot
    // pole (eos.cpp); the other terms are then not evaluated.
    bool beyond_limit = false;
};

// The terms of one model, chosen by overload (a PointModel picks them once per material). The
// density must be positive and finite (the point update checks it first).
EosTerms model_terms(const LinearEos& eos, double reference_density, double density);
EosTerms model_terms(const PolynomialEos& eos, double reference_density, double density);
EosTerms model_terms(const MieGruneisenEos& eos, double reference_density, double density);

// The words for a density beyond the Mie-Grueneisen guard (EosTerms::beyond_limit).
std::string eos_limit_message(const MieGruneisenEos& eos, double reference_density, double density);

// The terms of the model held by `eos`; throws std::domain_error for a density that is not
// positive and finite, or beyond the Mie-Grueneisen guard (eos_limit_message).
EosTerms eos_terms(const EquationOfState& eos, double reference_density, double density);

// The bulk modulus of the unstressed material: K (linear), K1 (polynomial), rho0 c0^2 (Mie-Grueneisen).
double reference_bulk_modulus(const EquationOfState& eos, double reference_density);

// K_s = rho dP/drho|_e + (P / rho) dP/de from the terms, floored at
// kBulkModulusFloorFraction * reference bulk modulus (see eos.cpp).
double isentropic_bulk_modulus(const EosTerms& t, double reference_bulk, double density, double energy);

// The floor on K_s as a fraction of the reference bulk modulus (eos.cpp explains the value).
inline constexpr double kBulkModulusFloorFraction = 0.01;

// Mie-Grueneisen pole guard: compression is refused once (s - 1) mu reaches 1 - kPoleMargin,
// i.e. mu >= 0.9 / (s - 1) (eos.cpp explains the value).
inline constexpr double kPoleMargin = 0.1;

// Symmetric tensors: Sym3 (xx, yy, zz, yz, xz, xy) <-> 3x3 matrix. Inline, with von_mises: the
// point update calls them for every point of every step.
inline Eigen::Matrix3d to_matrix(const Sym3& s) {
    Eigen::Matrix3d m;
    m << s[0], s[5], s[4],  //
        s[5], s[1], s[3],   //
        s[4], s[3], s[2];
    return m;
}

// The symmetric part of m.
inline Sym3 to_sym3(const Eigen::Matrix3d& m) {
    return {m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(1, 2) + m(2, 1)), 0.5 * (m(0, 2) + m(2, 0)), 0.5 * (m(0, 1) + m(1, 0))};
}

// sqrt(3/2 s:s), the von Mises equivalent of a deviator (materials.md, "Strength").
inline double von_mises(const Eigen::Matrix3d& deviator) { return std::sqrt(1.5 * deviator.squaredNorm()); }

// Flow stress and its slope dY/d eps_p at fixed rate and temperature, for the plastic models.
struct FlowStress {
    double stress = 0.0;  // Y, Pa
    double slope = 0.0;   // dY / d eps_p, Pa (infinite at eps_p = 0 when n < 1)
};

FlowStress johnson_cook_flow(const JohnsonCookStrength& jc, double plastic_strain, double strain_rate,
                             double homologous_temperature);

// Result of the radial return of a trial deviator (spec section 4).
struct ReturnResult {
    Eigen::Matrix3d deviator;              // on or inside the yield surface
    double plastic_strain_increment = 0.0;  // d eps_p >= 0
    double flow_stress = 0.0;              // Y at the end of the step (0 for an elastic material)
    bool plastic = false;
    int iterations = 0;  // Johnson-Cook: flow-stress evaluations of the return's iteration (0 otherwise)
    double trial_equivalent = 0.0;  // sigma_eq of the trial deviator, where it was returned (plastic)
};

// Radial return of the trial deviator to the flow stress of the strength model at plastic strain
// eps_p, strain rate (1/s) and homologous temperature; shear modulus G (Pa). dt: the step's length;
// the Johnson-Cook rate term uses the equivalent plastic strain rate d eps_p / dt of the return
// itself (Johnson and Cook 1983 define epsdot* so). One overload per model (a PointModel picks it
// once per material). previous_rate: the point's d eps_p / dt of its last step (PointState::
// plastic_strain_rate), where the Johnson-Cook iteration starts; the other models do not iterate.
ReturnResult model_return(const ElasticStrength& strength, const Eigen::Matrix3d& trial, double shear_modulus,
                          double plastic_strain, double dt, double homologous_temperature, double previous_rate);
ReturnResult model_return(const VonMisesStrength& strength, const Eigen::Matrix3d& trial, double shear_modulus,
                          double plastic_strain, double dt, double homologous_temperature, double previous_rate);
ReturnResult model_return(const JohnsonCookStrength& strength, const Eigen::Matrix3d& trial, double shear_modulus,
                          double plastic_strain, double dt, double homologous_temperature, double previous_rate);

}  // namespace gpa::materials::detail
