// The point update over loading paths (gpa-method.md section 4; materials.md): uniaxial strain
// (elastic slope, Hugoniot elastic limit, plastic slope), adiabatic heating from plastic work,
// the energy equation (closed loops, the exact linear solve, the Rankine-Hugoniot jump) and the
// sound speed.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "material_fixtures.hpp"

namespace gpa::materials {
namespace {

using test::Driver;
using test::pure_shear;
using test::to_matrix;

// Exact relations evaluated in a handful of flops: agreement to a few ulp, 1e-12 relative.
constexpr double kPointUpdateRoundOff = 1e-12;

Eigen::Matrix3d deviatoric_rate(const Eigen::Matrix3d& l) {
    const Eigen::Matrix3d d = 0.5 * (l + l.transpose());
    return d - d.trace() / 3.0 * Eigen::Matrix3d::Identity();
}

// An isotropic velocity gradient taking density rho_old to rho_new in dt (D' = 0).
Eigen::Matrix3d isotropic(double rho_old, double rho_new, double dt) {
    return -std::log(rho_new / rho_old) / (3.0 * dt) * Eigen::Matrix3d::Identity();
}

TEST(UniaxialStrain, ElasticSlopeHugoniotElasticLimitAndPlasticSlope) {
    // L = diag(-rate, 0, 0). With the logarithmic EOS, P = K eps (eps = ln(rho/rho0)) exactly and
    // s_xx = -4/3 G eps while elastic, so the axial stress is exactly -(K + 4G/3) eps; on yield
    // s_xx = -2Y/3 and the slope is K. (The plain linear EOS would give P = K (e^eps - 1): the same
    // picture with slopes larger by a factor 1 + eps.)
    const Material m = test::von_mises_aluminium();
    const double k = std::get<LinearEos>(m.eos).bulk_modulus;
    const double g = m.shear_modulus;
    const double y = std::get<VonMisesStrength>(m.strength).yield_stress;
    const double nu = (3.0 * k - 2.0 * g) / (2.0 * (3.0 * k + g));
    const double hel = y * (1.0 - nu) / (1.0 - 2.0 * nu);

    Driver p(m);
    Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
    const double rate = 1e5, dt = 1e-9;  // axial strain 1e-4 per step; yield at eps = Y / 2G = 5.8e-3
    l(0, 0) = -rate;

    struct Sample {
        double strain, axial_stress;  // compression positive
        bool plastic;
    };
    std::vector<Sample> samples;
    for (int step = 0; step < 300; ++step) {
        p.step(l, dt);
        const double eps = std::log(p.density / m.density);
        const double axial = -(p.state.deviatoric_stress[0] - p.state.pressure);
        samples.push_back({eps, axial, p.state.plastic_strain > 0.0});
        if (!samples.back().plastic) {
            // Elastic: slope K + 4G/3 exactly (round-off accumulated over <= 300 steps: 1e-11).
            EXPECT_NEAR(axial, (k + 4.0 * g / 3.0) * eps, 1e-11 * axial);
        } else {
            // On yield: sigma_xx - (-P) = s_xx = -2Y/3 (return to the surface, 1e-12 relative).
            EXPECT_NEAR(p.state.deviatoric_stress[0], -2.0 * y / 3.0, kPointUpdateRoundOff * y);
            // Perfect plasticity in uniaxial strain: eps_p = 2/3 (eps - Y / 2G), exact for the
            // radial return (also in the step that crosses yield).
            EXPECT_NEAR(p.state.plastic_strain, 2.0 / 3.0 * (eps - y / (2.0 * g)), 1e-10 * eps);
        }
        EXPECT_NEAR(test::trace(p.state.deviatoric_stress), 0.0, 1e-14 * y);
    }

    // Both regimes present.
    std::size_t first_plastic = 0;
    while (first_plastic < samples.size() && !samples[first_plastic].plastic) {
        ++first_plastic;
    }
    ASSERT_GT(first_plastic, 5u);
    ASSERT_LT(first_plastic + 5, samples.size());

    // The two measured lines: elastic S = M eps through the origin; plastic S = K_p eps + b.
    const Sample& e1 = samples[first_plastic - 1];
    const Sample& p1 = samples[first_plastic + 2];
    const Sample& p2 = samples.back();
    const double elastic_slope = e1.axial_stress / e1.strain;
    const double plastic_slope = (p2.axial_stress - p1.axial_stress) / (p2.strain - p1.strain);
    const double intercept = p2.axial_stress - plastic_slope * p2.strain;
    EXPECT_NEAR(elastic_slope, k + 4.0 * g / 3.0, 1e-10 * k);
    EXPECT_NEAR(plastic_slope, k, 1e-8 * k);  // a difference of two ~GPa stresses over 0.02 strain
    // The HEL is where the lines cross: Y (1 - nu) / (1 - 2 nu).
    const double crossing_strain = intercept / (elastic_slope - plastic_slope);
    EXPECT_NEAR(elastic_slope * crossing_strain, hel, 1e-8 * hel);
    EXPECT_LE(e1.axial_stress, hel);
    EXPECT_GE(samples[first_plastic].axial_stress, hel);
}

TEST(Heating, TemperatureRiseIsTaylorQuinneyPlasticWorkOverHeatCapacity) {
    // Copper, pure shear at gamma_dot = 1e3 /s to eps_p = 0.3, with thermal softening.
    const Material m = test::copper_linear();
    const auto& jc = std::get<JohnsonCookStrength>(m.strength);
    Driver p(m);
    const double gamma_dot = 1e3, dt = 1e-7;  // shear strain 1e-4 per step
    const double rate = gamma_dot / std::sqrt(3.0);
    double plastic_work = 0.0;
    int steps = 0;
    while (p.state.plastic_strain < 0.3) {
        const PointResult r = p.step(pure_shear(gamma_dot), dt);
        EXPECT_GE(r.plastic_work, 0.0);
        plastic_work += r.plastic_work;
        ++steps;
    }
    const double rise = p.state.temperature - m.room_temperature;
    // dT = beta dW_p / c_p step by step: the sum agrees to round-off.
    EXPECT_NEAR(rise, m.taylor_quinney * plastic_work / m.specific_heat, kPointUpdateRoundOff * rise);
    EXPECT_GT(rise, 20.0);  // ~0.3 * 250 MPa / (8930 * 383) * 0.9 ~ 20 K: far from zero

    // Independent check of the coupled heating: dT/d eps_p = beta Y(eps_p, rate, T*(T)) / (rho c_p),
    // integrated by RK4 with 1e5 steps (error ~1e-15) to the final plastic strain. The model uses
    // the start-of-step T (first order) and a trapezoid in eps_p with d eps_p ~ 6e-5 per step, so
    // its error is at most O(d eps_p) relative, plus the elastic-plastic transition step
    // (<= A d eps_p / W_p ~ 1e-4 of the work). The reference takes the rate as gamma_dot / sqrt 3,
    // the total rate; the model's rate is the plastic rate d eps_p / dt, which falls short of it by
    // the elastic part (the hardening rate over 3 G), a few per cent of the rate near first yield
    // and less later, so C ln(rate) differs by < 1e-3 and Y by < 1e-4. Tolerance 3e-4 (observed
    // 8.8e-5, most of it this rate difference).
    auto slope = [&](double eps, double temperature) {
        const double t_star = homologous_temperature(m, temperature);
        return m.taylor_quinney * johnson_cook_flow_stress(jc, eps, rate, t_star) / (m.density * m.specific_heat);
    };
    const int n = 100000;
    const double h = p.state.plastic_strain / n;
    double temperature = m.room_temperature;
    for (int i = 0; i < n; ++i) {
        const double eps = i * h;
        const double k1 = slope(eps, temperature);
        const double k2 = slope(eps + 0.5 * h, temperature + 0.5 * h * k1);
        const double k3 = slope(eps + 0.5 * h, temperature + 0.5 * h * k2);
        const double k4 = slope(eps + h, temperature + h * k3);
        temperature += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    EXPECT_NEAR(rise, temperature - m.room_temperature, 3e-4 * rise);
    EXPECT_GT(steps, 1000);
}

TEST(Heating, PlasticWorkMatchesTheIntegralOfTheFlowStress) {
    // No thermal softening (no melt, c_p = 0): at constant rate the specific plastic work is
    // W_p = R (A eps_p + B eps_p^(n+1) / (n + 1)) / rho. The per-step work is the mid-step
    // (trapezoid) value; with d eps_p ~ 6e-5 its quadrature error near eps_p = 0 is ~B d eps_p^(1+n),
    // and the step that crosses yield is off by at most A d eps_p: together < 1e-4 of W_p here.
    // The reference's rate is the total rate gamma_dot / sqrt 3, the model's the plastic rate
    // (see the test above): Y differs by < 1e-4. Tolerance 3e-4 (observed 6.5e-5).
    Material m = test::copper_linear();
    m.melt_temperature = std::numeric_limits<double>::infinity();
    m.specific_heat = 0.0;
    const auto& jc = std::get<JohnsonCookStrength>(m.strength);
    Driver p(m);
    const double gamma_dot = 1e3, dt = 1e-7;
    const double rate = gamma_dot / std::sqrt(3.0);
    double plastic_work = 0.0;
    while (p.state.plastic_strain < 0.5) {
        plastic_work += p.step(pure_shear(gamma_dot), dt).plastic_work;
    }
    EXPECT_EQ(p.state.temperature, m.room_temperature);
    const double eps = p.state.plastic_strain;
    const double r = 1.0 + jc.c * std::log(rate);
    const double expected = r * (jc.a * eps + jc.b * std::pow(eps, jc.n + 1.0) / (jc.n + 1.0)) / m.density;
    EXPECT_NEAR(plastic_work, expected, 3e-4 * expected);
}

TEST(Energy, ClosedShearLoopSplitsIntoPlasticWorkAndStoredElasticEnergy) {
    // Shear forward then back to zero total strain (pure shear: rho fixed, P = 0 with the linear
    // EOS, no spin). The energy equation books dt / rho s_mid : D' each step; the plastic work is
    // the plastic part of that same mid-step power, so e - e0 = W_p + s:s / (4 G rho) to round-off.
    const Material m = test::copper_linear();
    Driver p(m);
    const double gamma_dot = 1e3, dt = 1e-7;
    double plastic_work = 0.0, stress_power = 0.0, max_energy = 0.0;
    for (int leg = 0; leg < 2; ++leg) {
        const Eigen::Matrix3d l = pure_shear(leg == 0 ? gamma_dot : -gamma_dot);
        for (int step = 0; step < 3000; ++step) {
            const Eigen::Matrix3d s_old = to_matrix(p.state.deviatoric_stress);
            const PointResult r = p.step(l, dt);
            const Eigen::Matrix3d s_mid = 0.5 * (s_old + to_matrix(p.state.deviatoric_stress));
            stress_power += dt / m.density * s_mid.cwiseProduct(deviatoric_rate(l)).sum();
            plastic_work += r.plastic_work;
            max_energy = std::max(max_energy, std::abs(p.state.specific_internal_energy));
            EXPECT_EQ(p.state.pressure, 0.0);
        }
    }
    const double de = p.state.specific_internal_energy;
    const double stored = to_matrix(p.state.deviatoric_stress).squaredNorm() / (4.0 * m.shear_modulus * m.density);
    EXPECT_NEAR(de, stress_power, kPointUpdateRoundOff * max_energy);
    EXPECT_NEAR(de, plastic_work + stored, 1e-10 * max_energy);
    EXPECT_GT(stored, 0.0);  // reverse yielding leaves a residual deviator
    EXPECT_NEAR(p.state.temperature - m.room_temperature, m.taylor_quinney * plastic_work / m.specific_heat,
                kPointUpdateRoundOff * (p.state.temperature - m.room_temperature));
}

TEST(Energy, HydrostaticCycleWithoutEnergyDependenceReturnsToStart) {
    // Linear EOS (P independent of e), compress to mu = 0.05 and back; D' = 0, Q = 0, so
    // e changes by the trapezoid rule for -integral P dv, whose exact value over a closed path is 0.
    const Material m = test::copper_linear();
    const double k = std::get<LinearEos>(m.eos).bulk_modulus;
    const double rho0 = m.density, dt = 1e-8;
    auto run = [&](const std::vector<double>& densities) {
        Driver p(m);
        double peak = 0.0;
        for (std::size_t i = 1; i < densities.size(); ++i) {
            p.step_to(isotropic(densities[i - 1], densities[i], dt), dt, densities[i]);
            peak = std::max(peak, p.state.specific_internal_energy);
        }
        return std::pair{p.state.specific_internal_energy, peak};
    };
    // (a) The return path retraces the same densities: each step back has the same P_mid and the
    // opposite dv of its forward twin, so e returns to start to round-off.
    std::vector<double> mirrored;
    for (int i = 0; i <= 100; ++i) {
        mirrored.push_back(rho0 * (1.0 + 0.05 * i / 100.0));
    }
    for (int i = 99; i >= 0; --i) {
        mirrored.push_back(mirrored[static_cast<std::size_t>(i)]);
    }
    const auto [e_mirrored, peak] = run(mirrored);
    EXPECT_GT(peak, 1e4);  // K mu^2 / (2 rho0) ~ 2e4 J/kg at the top
    EXPECT_NEAR(e_mirrored, 0.0, 1e-12 * peak);

    // (b) Different steps out (100) and back (73): the trapezoid errors no longer cancel. Each
    // panel's error is at most h^3 / 12 max|P''(v)|, P(v) = K (v0 / v - 1), P'' = 2 K v0 / v^3.
    std::vector<double> uneven;
    for (int i = 0; i <= 100; ++i) {
        uneven.push_back(rho0 * (1.0 + 0.05 * i / 100.0));
    }
    for (int i = 72; i >= 0; --i) {
        uneven.push_back(rho0 * (1.0 + 0.05 * i / 73.0));
    }
    double bound = 0.0;
    for (std::size_t i = 1; i < uneven.size(); ++i) {
        const double h = std::abs(1.0 / uneven[i] - 1.0 / uneven[i - 1]);
        const double v_min = 1.0 / std::max(uneven[i], uneven[i - 1]);
        bound += h * h * h / 12.0 * 2.0 * k / (rho0 * v_min * v_min * v_min);
    }
    const double e_uneven = run(uneven).first;
    EXPECT_LE(std::abs(e_uneven), bound);
    EXPECT_LT(bound, 1e-3 * peak);  // "close to start": the bound is small against the energy swing
}

MieGruneisenEos copper_shock() { return std::get<MieGruneisenEos>(test::copper().eos); }

double copper_hugoniot_pressure(double mu) {
    const MieGruneisenEos eos = copper_shock();
    const double eta = 1.0 - (eos.slope - 1.0) * mu;
    return 8930.0 * eos.sound_speed * eos.sound_speed * mu * (1.0 + mu) / (eta * eta);
}

TEST(Energy, MieGruneisenSingleStepFromRestIsTheRankineHugoniotJump) {
    // From rest (P = 0, e = 0) one step to rho1 with Q = 0 and D' = 0 books
    // e1 = -(P1 / 2)(1/rho1 - 1/rho0), the Rankine-Hugoniot energy; solved exactly with the EOS,
    // the end state is on the Hugoniot: P1 = P_H(mu1) and e1 = e_H(mu1).
    const Material m = test::copper();
    for (double mu : {0.01, 0.1, 0.3}) {
        Driver p(m);
        const double rho1 = m.density * (1.0 + mu);
        p.step_to(isotropic(m.density, rho1, 1e-8), 1e-8, rho1);
        const double p_h = copper_hugoniot_pressure(mu);
        EXPECT_NEAR(p.state.pressure, p_h, kPointUpdateRoundOff * p_h) << mu;
        EXPECT_NEAR(p.state.specific_internal_energy, p_h * mu / (2.0 * m.density * (1.0 + mu)),
                    kPointUpdateRoundOff * p_h / m.density)
            << mu;
    }
}

TEST(Energy, MieGruneisenExactSolveMakesEnergyConsistentWithPressure) {
    // Compression with shear and artificial viscosity: at every step, P_new = EOS(rho_new, e_new) and
    // e_new - e_old = dt / rho_mid s_mid : D' - (P_mid + Q_mid)(1/rho_new - 1/rho_old) with that
    // P_new, to round-off.
    const Material m = test::copper();
    Driver p(m);
    Eigen::Matrix3d l = pure_shear(2e4);
    l(0, 0) = -3e4;  // compression along x
    const double dt = 1e-7;
    double q_old = 0.0;
    for (int step = 0; step < 80; ++step) {
        const double q_new = 5e8 * (1.0 + std::sin(0.3 * step));  // any non-negative Q history
        const PointState before = p.state;
        const double rho_old = p.density;
        const PointResult r = p.step(l, dt, q_old, q_new);
        const double rho_new = p.density;
        const EosResult eos = evaluate_eos(m.eos, m.density, rho_new, p.state.specific_internal_energy);
        EXPECT_NEAR(p.state.pressure, eos.pressure, kPointUpdateRoundOff * std::abs(eos.pressure));

        const double dv = 1.0 / rho_new - 1.0 / rho_old;
        const Eigen::Matrix3d s_mid = 0.5 * (to_matrix(before.deviatoric_stress) + to_matrix(p.state.deviatoric_stress));
        const double q_mid = 0.5 * (q_old + q_new);
        const double booked = dt / (0.5 * (rho_old + rho_new)) * s_mid.cwiseProduct(deviatoric_rate(l)).sum() -
                              (0.5 * (before.pressure + eos.pressure) + q_mid) * dv;
        const double scale = std::abs(p.state.specific_internal_energy) + std::abs(eos.pressure * dv);
        EXPECT_NEAR(p.state.specific_internal_energy - before.specific_internal_energy, booked, kPointUpdateRoundOff * scale);
        EXPECT_NEAR(r.viscous_work, -q_mid * dv, kPointUpdateRoundOff * std::abs(q_mid * dv));
        EXPECT_GT(r.viscous_work, 0.0);  // compression with Q > 0
        q_old = q_new;
    }
    EXPECT_GT(p.density / m.density - 1.0, 0.2);  // well into the nonlinear part of the Hugoniot
}

TEST(Energy, AFailedExpandedPointCompressedHardInOneStepNeedsNoEnergySolveWhenTheCallerBooksTheWork) {
    // A failed node of a fragment cloud (hypervelocity impact, 0.2 mm, all-variable) expanded to a
    // third of its density and compressed by 29 % in one step: 1 + Gamma0 rho0 dv / 2 = 0.32, so the
    // point update's own trapezoidal energy solve is refused, naming the step; with the compatible
    // update (the caller books the work) there is no solve, and the update must go through with
    // P = EOS(rho_new, e) clamped at zero and e left for the caller (it used to throw the same
    // refusal and stop the run).
    const Material m = test::copper();
    PointState failed;
    failed.failed = true;
    failed.damage = 1.0;
    failed.specific_internal_energy = 2e5;  // J/kg, heated by the impact
    PointIncrement inc;
    inc.dt = 1.6e-9;
    inc.density_old = m.density / 3.0;
    inc.density_new = 1.29 * inc.density_old;
    inc.velocity_gradient = isotropic(inc.density_old, inc.density_new, inc.dt);
    inc.failure_enabled = true;
    ASSERT_LT(1.0 + 0.5 * 2.02 * m.density * (1.0 / inc.density_new - 1.0 / inc.density_old), 0.5);

    PointState by_point = failed;
    try {
        update_point(m, by_point, inc);
        ADD_FAILURE() << "the point update's own energy solve must refuse this step";
    } catch (const std::domain_error& e) {
        EXPECT_NE(std::string(e.what()).find("too large for the energy solve"), std::string::npos) << e.what();
    }

    inc.energy_booked_by_caller = true;
    PointState by_caller = failed;
    const PointResult r = update_point(m, by_caller, inc);
    const EosResult eos = evaluate_eos(m.eos, m.density, inc.density_new, failed.specific_internal_energy);
    EXPECT_EQ(by_caller.specific_internal_energy, failed.specific_internal_energy);  // the caller's to change
    const double expected = std::max(eos.pressure, 0.0);  // no tension once failed
    EXPECT_NEAR(by_caller.pressure, expected, kPointUpdateRoundOff * std::abs(eos.pressure));
    EXPECT_TRUE(std::isfinite(r.sound_speed));
    EXPECT_GT(r.sound_speed, 0.0);
    EXPECT_TRUE(by_caller.failed);
}

TEST(SoundSpeed, ReferenceAndCompressedStates) {
    const Material m = test::copper();
    const double k0 = 8930.0 * 3940.0 * 3940.0;
    const double c_ref = std::sqrt((k0 + 4.0 * m.shear_modulus / 3.0) / m.density);
    EXPECT_NEAR(reference_wave_speed(m), c_ref, kPointUpdateRoundOff * c_ref);

    Driver p(m);
    const PointResult at_rest = p.step(Eigen::Matrix3d::Zero(), 1e-8);
    EXPECT_NEAR(at_rest.sound_speed, c_ref, kPointUpdateRoundOff * c_ref);

    const double rho1 = 1.2 * m.density;
    const PointResult compressed = p.step_to(isotropic(m.density, rho1, 1e-8), 1e-8, rho1);
    const double k_s = evaluate_eos(m.eos, m.density, rho1, p.state.specific_internal_energy).bulk_modulus;
    EXPECT_NEAR(compressed.sound_speed, std::sqrt((k_s + 4.0 * m.shear_modulus / 3.0) / rho1),
                kPointUpdateRoundOff * compressed.sound_speed);
    EXPECT_GT(compressed.sound_speed, c_ref);
}

TEST(PointUpdate, RejectsNonPositiveDensity) {
    const Material m = test::copper();
    PointState state;
    PointIncrement inc;
    inc.dt = 1e-8;
    inc.density_old = m.density;
    inc.density_new = 0.0;
    EXPECT_THROW(update_point(m, state, inc), std::domain_error);
    inc.density_new = m.density;
    inc.dt = -1.0;
    EXPECT_THROW(update_point(m, state, inc), std::domain_error);
}

TEST(PointUpdate, PoleGuardPropagates) {
    // Copper: s = 1.489, guard at mu = 0.9 / (s - 1) = 1.84. Compress in steps of 0.01 rho0.
    const Material m = test::copper();
    Driver p(m);
    double mu = 0.0;
    try {
        for (; mu < 2.5; mu += 0.01) {
            p.step_to(isotropic(p.density, m.density * (1.0 + mu + 0.01), 1e-8), 1e-8, m.density * (1.0 + mu + 0.01));
        }
        FAIL() << "no exception up to mu = 2.5";
    } catch (const std::domain_error& e) {
        EXPECT_NE(std::string(e.what()).find("pole"), std::string::npos) << e.what();
        EXPECT_NEAR(mu + 0.01, 0.9 / 0.489, 0.011);
    }
}

TEST(PointModel, EachFaultLeavesTheStateAsItWasAndSaysWhyAsUpdatePointDoes) {
    // PointModel::update never throws: for each fault it returns PointResult::fault with the state
    // untouched, and fault_message gives the words update_point throws for the same point.
    const Material m = test::copper();
    PointState start;
    start.deviatoric_stress = {1e7, -4e6, -6e6, 0.0, 0.0, 3e6};
    start.pressure = 2e8;
    start.specific_internal_energy = 5e3;
    start.plastic_strain = 0.1;
    start.temperature = 320.0;
    start.damage = 0.2;
    const auto same = [](const PointState& a, const PointState& b) {
        return a.deviatoric_stress == b.deviatoric_stress && a.pressure == b.pressure &&
               a.specific_internal_energy == b.specific_internal_energy && a.plastic_strain == b.plastic_strain &&
               a.temperature == b.temperature && a.damage == b.damage && a.failed == b.failed;
    };
    struct Case {
        const char* name;
        PointFault fault;
        PointIncrement inc;
        bool failed = false;
        const char* words;
    };
    std::vector<Case> cases;
    PointIncrement bad;
    bad.dt = 1e-8;
    bad.density_old = m.density;
    bad.density_new = -1.0;
    cases.push_back({"negative density", PointFault::bad_increment, bad, false, "must be positive and finite"});
    PointIncrement pole;
    pole.dt = 1e-8;
    pole.density_old = m.density;
    pole.density_new = 3.0 * m.density;  // mu = 2 beyond the guard at 1.84
    pole.velocity_gradient = isotropic(pole.density_old, pole.density_new, pole.dt);
    cases.push_back({"beyond the Hugoniot pole", PointFault::eos_limit, pole, false, "Hugoniot pole"});
    PointIncrement crushed;  // a failed node of a fragment cloud (see the Energy test above)
    crushed.dt = 1.6e-9;
    crushed.density_old = m.density / 3.0;
    crushed.density_new = 1.29 * crushed.density_old;
    crushed.velocity_gradient = isotropic(crushed.density_old, crushed.density_new, crushed.dt);
    cases.push_back({"one step too large for the energy solve", PointFault::energy_solve, crushed, true,
                     "too large for the energy solve"});
    const PointModel model(m);
    for (const Case& c : cases) {
        PointState state = start;
        state.failed = c.failed;
        const PointState before = state;
        const PointResult r = model.update(state, c.inc);
        EXPECT_EQ(r.fault, c.fault) << c.name;
        EXPECT_TRUE(same(state, before)) << c.name << ": the state changed";
        const std::string message = model.fault_message(state, c.inc, r);
        EXPECT_NE(message.find(c.words), std::string::npos) << c.name << ": " << message;
        try {
            update_point(m, state, c.inc);
            ADD_FAILURE() << c.name << ": update_point must throw";
        } catch (const std::domain_error& e) {
            EXPECT_EQ(std::string(e.what()), message) << c.name;
        }
        EXPECT_TRUE(same(state, before)) << c.name << ": update_point changed the state";
    }
    PointState state = start;
    PointIncrement fine = pole;
    fine.density_new = 1.01 * m.density;
    fine.velocity_gradient = isotropic(fine.density_old, fine.density_new, fine.dt);
    const PointResult r = model.update(state, fine);
    EXPECT_EQ(r.fault, PointFault::none);
    EXPECT_EQ(model.fault_message(state, fine, r), "");
    EXPECT_FALSE(same(state, start));  // it advanced
}

}  // namespace
}  // namespace gpa::materials
