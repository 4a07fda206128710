// Johnson-Cook damage and spall (materials.md, "Fracture"): the failure strain and its floor,
// damage accumulation, failure at D >= 1 (no deviator, no tension afterwards), spall only when
// failure is enabled.

#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "material_fixtures.hpp"

namespace gpa::materials {
namespace {

using test::Driver;
using test::pure_shear;
using test::von_mises;

// Exact formulas evaluated in a handful of flops: agreement to a few ulp, 1e-12 relative.
constexpr double kFailureRoundOff = 1e-12;

// materials.md, Johnson-Cook fracture constants.
const JohnsonCookFailure kCopperFracture{0.54, 4.89, -3.03, 0.014, 1.12, 1.0, 0.01};
const JohnsonCookFailure kIronFracture{-2.20, 5.43, -0.47, 0.016, 0.63, 1.0, 0.01};

// The closed form of materials.md, with epsdot* = max(epsdot / epsdot0, 1) written out (no floor
// at min_failure_strain: the tests apply it where they need it).
double eps_f_closed_form(const JohnsonCookFailure& f, double sigma_star, double rate, double t_star) {
    const double rate_ratio = std::max(rate / f.reference_strain_rate, 1.0);
    return (f.d1 + f.d2 * std::exp(f.d3 * sigma_star)) * (1.0 + f.d4 * std::log(rate_ratio)) * (1.0 + f.d5 * t_star);
}

TEST(JohnsonCookFailureStrain, MatchesClosedForm) {
    for (double sigma_star : {-0.5, 0.0, 1.0 / 3.0, 0.8}) {
        for (double rate : {1.0, 1e3}) {
            for (double t_star : {0.0, 0.4}) {
                const double expected = eps_f_closed_form(kCopperFracture, sigma_star, rate, t_star);
                EXPECT_NEAR(johnson_cook_failure_strain(kCopperFracture, sigma_star, rate, t_star), expected,
                            kFailureRoundOff * expected);
            }
        }
    }
}

TEST(JohnsonCookFailureStrain, FloorAndGuards) {
    // Armco iron: D1 + D2 exp(D3 sigma*) < 0 for sigma* > ln(5.43 / 2.2) / 0.47 = 1.9224; at 1.92 it lies in (0, 0.01).
    const double raw = eps_f_closed_form(kIronFracture, 2.5, 1.0, 0.0);
    ASSERT_LT(raw, 0.0);
    EXPECT_EQ(johnson_cook_failure_strain(kIronFracture, 2.5, 1.0, 0.0), 0.01);
    EXPECT_EQ(johnson_cook_failure_strain(kIronFracture, 10.0, 1e4, 0.5), 0.01);
    // Below the floor but positive: floored too.
    const double small = eps_f_closed_form(kIronFracture, 1.92, 1.0, 0.0);
    ASSERT_GT(small, 0.0);
    ASSERT_LT(small, 0.01);
    EXPECT_EQ(johnson_cook_failure_strain(kIronFracture, 1.92, 1.0, 0.0), 0.01);
    // Rate below the reference (and zero) behaves as the reference rate: no log of 0.
    const double at_reference = johnson_cook_failure_strain(kCopperFracture, 0.3, 1.0, 0.2);
    EXPECT_EQ(johnson_cook_failure_strain(kCopperFracture, 0.3, 1e-3, 0.2), at_reference);
    EXPECT_EQ(johnson_cook_failure_strain(kCopperFracture, 0.3, 0.0, 0.2), at_reference);
    // T* clamped to [0, 1].
    EXPECT_EQ(johnson_cook_failure_strain(kCopperFracture, 0.3, 1.0, -1.0),
              johnson_cook_failure_strain(kCopperFracture, 0.3, 1.0, 0.0));
    EXPECT_EQ(johnson_cook_failure_strain(kCopperFracture, 0.3, 1.0, 3.0),
              johnson_cook_failure_strain(kCopperFracture, 0.3, 1.0, 1.0));
}

// Copper strength with a linear EOS, no heating (T* = 0 throughout) and a fracture set with a
// small failure strain: in pure shear P = 0, sigma* = 0, eps_f = (D1 + D2)(1 + D4 ln epsdot*), with
// epsdot* the step's equivalent plastic strain rate d eps_p / dt over epsdot0.
Material shear_failure_material() {
    Material m = test::copper_linear();
    m.specific_heat = 0.0;
    m.failure.johnson_cook = JohnsonCookFailure{0.05, 0.05, -1.5, 0.01, 0.5, 1.0, 0.01};
    return m;
}

TEST(Damage, AccumulatesPlasticStrainOverFailureStrainAndFailsAtOne) {
    const Material m = shear_failure_material();
    const JohnsonCookFailure& f = *m.failure.johnson_cook;
    Driver p(m);
    p.failure_enabled = true;
    const double gamma_dot = 1e3, dt = 1e-7;
    const double total_rate = gamma_dot / std::sqrt(3.0);
    // D = sum d eps_p / eps_f(sigma* = 0, d eps_p / dt, T* = 0), step by step: eps_f follows the plastic
    // rate, which is below the total rate (part of each hardening step's strain is elastic) and
    // varies along the path.
    double expected_damage = 0.0;
    double eps_f_min = std::numeric_limits<double>::infinity(), eps_f_max = 0.0;
    double eps_before_failure_step = 0.0;
    int failure_step = -1;
    for (int step = 0; step < 10000 && failure_step < 0; ++step) {
        const double damage_before = p.state.damage;
        const double eps_before = p.state.plastic_strain;
        const PointResult r = p.step(pure_shear(gamma_dot), dt);
        EXPECT_EQ(p.state.pressure, 0.0);
        const double d_eps = p.state.plastic_strain - eps_before;
        EXPECT_NEAR(r.plastic_strain_rate * dt, d_eps, test::increment_read_back_tolerance(p.state.plastic_strain));
        if (d_eps > 0.0) {
            EXPECT_LT(r.plastic_strain_rate, total_rate);
            const double eps_f = eps_f_closed_form(f, 0.0, d_eps / dt, 0.0);
            eps_f_min = std::min(eps_f_min, eps_f);
            eps_f_max = std::max(eps_f_max, eps_f);
            expected_damage += d_eps / eps_f;
        }
        // Sums of a few thousand terms, each rounded once as in the library; d eps_p read back from
        // the stored plastic strain telescopes, so the increments' read-back errors do not add up.
        EXPECT_NEAR(p.state.damage, expected_damage, kFailureRoundOff * std::max(expected_damage, 1e-3));
        if (r.failed_now) {
            failure_step = step;
            eps_before_failure_step = eps_before;
            EXPECT_LT(damage_before, 1.0);
            EXPECT_GE(p.state.damage, 1.0);
            EXPECT_TRUE(p.state.failed);
        } else {
            EXPECT_FALSE(p.state.failed);
        }
    }
    ASSERT_GT(failure_step, 0);
    // eps_f varies along the path (from the first-yield step's slow plastic rate, ~3 /s, to nearly
    // the total rate, 577 /s: eps_f from ~0.1012 to ~0.1064), and D = 1 is reached between the
    // bounds it implies:
    // eps_p / eps_f_max <= D <= eps_p / eps_f_min, with D < 1 before the last step and D >= 1 after it.
    EXPECT_GT(eps_f_max - eps_f_min, 1e-3);
    EXPECT_GE(p.state.plastic_strain, eps_f_min);
    EXPECT_LT(eps_before_failure_step, eps_f_max);
    // The damage differs from that with the old total-rate eps_f by far more than the tolerance above.
    EXPECT_GT(std::abs(p.state.damage - p.state.plastic_strain / eps_f_closed_form(f, 0.0, total_rate, 0.0)),
              1e3 * kFailureRoundOff);
    // Failed: no deviator, shear modulus gone from the sound speed.
    EXPECT_EQ(von_mises(p.state.deviatoric_stress), 0.0);

    // Further shear: no deviator, no plastic strain, no plastic work; sound speed is bulk only.
    const double eps_at_failure = p.state.plastic_strain;
    const PointResult r = p.step(pure_shear(gamma_dot), dt);
    EXPECT_FALSE(r.failed_now);
    EXPECT_EQ(r.plastic_strain_rate, 0.0);
    EXPECT_EQ(von_mises(p.state.deviatoric_stress), 0.0);
    EXPECT_EQ(p.state.plastic_strain, eps_at_failure);
    EXPECT_EQ(r.plastic_work, 0.0);
    const double k_s = evaluate_eos(m.eos, m.density, p.density, p.state.specific_internal_energy).bulk_modulus;
    EXPECT_NEAR(r.sound_speed, std::sqrt(k_s / p.density), kFailureRoundOff * r.sound_speed);

    // No tension: expanding gives P = 0, not K mu < 0; compression still carries pressure.
    p.step_to(Eigen::Matrix3d::Zero(), dt, 0.98 * m.density);
    EXPECT_EQ(p.state.pressure, 0.0);
    const double k = std::get<LinearEos>(m.eos).bulk_modulus;
    p.step_to(Eigen::Matrix3d::Zero(), dt, 1.01 * m.density);
    EXPECT_NEAR(p.state.pressure, 0.01 * k, kFailureRoundOff * k);
    EXPECT_TRUE(p.state.failed);
}

TEST(Damage, NothingAccumulatesWhenFailureIsDisabled) {
    Driver p(shear_failure_material());
    p.failure_enabled = false;
    for (int step = 0; step < 3000; ++step) {  // eps_p ~ 0.17 > eps_f ~ 0.106
        EXPECT_FALSE(p.step(pure_shear(1e3), 1e-7).failed_now);
    }
    EXPECT_GT(p.state.plastic_strain, 0.15);
    EXPECT_EQ(p.state.damage, 0.0);
    EXPECT_FALSE(p.state.failed);
    EXPECT_GT(von_mises(p.state.deviatoric_stress), 0.0);
}

TEST(Damage, UsesTriaxialityFromPressureAndVonMisesStress) {
    // Hold the density at 0.99 rho0 (tension, P = -0.01 K) and shear one plastic step:
    // sigma* = -P / sigma_vm with the end-of-step values.
    Material m = shear_failure_material();
    Driver p(m);
    p.failure_enabled = true;
    p.density = 0.99 * m.density;
    p.state.pressure = std::get<LinearEos>(m.eos).bulk_modulus * -0.01;
    const double gamma_dot = 1e4, dt = 1e-6;
    const PointResult r = p.step_to(pure_shear(gamma_dot), dt, p.density);
    const double d_eps = p.state.plastic_strain;  // from eps_p = 0: the stored value is the increment itself
    ASSERT_GT(d_eps, 0.0);
    const double sigma_star = -p.state.pressure / von_mises(p.state.deviatoric_stress);
    EXPECT_GT(sigma_star, 1.0);  // 1.4 GPa of tension over ~100 MPa of flow stress
    // eps_f at the step's plastic rate d eps_p / dt (above epsdot0, so D4 acts; below the total rate).
    const double rate = d_eps / dt;
    EXPECT_NEAR(r.plastic_strain_rate, rate, kFailureRoundOff * rate);
    EXPECT_GT(rate, m.failure.johnson_cook->reference_strain_rate);
    EXPECT_LT(rate, gamma_dot / std::sqrt(3.0));
    const double eps_f = eps_f_closed_form(*m.failure.johnson_cook, sigma_star, rate, 0.0);
    EXPECT_NEAR(p.state.damage, d_eps / std::max(eps_f, 0.01), kFailureRoundOff * p.state.damage);
}

TEST(Damage, TriaxialityIsZeroWhereVonMisesStressVanishes) {
    // Molten copper (Y = 0, so sigma_vm = 0 after the return) in tension: sigma* is defined as 0, so
    // eps_f = (D1 + D2)(1 + D4 ln epsdot*)(1 + D5 T*) with T* = 1, finite and positive.
    Material m = shear_failure_material();
    Driver p(m);
    p.failure_enabled = true;
    p.state.temperature = 2000.0;
    p.density = 0.99 * m.density;
    p.state.pressure = std::get<LinearEos>(m.eos).bulk_modulus * -0.01;
    const double gamma_dot = 1e3, dt = 1e-7;
    p.step_to(pure_shear(gamma_dot), dt, p.density);
    // Y = 0: all the trial strain is plastic, so the plastic rate d eps_p / dt is the total gamma_dot / sqrt(3).
    const double rate = gamma_dot / std::sqrt(3.0);
    const double eps_f = (0.05 + 0.05) * (1.0 + 0.01 * std::log(rate)) * (1.0 + 0.5);
    ASSERT_GT(p.state.plastic_strain, 0.0);
    EXPECT_EQ(von_mises(p.state.deviatoric_stress), 0.0);
    EXPECT_NEAR(p.state.damage, p.state.plastic_strain / eps_f, kFailureRoundOff * p.state.damage);
}

// Elastic copper-like point with a spall pressure of 1 GPa; P = K mu with K = 138.6 GPa.
Material spall_material() {
    Material m = test::copper_linear();
    m.strength = ElasticStrength{};
    m.failure.spall_pressure = 1e9;
    return m;
}

TEST(Spall, TriggersBelowMinusSpallPressureOnlyWhenEnabled) {
    const Material m = spall_material();
    const double k = std::get<LinearEos>(m.eos).bulk_modulus;
    const double mu_above = -0.9e9 / k, mu_below = -1.1e9 / k;
    for (bool enabled : {false, true}) {
        Driver p(m);
        p.failure_enabled = enabled;
        p.state.deviatoric_stress = {1e7, -1e7, 0.0, 0.0, 0.0, 2e6};
        PointResult r = p.step_to(Eigen::Matrix3d::Zero(), 1e-8, m.density * (1.0 + mu_above));
        EXPECT_FALSE(r.failed_now);
        EXPECT_NEAR(p.state.pressure, -0.9e9, kFailureRoundOff * k);
        r = p.step_to(Eigen::Matrix3d::Zero(), 1e-8, m.density * (1.0 + mu_below));
        if (enabled) {
            EXPECT_TRUE(r.failed_now);
            EXPECT_TRUE(p.state.failed);
            EXPECT_EQ(p.state.pressure, 0.0);  // no tension once failed
            EXPECT_EQ(von_mises(p.state.deviatoric_stress), 0.0);
            EXPECT_NEAR(r.sound_speed,
                        std::sqrt(evaluate_eos(m.eos, m.density, p.density, 0.0).bulk_modulus / p.density),
                        kFailureRoundOff * r.sound_speed);
        } else {
            EXPECT_FALSE(r.failed_now);
            EXPECT_FALSE(p.state.failed);
            EXPECT_NEAR(p.state.pressure, -1.1e9, kFailureRoundOff * k);
            EXPECT_GT(von_mises(p.state.deviatoric_stress), 0.0);
        }
    }
}

}  // namespace
}  // namespace gpa::materials
