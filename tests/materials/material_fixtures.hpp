#pragma once
// Materials and a small driver shared by the material tests. Constants from materials.md.

#include <cmath>
#include <limits>
#include <utility>

#include <Eigen/Core>

#include "gpa/materials/material.hpp"

namespace gpa::materials::test {

// OFHC copper: Johnson-Cook strength (Johnson and Cook 1983), Mie-Grueneisen (Steinberg).
// rho0 = 8930 kg/m^3, the shock table's density, used for masses and the EOS alike.
inline Material copper() {
    Material m;
    m.name = "OFHC copper";
    m.source = "materials.md tables (test fixture)";
    m.density = 8930.0;
    m.shear_modulus = 46e9;
    m.specific_heat = 383.0;
    m.taylor_quinney = 0.9;
    m.room_temperature = 294.0;
    m.melt_temperature = 1356.0;
    m.eos = MieGruneisenEos{3940.0, 1.489, 2.02};
    m.strength = JohnsonCookStrength{90e6, 292e6, 0.31, 0.025, 1.09, 1.0};
    return m;
}

// Copper strength and heat with a linear EOS (K = rho0 c0^2): no energy dependence, so pure shear
// keeps P = 0 exactly.
inline Material copper_linear() {
    Material m = copper();
    m.eos = LinearEos{8930.0 * 3940.0 * 3940.0, false};
    return m;
}

// Elastic-perfectly plastic aluminium-like material with the logarithmic linear EOS.
inline Material von_mises_aluminium() {
    Material m;
    m.name = "von Mises aluminium";
    m.density = 2770.0;
    m.shear_modulus = 26e9;
    m.eos = LinearEos{68e9, true};
    m.strength = VonMisesStrength{300e6};
    return m;
}

inline Eigen::Matrix3d to_matrix(const Sym3& s) {
    Eigen::Matrix3d m;
    m << s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2];
    return m;
}

inline double von_mises(const Eigen::Matrix3d& s) { return std::sqrt(1.5 * s.squaredNorm()); }
inline double von_mises(const Sym3& s) { return von_mises(to_matrix(s)); }
inline double trace(const Sym3& s) { return s[0] + s[1] + s[2]; }

// Pure shear in x-y at engineering shear rate gamma_dot: L symmetric, so no spin and no volume change.
inline Eigen::Matrix3d pure_shear(double gamma_dot) {
    Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
    l(0, 1) = l(1, 0) = 0.5 * gamma_dot;
    return l;
}

// The plastic strain increment of a step read back as eps_after - eps_before differs from the
// increment x the return computed by the rounding of eps_before + x when it was stored (at most
// eps_machine/2 eps_after) and of the subtraction (eps_machine/2 x); x recovered from the reported
// plastic rate as (x / dt) dt carries two more roundings (eps_machine x). With x <= eps_after the
// sum is at most 2 eps_machine eps_after: this bound, with a factor-2 margin, is how closely the
// read-back increment, the reported rate times dt and x can be compared.
inline double increment_read_back_tolerance(double plastic_strain_after) {
    return 4.0 * std::numeric_limits<double>::epsilon() * plastic_strain_after;
}

// Drives one point with a constant-in-step velocity gradient; density follows
// rho_new = rho_old exp(-tr(L) dt), exact for a constant L.
struct Driver {
    Material material;
    PointState state;
    double density;
    bool failure_enabled = false;

    explicit Driver(Material m) : material(std::move(m)), density(material.density) {
        state.temperature = material.room_temperature;
    }

    PointResult step(const Eigen::Matrix3d& l, double dt, double q_old = 0.0, double q_new = 0.0) {
        PointIncrement inc;
        inc.velocity_gradient = l;
        inc.dt = dt;
        inc.density_old = density;
        inc.density_new = density * std::exp(-l.trace() * dt);
        inc.viscous_pressure_old = q_old;
        inc.viscous_pressure_new = q_new;
        inc.failure_enabled = failure_enabled;
        density = inc.density_new;
        return update_point(material, state, inc);
    }

    // A step to a prescribed density (the velocity gradient still sets the deviator).
    PointResult step_to(const Eigen::Matrix3d& l, double dt, double density_new) {
        PointIncrement inc;
        inc.velocity_gradient = l;
        inc.dt = dt;
        inc.density_old = density;
        inc.density_new = density_new;
        inc.failure_enabled = failure_enabled;
        density = density_new;
        return update_point(material, state, inc);
    }
};

}  // namespace gpa::materials::test
