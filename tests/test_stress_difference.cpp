// The stress-difference form of the momentum equation (the paper's Eq. 28; kernels.hpp,
// stress_difference_term; docs/surfaces.md), selectable beside the pairwise form (Eq. 21-24, the
// paper's Eq. 29) as solver.force_form = "stress-difference". What it is for: a uniform stress
// exerts no force on any node whose neighbourhood is not one-sided, however disordered, where the
// pairwise form's forces only cancel on symmetric neighbourhoods. What it needs: at a free surface
// the missing side's zero stress (the completion), without which a loaded face would feel nothing.
// What it gives up: nothing is equal and opposite, so momentum is not conserved.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "support/lattices.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

// A plane-strain block of 7 x 7 unit cells (a = 1, the GPA weight, variable connectivity) under a
// stress, optionally jittered; the gradient pass sets the factors, then the forces of either form.
struct Block {
    NodeStore nodes;
    CompressedRows lists;
    bool full = false;

    Block(double jitter, bool moment_matrix, std::uint64_t seed = 7) : nodes(testing::make_lattice(testing::unit_cells(7))), full(moment_matrix) {
        if (jitter > 0.0) testing::jitter(nodes, jitter, 1.0, seed);
        lists = find_neighbours(nodes, 1.0, nodes.size());
        auto f = gradient_fields<2>(nodes, 1.0);
        f.full_normalisation = moment_matrix;
        compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, f);
    }

    // sigma = s - P I with s and P set from a Cauchy stress (xx, zz, xz, yy), per node.
    template <class Stress>
    void set_stress(Stress&& at) {
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const std::array<double, 4> s = at(nodes.position[0][i], nodes.position[1][i]);
            const double p = -(s[0] + s[1] + s[3]) / 3.0;
            nodes.pressure[i] = p;
            nodes.deviatoric_stress[0][i] = s[0] + p;
            nodes.deviatoric_stress[1][i] = s[1] + p;
            nodes.deviatoric_stress[2][i] = s[2];
            nodes.deviatoric_stress[3][i] = s[3] + p;
        }
    }

    void forces(bool stress_difference) {
        auto f = force_fields<2>(nodes, 1.0);
        f.full_normalisation = full;
        f.stress_difference = stress_difference;
        f.hoop_count = nodes.size();
        compute_forces<PlaneStrain>(lists, make_serial_plan(lists), WeightKind::Gpa, nullptr, f, nodes.size());
    }

    // The interior: nodes two cells or more inside every face (their neighbourhoods are whole).
    bool interior(std::size_t i) const {
        const double x = nodes.position[0][i], z = nodes.position[1][i];
        return x > 2.0 && x < 5.0 && z > 2.0 && z < 5.0;
    }
};

TEST(StressDifference, AUniformStressExertsNoForceInsideADisorderedBody) {
    for (const bool full : {false, true}) {
        SCOPED_TRACE(full ? "moment matrix" : "per-direction");
        Block b(0.2, full);
        b.set_stress([](double, double) { return std::array<double, 4>{-0.3, -1.0, 0.4, -0.5}; });
        b.forces(true);
        double largest_difference = 0.0;
        for (std::size_t i = 0; i < b.nodes.size(); ++i) {
            if (!b.interior(i)) continue;
            largest_difference = std::max({largest_difference, std::abs(b.nodes.force[0][i]), std::abs(b.nodes.force[1][i])});
        }
        b.forces(false);
        double largest_pairwise = 0.0;
        for (std::size_t i = 0; i < b.nodes.size(); ++i) {
            if (!b.interior(i)) continue;
            largest_pairwise = std::max({largest_pairwise, std::abs(b.nodes.force[0][i]), std::abs(b.nodes.force[1][i])});
        }
        std::printf("[ measured ] uniform stress of scale 1 on a block jittered by 0.2 d, largest interior force: "
                    "stress difference %.2g, pairwise %.2g\n", largest_difference, largest_pairwise);
        EXPECT_LT(largest_difference, 1e-14);  // sigma_j - sigma_i is exactly zero
        EXPECT_GT(largest_pairwise, 1e-2);     // the pairwise form cancels on symmetric neighbourhoods only
    }
}

TEST(StressDifference, ALinearStressGivesEachInteriorNodeItsVolumeTimesTheDivergence) {
    // sigma_zz = 2 z, sigma_xz = -z: div sigma = (-1, 2). The moment matrix makes the operator
    // exact for affine fields on any neighbourhood, so the interior force is V (-1, 2) to round-off.
    Block b(0.2, true);
    b.set_stress([](double, double z) { return std::array<double, 4>{0.0, 2.0 * z, -z, 0.0}; });
    b.forces(true);
    for (std::size_t i = 0; i < b.nodes.size(); ++i) {
        if (!b.interior(i)) continue;
        EXPECT_NEAR(b.nodes.force[0][i], -b.nodes.volume[i], 1e-12);
        EXPECT_NEAR(b.nodes.force[1][i], 2.0 * b.nodes.volume[i], 1e-12);
    }
}

TEST(StressDifference, AFreeFaceCarriesItsTractionThroughTheCompletion) {
    // The paper's lattice under sigma_z = -1: a cell at the free top face is pushed up by the
    // compressed material below with the stress times its width, +1, and a cell at the bottom face
    // down with -1; a side face and the rest feel nothing along z. Eq. 28 alone (no completion)
    // would give the top face nothing: its neighbours' stress equals its own. Exact on the faces
    // under either normalisation and at the corners under the per-direction factors.
    for (const bool full : {false, true}) {
        SCOPED_TRACE(full ? "moment matrix" : "per-direction");
        Block b(0.0, full);
        b.set_stress([](double, double) { return std::array<double, 4>{0.0, -1.0, 0.0, 0.0}; });
        b.forces(true);
        for (std::size_t i = 0; i < b.nodes.size(); ++i) {
            const double x = b.nodes.position[0][i], z = b.nodes.position[1][i];
            const bool corner = (x < 1.0 || x > 6.0) && (z < 1.0 || z > 6.0);
            const double expected_z = z > 6.0 ? 1.0 : z < 1.0 ? -1.0 : 0.0;
            if (corner && full) {
                // The full normalisation of a corner's three neighbours couples x and z: the
                // completed sum gives 0.815 (the moment-matrix surface correction's 1.229 at the
                // same corner is the like of it).
                EXPECT_NEAR(std::abs(b.nodes.force[1][i]), 0.8153, 1e-4) << "node at (" << x << ", " << z << ")";
                continue;
            }
            EXPECT_NEAR(b.nodes.force[1][i], expected_z, 1e-12) << "node at (" << x << ", " << z << ")";
            if (!corner) {
                EXPECT_NEAR(b.nodes.force[0][i], 0.0, 1e-12) << "node at (" << x << ", " << z << ")";
            }
        }
    }
}

// A prestressed copper bar with a conical nose, free in space and at rest, under each form: the
// pairwise forces keep its momentum at zero; the stress-difference forces do not.
TEST(StressDifference, MomentumIsNotConservedAndTheRunIsThreadIndependent) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/taylor-copper-190.toml");
    s.geometry = GeometryKind::PlaneStrain;
    auto& bar = s.bodies[0];  // a plane-strain bar with a conical nose: no symmetry along z
    bar.radius = 3e-3;
    bar.length = 8e-3;
    bar.nose = NoseSpec{NoseKind::Cone, 4e-3, 0.0, -1};
    bar.spacing = 0.5e-3;
    bar.velocity = {0.0, 0.0, 0.0};
    bar.initial_stress = {-200e6, 100e6, 50e6, 0.0};
    s.planes.clear();
    s.stop.kinetic_energy_fraction = 0.0;
    s.stop.end_time = 1.0;
    double drift[2] = {0.0, 0.0};
    for (const ForceForm form : {ForceForm::Pairwise, ForceForm::StressDifference}) {
        s.solver.force_form = form;
        Simulation run(s, 2);
        double mass = 0.0;
        for (std::size_t i = 0; i < run.real_count(); ++i) mass += run.nodes().mass[i];
        for (int k = 0; k < 200; ++k) run.step();
        const auto& p = run.totals().momentum;
        // Momentum over the scale of the motion: the mass times the largest speed.
        double fastest = 0.0;
        for (std::size_t i = 0; i < run.real_count(); ++i) {
            fastest = std::max(fastest, std::hypot(run.nodes().velocity[0][i], run.nodes().velocity[1][i]));
        }
        drift[form == ForceForm::StressDifference] = std::hypot(p[0], p[1]) / (mass * fastest);
        if (form == ForceForm::StressDifference) {
            Simulation one(s, 1);
            for (int k = 0; k < 200; ++k) one.step();
            EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(run));
        }
    }
    std::printf("[ measured ] a free prestressed nosed bar after 200 steps: |momentum| / (mass x largest speed) %.2g pairwise, "
                "%.2g stress difference\n", drift[0], drift[1]);
    EXPECT_LT(drift[0], 1e-13);
    EXPECT_GT(drift[1], 1e-6);
}

// A plane-strain copper block closed on every side (symmetry planes at x = 0 and x = W, rigid
// walls without lift-off at z = 0 and z = H), moving along x at 20 m/s: it runs into its mirror
// image at x = W and away from the one at x = 0, and rings between them. The pairwise form
// conserves its energy to round-off. The stress-difference form ties the forces' work to nothing
// (docs/surfaces.md) and its energy drifts, but with no free surface the drift stays bounded: it
// settles within the first microseconds and then holds for 40 us (some ten round trips of the
// wave, 900 steps at the finer spacing), and it halves with the spacing, a discretisation error.
// (With a free surface a mode grows from it with an e-folding time of about 0.2 us: docs/surfaces.md.)
TEST(StressDifference, EnergyStaysBoundedInABlockClosedOnEverySide) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/taylor-copper-190.toml");
    s.geometry = GeometryKind::PlaneStrain;
    auto& block = s.bodies[0];
    block.shape = ShapeKind::Rectangle;
    block.origin = {0.0, 0.0, 0.0};
    block.size = {4e-3, 4e-3, 0.0};
    block.velocity = {20.0, 0.0, 0.0};
    s.planes.clear();
    const auto plane = [](const char* name, PlaneKind kind, int axis, double position, int facing) {
        PlaneSpec p;
        p.name = name;
        p.kind = kind;
        p.axis = axis;
        p.position = position;
        p.side = facing;
        p.lift_off = false;
        return p;
    };
    s.planes.push_back(plane("left", PlaneKind::Symmetry, 0, 0.0, +1));
    s.planes.push_back(plane("right", PlaneKind::Symmetry, 0, 4e-3, -1));
    s.planes.push_back(plane("floor", PlaneKind::Rigid, 1, 0.0, +1));
    s.planes.push_back(plane("ceiling", PlaneKind::Rigid, 1, 4e-3, -1));
    s.stop.kinetic_energy_fraction = 0.0;
    s.stop.energy_error = 0.0;  // the guard would stop the stress-difference runs
    s.stop.end_time = 40e-6;
    struct Drift {
        double largest = 0.0, at_5us = 0.0, at_end = 0.0;
    };
    const auto run_to_end = [&](ForceForm form, double spacing) {
        Scene scene = s;
        scene.solver.force_form = form;
        scene.bodies[0].spacing = spacing;
        Simulation run(scene, 2);
        Drift d;
        while (!run.finished()) {
            run.step();
            d.largest = std::max(d.largest, std::abs(run.totals().energy_error));
            if (run.time() <= 5e-6) d.at_5us = run.totals().energy_error;
        }
        d.at_end = run.totals().energy_error;
        EXPECT_EQ(run.stop_reason(), "end time 40 us reached");
        std::printf("[ measured ] %s at %.2f mm: energy error %.3g at 5 us, %.3g at 40 us, largest %.3g, %zu steps\n",
                    form == ForceForm::Pairwise ? "pairwise" : "stress difference", spacing * 1e3, d.at_5us, d.at_end, d.largest,
                    run.steps());
        return d;
    };
    EXPECT_LT(run_to_end(ForceForm::Pairwise, 0.25e-3).largest, 1e-13);
    const Drift coarse = run_to_end(ForceForm::StressDifference, 0.5e-3);
    const Drift fine = run_to_end(ForceForm::StressDifference, 0.25e-3);
    for (const Drift& d : {coarse, fine}) {
        // The bound docs/surfaces.md states for a closed body: 5 % (measured 4.2 % and 2.1 %).
        EXPECT_LT(d.largest, 0.05);
        // Held, not growing: from 5 to 40 us it moves by under half a per cent of the energy (a
        // mode that grows as from a free surface would have e-folded a hundred times over).
        EXPECT_LT(std::abs(d.at_end - d.at_5us), 0.005);
    }
    EXPECT_LT(fine.largest, 0.7 * coarse.largest) << "the drift must fall with the spacing";
}

TEST(StressDifference, BondViscosityIsRefused) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/armco-cylinder-bond.toml");
    s.solver.force_form = ForceForm::StressDifference;
    try {
        validate_scene(s);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bond viscosity is a pair force"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace gpa
