// Equations of state against closed forms (materials.md, "Equation of state"): the linear EOS,
// the Mie-Grueneisen EOS on and off its Hugoniot, its tension branch and pole guard, the EPIC
// polynomial's third-order agreement with the Hugoniot, and the isentropic bulk modulus.

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/materials/material.hpp"

namespace gpa::materials {
namespace {

// Exact formulas evaluated in a handful of flops: agreement to a few ulp, 1e-12 relative.
constexpr double kRoundOff = 1e-12;

struct ShockMaterial {
    const char* name;
    double rho0, c0, s, gamma0;
};

// materials.md, "Shock (Mie-Grueneisen) constants".
const std::vector<ShockMaterial>& shock_table() {
    static const std::vector<ShockMaterial> table = {
        {"OFHC copper", 8930.0, 3940.0, 1.489, 2.02},
        {"4340 steel", 7810.0, 4578.0, 1.33, 1.67},
        {"2024 aluminium", 2785.0, 5328.0, 1.338, 2.0},
        {"iron", 7850.0, 3570.0, 1.92, 1.8},
    };
    return table;
}

// P_H = rho0 c0^2 mu (1 + mu) / (1 - (s - 1) mu)^2, the linear Us-up Hugoniot.
double hugoniot_pressure(const ShockMaterial& m, double mu) {
    const double eta = 1.0 - (m.s - 1.0) * mu;
    return m.rho0 * m.c0 * m.c0 * mu * (1.0 + mu) / (eta * eta);
}

// e_H = P_H mu / (2 rho0 (1 + mu)), the Rankine-Hugoniot energy from rest.
double hugoniot_energy(const ShockMaterial& m, double mu) {
    return hugoniot_pressure(m, mu) * mu / (2.0 * m.rho0 * (1.0 + mu));
}

MieGruneisenEos mie_gruneisen(const ShockMaterial& m) { return {m.c0, m.s, m.gamma0}; }

// K1, K2, K3 from the third-order expansion of the linear Hugoniot (materials.md).
PolynomialEos polynomial_from_shock(const ShockMaterial& m) {
    const double k1 = m.rho0 * m.c0 * m.c0;
    return {k1, k1 * (2.0 * m.s - 1.0), k1 * (m.s - 1.0) * (3.0 * m.s - 1.0), m.gamma0};
}

TEST(LinearEos, PressureAndBulkModulus) {
    const double k = 137e9, rho0 = 8930.0;
    for (double mu : {-0.2, -0.01, 0.0, 0.03, 0.4}) {
        const double rho = rho0 * (1.0 + mu);
        const EosResult lin = evaluate_eos(LinearEos{k, false}, rho0, rho, 1e6);
        EXPECT_NEAR(lin.pressure, k * mu, kRoundOff * k);
        EXPECT_EQ(lin.energy_coefficient, 0.0);
        EXPECT_NEAR(lin.bulk_modulus, k * (1.0 + mu), kRoundOff * k);  // rho dP/drho = K rho / rho0

        const EosResult log = evaluate_eos(LinearEos{k, true}, rho0, rho, 1e6);
        EXPECT_NEAR(log.pressure, k * std::log(1.0 + mu), kRoundOff * k);
        EXPECT_NEAR(log.bulk_modulus, k, kRoundOff * k);  // rho d(K ln rho)/drho = K
    }
}

TEST(MieGruneisenEos, PressureOnTheHugoniotIsTheHugoniotPressure) {
    // With e = e_H(mu) the Gruneisen correction cancels the subtracted Hugoniot energy exactly.
    for (const ShockMaterial& m : shock_table()) {
        for (double mu : {1e-3, 0.01, 0.1, 0.3, 0.5}) {
            const double p_h = hugoniot_pressure(m, mu);
            const EosResult r = evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 + mu), hugoniot_energy(m, mu));
            EXPECT_NEAR(r.pressure, p_h, kRoundOff * p_h) << m.name << " mu=" << mu;
        }
    }
}

TEST(MieGruneisenEos, OffTheHugoniotPressureMovesByGammaRhoTimesEnergy) {
    for (const ShockMaterial& m : shock_table()) {
        for (double mu : {0.05, 0.2}) {
            const double e_h = hugoniot_energy(m, mu);
            const double rho = m.rho0 * (1.0 + mu);
            for (double de : {-2e5, 3e5, 1e6}) {
                const EosResult r = evaluate_eos(mie_gruneisen(m), m.rho0, rho, e_h + de);
                // Gamma rho = Gamma0 rho0 (materials.md): dP/de = Gamma0 rho0 at every density.
                EXPECT_NEAR(r.energy_coefficient, m.gamma0 * m.rho0, kRoundOff * m.gamma0 * m.rho0);
                const double expected = hugoniot_pressure(m, mu) + m.gamma0 * m.rho0 * de;
                EXPECT_NEAR(r.pressure, expected, kRoundOff * std::abs(hugoniot_pressure(m, mu))) << m.name;
            }
        }
    }
}

TEST(MieGruneisenEos, TensionBranchIsLinear) {
    for (const ShockMaterial& m : shock_table()) {
        const double k0 = m.rho0 * m.c0 * m.c0;
        for (double mu : {-0.3, -0.05, -1e-4}) {
            for (double e : {0.0, 2e5}) {
                const EosResult r = evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 + mu), e);
                EXPECT_NEAR(r.pressure, k0 * mu + m.gamma0 * m.rho0 * e, kRoundOff * k0) << m.name;
            }
        }
    }
}

TEST(MieGruneisenEos, PressureAndBulkModulusAreContinuousAtZeroStrain) {
    // Both branches start with slope rho0 c0^2; a 1e-9 step in mu changes P by ~1e-9 K0 and K_s by
    // ~1e-9 (2s + Gamma0) K0: tolerance 1e-8 K0.
    for (const ShockMaterial& m : shock_table()) {
        const double k0 = m.rho0 * m.c0 * m.c0;
        const EosResult below = evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 - 1e-9), 1e4);
        const EosResult above = evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 + 1e-9), 1e4);
        EXPECT_NEAR(below.pressure, above.pressure, 1e-8 * k0);
        EXPECT_NEAR(below.bulk_modulus, above.bulk_modulus, 1e-8 * k0);
    }
}

TEST(MieGruneisenEos, PoleGuardThrowsNamingMuAndTheLimit) {
    for (const ShockMaterial& m : shock_table()) {
        const double pole = 1.0 / (m.s - 1.0);
        const double limit = 0.9 * pole;  // the documented 10 % margin (eos.cpp)
        const std::string limit_text = fmt::format("mu = {:.6g}", limit);
        for (double mu : {pole, 1.0001 * limit, 1.5 * pole}) {
            try {
                (void)evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 + mu), 0.0);
                ADD_FAILURE() << m.name << ": no exception at mu = " << mu;
            } catch (const std::domain_error& e) {
                const std::string what = e.what();
                EXPECT_NE(what.find(fmt::format("mu = {:.6g}", mu)), std::string::npos) << what;
                EXPECT_NE(what.find(limit_text), std::string::npos) << what;
            }
        }
        EXPECT_NO_THROW((void)evaluate_eos(mie_gruneisen(m), m.rho0, m.rho0 * (1.0 + 0.999 * limit), 0.0)) << m.name;
    }
    // s <= 1 has no pole in compression.
    const EosResult r = evaluate_eos(MieGruneisenEos{4000.0, 0.9, 1.5}, 5000.0, 5000.0 * 6.0, 0.0);
    EXPECT_TRUE(std::isfinite(r.pressure));
    EXPECT_GT(r.pressure, 0.0);
}

TEST(PolynomialEos, MatchesTheHugoniotToThirdOrder) {
    // P_poly - P_H = (K(mu) - P_H) g(mu) on the Hugoniot energy, and
    // P_H / K1 = mu + (2s-1) mu^2 + (s-1)(3s-1) mu^3 + c4 mu^4 + c5 mu^5 + ..., with
    // c4 = 4 (s-1)^3 + 3 (s-1)^2 and c5 = 5 (s-1)^4 + 4 (s-1)^3. So the error over -K1 c4 mu^4 g
    // is 1 + (c5 / c4) mu + O(mu^2): within 2 % at mu <= 0.01 for these s (c5/c4 <= 1.3), and
    // halving mu divides the error by 16 within 2 %.
    for (const ShockMaterial& m : shock_table()) {
        const PolynomialEos poly = polynomial_from_shock(m);
        const double x = m.s - 1.0;
        const double c4 = 4.0 * x * x * x + 3.0 * x * x;
        auto error = [&](double mu) {
            const double rho = m.rho0 * (1.0 + mu);
            return evaluate_eos(poly, m.rho0, rho, hugoniot_energy(m, mu)).pressure - hugoniot_pressure(m, mu);
        };
        for (double mu : {0.01, 0.005, 0.0025}) {
            const double g = 1.0 - m.gamma0 * mu / (2.0 * (1.0 + mu));
            const double leading = -poly.k1 * c4 * mu * mu * mu * mu * g;
            EXPECT_NEAR(error(mu) / leading, 1.0, 0.02) << m.name << " mu=" << mu;
        }
        EXPECT_NEAR(error(0.01) / error(0.005), 16.0, 16.0 * 0.02) << m.name;
    }
}

TEST(PolynomialEos, TensionBranchIsLinear) {
    const PolynomialEos poly{140e9, 200e9, 90e9, 2.0};
    const double rho0 = 8930.0;
    for (double mu : {-0.2, -0.01}) {
        const EosResult r = evaluate_eos(poly, rho0, rho0 * (1.0 + mu), 3e5);
        EXPECT_NEAR(r.pressure, poly.k1 * mu + poly.gruneisen * rho0 * 3e5, kRoundOff * poly.k1);
        EXPECT_NEAR(r.energy_coefficient, poly.gruneisen * rho0, kRoundOff * rho0);
    }
}

// K_s = rho dP/drho|_e + (P/rho) dP/de checked against a central difference of P at fixed e.
// Step h = 1e-5 rho: truncation h^2 P''' / 6 is ~1e-10 relative for these smooth curves, round-off
// ~eps |P| / h ~1e-11 relative; tolerance 1e-7 relative. Skipped where the floor is active.
TEST(Eos, IsentropicBulkModulusMatchesFiniteDifference) {
    for (const ShockMaterial& m : shock_table()) {
        const std::vector<EquationOfState> models = {mie_gruneisen(m), polynomial_from_shock(m)};
        for (const EquationOfState& eos : models) {
            for (double mu : {-0.15, -0.02, 0.02, 0.2, 0.45}) {
                for (double e : {0.0, 4e5}) {
                    const double rho = m.rho0 * (1.0 + mu);
                    const double h = 1e-5 * rho;
                    const EosResult r = evaluate_eos(eos, m.rho0, rho, e);
                    const double dp_drho = (evaluate_eos(eos, m.rho0, rho + h, e).pressure -
                                            evaluate_eos(eos, m.rho0, rho - h, e).pressure) /
                                           (2.0 * h);
                    const double expected = rho * dp_drho + r.pressure / rho * r.energy_coefficient;
                    ASSERT_GT(expected, 0.01 * m.rho0 * m.c0 * m.c0);
                    EXPECT_NEAR(r.bulk_modulus, expected, 1e-7 * expected) << m.name << " mu=" << mu;
                }
            }
        }
    }
}

TEST(Eos, BulkModulusStaysPositiveAndIsFlooredInDeepTension) {
    for (const ShockMaterial& m : shock_table()) {
        const double k0 = m.rho0 * m.c0 * m.c0;
        const std::vector<EquationOfState> models = {mie_gruneisen(m), polynomial_from_shock(m)};
        for (const EquationOfState& eos : models) {
            for (double mu = -0.6; mu <= 0.8; mu += 0.05) {
                for (double e : {0.0, 1e5, 1e6}) {
                    const EosResult r = evaluate_eos(eos, m.rho0, m.rho0 * (1.0 + mu), e);
                    EXPECT_GE(r.bulk_modulus, 0.01 * k0) << m.name << " mu=" << mu << " e=" << e;
                }
            }
            // At mu = -0.5, e = 0: K_s = K0 (0.5 + Gamma0 (-0.5) / 0.5) < 0 for Gamma0 > 0.5: floored.
            const EosResult deep = evaluate_eos(eos, m.rho0, 0.5 * m.rho0, 0.0);
            EXPECT_NEAR(deep.bulk_modulus, 0.01 * k0, kRoundOff * k0) << m.name;
        }
    }
}

TEST(Eos, RejectsNonPositiveDensity) {
    EXPECT_THROW((void)evaluate_eos(LinearEos{1e9, false}, 1000.0, 0.0, 0.0), std::domain_error);
    EXPECT_THROW((void)evaluate_eos(LinearEos{1e9, true}, 1000.0, -5.0, 0.0), std::domain_error);
}

}  // namespace
}  // namespace gpa::materials
