// Plate perforation against measurement: a blunt hardened projectile, 20 mm across and 197 g, onto
// a 12 mm Weldox 460 E plate (scenes/perforation-weldox-460e.toml; Borvik, Langseth, Hopperstad
// and Malo, Int. J. Impact Eng. 22 (1999) 855-886, measured ballistic limit 184.5 m/s).

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa {
namespace {

constexpr double measured_ballistic_limit = 184.5;  // m/s, Borvik et al. (1999), 12 mm plate, blunt projectile

struct Shot {
    double residual_velocity = 0.0;  // m/s, of the projectile's main piece along the impact direction
    bool perforated = false;
    std::size_t plate_pieces = 0;
    double projectile_whole = 0.0;  // the mass share of the projectile's main piece
    double momentum_error = 0.0;  // |p(t) - p(0) - clamp impulse| over |p(0)|, largest over the run
    double energy_error = 0.0;    // largest |energy error| over the run
};

// One shot at the scene's own resolution (0.5 mm, both bodies), stopped 100 us after impact: at
// 250 m/s and above the plug has left by 75 us and the residual velocity has settled to 0.2 %.
Shot fire(double speed) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/perforation-weldox-460e.toml");
    s.bodies[1].velocity = {0.0, -speed, 0.0};
    s.stop.end_time = 100e-6;
    Simulation sim(s, 2);
    const double p0 = sim.totals().momentum[1];
    Shot shot;
    while (!sim.finished()) {
        sim.step();
        const Totals& t = sim.totals();
        shot.momentum_error = std::max(shot.momentum_error, std::abs(t.momentum[1] - p0 - t.regions[0].impulse[1]) / std::abs(p0));
        shot.energy_error = std::max(shot.energy_error, std::abs(t.energy_error));
    }
    sim.measure_bodies();
    const Totals& t = sim.totals();
    shot.residual_velocity = t.bodies[1].residual_speed_along_axis;
    shot.perforated = t.bodies[0].perforated;
    shot.plate_pieces = t.bodies[0].pieces;
    shot.projectile_whole = t.bodies[1].main_piece_mass / t.bodies[1].mass;
    std::printf("%.0f m/s: residual %.2f m/s, perforated %d, plate pieces %zu, %zu steps, energy error %.2g, momentum %.2g\n", speed,
                shot.residual_velocity, shot.perforated ? 1 : 0, shot.plate_pieces, sim.steps(), shot.energy_error,
                shot.momentum_error);
    return shot;
}

TEST(Perforation, TheBallisticLimitOfARechtIpsonFitIsWithinTenPercentOfTheMeasured) {
    // Two speeds well above the limit (1.36 and 1.63 times it), as the experiments' own curve was
    // fitted through residual velocities above it.
    const double v1 = 250.0, v2 = 300.0;
    const Shot a = fire(v1), b = fire(v2);
    for (const Shot* s : {&a, &b}) {
        EXPECT_TRUE(s->perforated) << "a plug must leave the plate";
        EXPECT_GE(s->plate_pieces, 2u) << "the plug is a piece of its own";
        // The hardened projectile stays whole; at its edge, where the plug shears off, a corner node
        // may be torn off (numerical fracture of one node of 3200: docs/validation.md).
        EXPECT_GT(s->projectile_whole, 0.999) << "the projectile broke up";
        // Momentum: pair forces are equal and opposite, so the bodies' momentum changes only by what
        // the clamped rim gives them (round-off over some 8000 steps).
        EXPECT_LT(s->momentum_error, 1e-9);
        // Energy: the clamp does no work (its nodes do not move) and the compatible update books
        // every force's work, so the balance closes to round-off: 1e-9 leaves room for the round-off
        // of 8000 steps, not for a missing term (the plastic work is 60 % of the energy).
        EXPECT_LT(s->energy_error, 1e-9);
    }
    ASSERT_GT(b.residual_velocity, a.residual_velocity);
    ASSERT_GT(a.residual_velocity, 0.0);
    // Recht and Ipson (1963): v_r^2 = a^2 (v^2 - v_bl^2), the form Borvik et al. fitted to their
    // blunt-projectile tests. Through two points: a^2 = (v_r2^2 - v_r1^2) / (v2^2 - v1^2), then v_bl.
    const double a2 = (b.residual_velocity * b.residual_velocity - a.residual_velocity * a.residual_velocity) /
                      (v2 * v2 - v1 * v1);
    const double limit = std::sqrt(v1 * v1 - a.residual_velocity * a.residual_velocity / a2);
    std::printf("Recht-Ipson: a = %.3f, ballistic limit %.1f m/s (measured %.1f m/s, %+.1f %%)\n", std::sqrt(a2), limit,
                measured_ballistic_limit, 100.0 * (limit / measured_ballistic_limit - 1.0));
    // a is the share of momentum the projectile keeps: for a rigid projectile and a plug of the
    // projectile's diameter, a = m_p / (m_p + m_plug) = 197 / (197 + 29.6) = 0.87, less whatever
    // the plate's bending takes; above 1 or far below it the fit would mean nothing.
    EXPECT_GT(std::sqrt(a2), 0.7);
    EXPECT_LT(std::sqrt(a2), 1.0);
    // 10 %, the bound: the material model was fitted to material tests, not to these shots
    // (the energy a plug takes scales with the flow stress, and the limit with its square root), the
    // experiments' own limit is a fit of the same form, and the result moves with the spacing, since
    // the band of failed nodes is one node wide (docs/validation.md: the study at 0.5, 0.35 and
    // 0.25 mm).
    EXPECT_NEAR(limit, measured_ballistic_limit, 0.10 * measured_ballistic_limit);
}

}  // namespace
}  // namespace gpa
