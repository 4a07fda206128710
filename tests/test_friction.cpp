// Coulomb friction on rigid planes (scene.hpp, PlaneSpec::friction_*; RigidPlanes::apply_friction):
// a block that slides along a plane through the whole of an oblique impact loses tangential
// momentum mu_d times the normal impulse the plane gave it (the Coulomb law integrated over the
// contact), one that would slide more slowly than friction allows is held to no more than that,
// friction does nothing to a block without tangential velocity, and the heat it makes closes the
// energy balance.

#include <cmath>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

// A plane-strain elastic steel block 4 mm x 2 mm resting on a rigid plane at z = 0 (lift-off),
// moving at (tangential, -normal) m/s; the plane has friction mu_s, mu_d.
Scene block_on_plane(double tangential, double normal, double mu_static, double mu_dynamic) {
    Scene s;
    s.geometry = GeometryKind::PlaneStrain;
    s.materials.push_back(testing::elastic_material("steel", 7800.0, 200e9, 0.3));
    BodySpec b;
    b.name = "block";
    b.shape = ShapeKind::Rectangle;
    b.material = "steel";
    b.origin = {0.0, 0.0, 0.0};
    b.size = {4e-3, 2e-3, 0.0};
    b.spacing = 0.25e-3;
    b.velocity = {tangential, -normal, 0.0};
    s.bodies.push_back(b);
    PlaneSpec plane;
    plane.name = "floor";
    plane.axis = 1;
    plane.friction_static = mu_static;
    plane.friction_dynamic = mu_dynamic;
    s.planes.push_back(plane);
    s.stop.max_steps = 100000;
    return s;
}

struct Impact {
    double tangential_momentum_change = 0.0;  // kg m/s per metre of thickness
    double normal_impulse = 0.0;              // the plane's, N s per metre
    double pressing_impulse = 0.0;            // its pressing part (PlaneReport::pressing_impulse)
    double friction_work = 0.0;               // J per metre
    double energy_error = 0.0;
    double final_normal_velocity = 0.0;       // of the block's centre of mass: it has left the plane
};

// Runs the block until it has left the plane (the plane's reaction back to zero after the contact,
// the block moving away): the whole impact.
Impact run(const Scene& scene) {
    Simulation sim(scene, 2);
    const double p0 = sim.totals().momentum[0];
    bool touched = false;
    for (int k = 0; k < 20000; ++k) {
        sim.step();
        const auto& t = sim.totals();
        touched |= t.planes[0].reaction != 0.0;
        if (touched && t.planes[0].reaction == 0.0 && t.momentum[1] > 0.0) break;
    }
    const auto& t = sim.totals();
    EXPECT_TRUE(touched);
    double mass = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) mass += sim.nodes().mass[i];
    return {t.momentum[0] - p0, t.planes[0].impulse, t.planes[0].pressing_impulse, t.planes[0].friction_work, t.energy_error,
            t.momentum[1] / mass};
}

TEST(Friction, ABlockSlidingThroughTheImpactLosesMuTimesTheNormalImpulse) {
    // 30 m/s along the plane, 5 m/s onto it, mu = 0.2: a rigid block would lose at most
    // mu (1 + e) 5 = 2 m/s of its 30 along the plane, so every node slides throughout, and the
    // friction force is mu_d N at every contact node at every step.
    const double mu = 0.2;
    const Impact sliding = run(block_on_plane(30.0, 5.0, mu, mu));
    ASSERT_GT(sliding.normal_impulse, 0.0);
    EXPECT_GT(sliding.final_normal_velocity, 0.0) << "the block left the plane";
    // Sum over steps of the same per-step identity (sum F_t = -mu sum N over the pressed nodes):
    // round-off. The pressing impulse is the plane's normal impulse but for the pull of the few
    // nodes in tension on it (measured: 0.2 % here).
    EXPECT_NEAR(sliding.tangential_momentum_change, -mu * sliding.pressing_impulse, 1e-9 * mu * sliding.pressing_impulse);
    EXPECT_GE(sliding.pressing_impulse, sliding.normal_impulse);
    EXPECT_LT(sliding.pressing_impulse, 1.01 * sliding.normal_impulse);
    EXPECT_GT(sliding.friction_work, 0.0);
    // The compatible update books every force's work; the friction's as heat: the balance closes
    // to round-off (1e-10 of the block's energy, far below the friction's share of it).
    EXPECT_LT(std::abs(sliding.energy_error), 1e-10);

    // Without friction nothing changes along the plane.
    const Impact frictionless = run(block_on_plane(30.0, 5.0, 0.0, 0.0));
    EXPECT_LT(std::abs(frictionless.tangential_momentum_change), 1e-12 * 7800.0 * 8e-6 * 30.0);
    EXPECT_EQ(frictionless.friction_work, 0.0);
}

TEST(Friction, ASlowBlockIsHeldByNoMoreThanTheCoulombLimit) {
    // 0.2 m/s along the plane, 5 m/s onto it, mu_s = mu_d = 0.5: friction could take up to
    // 0.5 (1 + e) 5 m/s: the contact nodes stick, and the tangential impulse stays within
    // mu times the normal one.
    const double mu = 0.5;
    const Impact held = run(block_on_plane(0.2, 5.0, mu, mu));
    ASSERT_GT(held.normal_impulse, 0.0);
    EXPECT_LT(held.tangential_momentum_change, 0.0) << "friction slowed it";
    EXPECT_LT(-held.tangential_momentum_change, mu * held.pressing_impulse * (1.0 - 1e-3)) << "sticking takes less than sliding";
    EXPECT_LT(std::abs(held.energy_error), 1e-10);
    // A block that meets the plane head on spreads sideways on it (Poisson), symmetrically: the
    // friction on its two halves makes heat but no net tangential momentum (to the round-off of a
    // stick-or-slip decision at the threshold: 1e-6 of the block's momentum).
    const Impact head_on = run(block_on_plane(0.0, 5.0, mu, mu));
    EXPECT_GT(head_on.friction_work, 0.0);
    EXPECT_LT(std::abs(head_on.tangential_momentum_change), 1e-6 * 7800.0 * 8e-6 * 5.0);
}

TEST(Friction, IsRefusedWhereItCannotAct) {
    Scene s = block_on_plane(1.0, 1.0, 0.3, 0.4);
    EXPECT_THROW(validate_scene(s), InputError) << "static below dynamic";
    s = block_on_plane(1.0, 1.0, 0.3, 0.3);
    s.planes[0].kind = PlaneKind::Symmetry;
    EXPECT_THROW(validate_scene(s), InputError) << "a symmetry plane";
    s = block_on_plane(1.0, 1.0, 0.3, 0.3);
    s.bodies[0].discretisation = Discretisation::Elements;
    EXPECT_THROW(validate_scene(s), InputError) << "an element body";
    s = block_on_plane(1.0, 1.0, std::nan(""), 0.3);
    EXPECT_THROW(validate_scene(s), InputError);
    EXPECT_NO_THROW(validate_scene(block_on_plane(1.0, 1.0, 0.5, 0.3)));
}

}  // namespace
}  // namespace gpa
