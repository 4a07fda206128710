// The paper's correction at free surfaces and interfaces (its section 2.5, spec section 7;
// kernels.hpp, OneSidedMoments): its lattice numbers, and the balances of a run with it.
//
// The paper's set-up (spec section 7): a plane-strain lattice of unit nodes (d = 1, A = 1, a = 1,
// the GPA weight, variable connectivity) under a uniform sigma_z = -1. The net z-force between a
// node and its neighbours on one side of it along z, its own stress on them less theirs on it, is
// 1 (the stress times the unit area) for an interior node A. At a node B in the middle of the free
// top face, alpha_z is twice the interior value, its own stress pushes the row below twice as hard
// and the net force is 1.5; at the top corner D alpha_z is 2.45 times the interior value and the
// net force 1.48; at a node C of a side face it is 0.98 (the interior node above it pushes it with
// its smaller alpha). Halving alpha_z at B and D gives 1.0 and 0.98: the correction makes the top
// face's nodes carry what the side face's already do.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/LU>
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/simulation.hpp"
#include "support/lattices.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

struct StressedBlock {
    NodeStore nodes = testing::make_lattice(testing::unit_cells(7));  // nodes at 0.5 ... 6.5
    CompressedRows lists;
    bool full = false;

    StressedBlock(bool corrected, bool moment_matrix) : full(moment_matrix) {
        lists = find_neighbours(nodes, 1.0, nodes.size());
        testing::set_uniaxial_stress_z(nodes, -1.0);
        auto f = gradient_fields<2>(nodes, 1.0);
        f.full_normalisation = moment_matrix;
        f.surface_correction = corrected;
        compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, f);
    }

    std::size_t node_at(double x, double z) const { return testing::node_at(nodes, x, z); }

    Mat<2> normalisation(std::size_t i) const {
        std::array<const double*, 2> alpha{nodes.alpha[0].data(), nodes.alpha[1].data()};
        std::array<const double*, 3> shear{full ? nodes.alpha_shear[0].data() : nullptr, nullptr, nullptr};
        return normalisation_of<2>(alpha, shear, i);
    }

    // The z-force that centre i's stress exerts on j (Eq. 22).
    double force_z(std::size_t i, std::size_t j) const {
        const auto f = force_fields<2>(const_cast<NodeStore&>(nodes), 1.0);
        const auto p = f.pairs.pair<GpaWeight>(i, j);
        const auto sigma = cauchy_stress<PlaneStrain>(f.deviatoric_stress, f.pressure, nullptr, i);
        return pair_force(p, nodes.volume[i], nodes.size_weight[j], (normalisation(i) * p.dx).eval(), sigma, 0.0)[1];
    }

    // |sum over the neighbours at z + dz of (i's force on them - theirs on i)|, z-components.
    double net_force(double x, double z, double dz) const {
        const std::size_t i = node_at(x, z);
        double net = 0.0;
        int counted = 0;
        for (double dx : {-1.0, 0.0, 1.0}) {
            const double xj = x + dx, zj = z + dz;
            if (xj < 0.0 || xj > 7.0 || zj < 0.0 || zj > 7.0) continue;
            const std::size_t j = node_at(xj, zj);
            net += force_z(i, j) - force_z(j, i);
            ++counted;
        }
        EXPECT_GE(counted, 2);
        return std::abs(net);
    }
};

TEST(SurfaceCorrection, AMomentGainsNothingWhileNearEvenAndItselfWhenOneSideIsEmpty) {
    // A side at least a third of the other (|p - n| <= (p + n) / 2): no gain.
    EXPECT_EQ(one_sided_gain(1.0, 1.0, one_sided_threshold), 0.0);
    EXPECT_EQ(one_sided_gain(3.0, 1.0, one_sided_threshold), 0.0);
    EXPECT_EQ(one_sided_gain(1.0, 3.0, one_sided_threshold), 0.0);
    // One side empty: the whole moment (the factor halved), whichever side.
    EXPECT_DOUBLE_EQ(one_sided_gain(2.5, 0.0, one_sided_threshold), 2.5);
    EXPECT_DOUBLE_EQ(one_sided_gain(0.0, 2.5, one_sided_threshold), 2.5);
    // Linear in between and continuous at the threshold: p = 7, n = 1 is half-way from 3:1 to 1:0
    // in |p - n| / (p + n) = 0.75, so half the moment.
    EXPECT_DOUBLE_EQ(one_sided_gain(7.0, 1.0, one_sided_threshold), 4.0);
    EXPECT_LT(one_sided_gain(3.0 + 1e-9, 1.0, one_sided_threshold), 1e-8);
}

// The lattice's nodes: A interior, B the middle of the free top face, C a side face, D the top
// corner (x = 6.5 is the block's right face, z = 6.5 its top).
constexpr double top = 6.5, side = 6.5, middle = 3.5;

TEST(SurfaceCorrection, ThePapersLatticeNodesWithoutIt) {
    const StressedBlock b(false, false);
    // Interior: 1 exactly (the paper's 1.0000). Top face: its own alpha_z twice the interior's, so
    // 2 x 0.5 + 0.5 = 1.5. Side node (alpha_z = 1 / (1 + (1 - sqrt 2 / 2)) = 0.7735 with two
    // diagonals instead of four): its own push 0.5, the side node above 0.3867 and the interior
    // diagonal 0.0923, 0.979 in all. Corner (alpha_z 1.547): its own 1.0, the same 0.479 back.
    EXPECT_NEAR(b.net_force(middle, middle, +1.0), 1.0, 1e-12);
    EXPECT_NEAR(b.net_force(middle, top, -1.0), 1.5, 1e-12);
    EXPECT_NEAR(b.net_force(side, middle, +1.0), 0.98, 5e-3);  // the paper's two decimals
    EXPECT_NEAR(b.net_force(side, top, -1.0), 1.48, 5e-3);
}

TEST(SurfaceCorrection, HalvesAlphaNormalToTheFaceAndGivesThePapersCorrectedForces) {
    const StressedBlock plain(false, false), corrected(true, false);
    const std::size_t interior = plain.node_at(middle, middle), face = plain.node_at(middle, top),
                      corner = plain.node_at(side, top), side_node = plain.node_at(side, middle);
    // alpha normal to a face halved, alpha along it kept; interior nodes keep both (exactly: an even
    // neighbourhood's two sides cancel).
    EXPECT_EQ(corrected.nodes.alpha[0][interior], plain.nodes.alpha[0][interior]);
    EXPECT_EQ(corrected.nodes.alpha[1][interior], plain.nodes.alpha[1][interior]);
    EXPECT_NEAR(corrected.nodes.alpha[1][face], 0.5 * plain.nodes.alpha[1][face], 1e-15);
    EXPECT_EQ(corrected.nodes.alpha[0][face], plain.nodes.alpha[0][face]);
    EXPECT_NEAR(corrected.nodes.alpha[0][side_node], 0.5 * plain.nodes.alpha[0][side_node], 1e-15);
    EXPECT_EQ(corrected.nodes.alpha[1][side_node], plain.nodes.alpha[1][side_node]);
    EXPECT_NEAR(corrected.nodes.alpha[0][corner], 0.5 * plain.nodes.alpha[0][corner], 1e-15);
    EXPECT_NEAR(corrected.nodes.alpha[1][corner], 0.5 * plain.nodes.alpha[1][corner], 1e-15);
    // The face's alpha_z back at the interior value: 1.26 -> 0.63.
    EXPECT_NEAR(corrected.nodes.alpha[1][face], plain.nodes.alpha[1][interior], 1e-12);

    EXPECT_NEAR(corrected.net_force(middle, middle, +1.0), 1.0, 1e-12);
    EXPECT_NEAR(corrected.net_force(middle, top, -1.0), 1.0, 1e-12);  // paper: B 1.5 -> 1.0
    EXPECT_NEAR(corrected.net_force(side, top, -1.0), 0.98, 5e-3);    // paper: D 1.48 -> 0.98
    // The side node's z-force is its own alpha_z's, which the correction leaves: 0.98 both ways.
    EXPECT_EQ(corrected.net_force(side, middle, +1.0), plain.net_force(side, middle, +1.0));
}

TEST(SurfaceCorrection, TheMomentMatrixRuleGivesThePapersNumbersOnAFaceAndCorrectsACornerAlongItsDiagonal) {
    const StressedBlock plain(false, true), corrected(true, true);
    // Uncorrected, the moment matrix gives the per-direction numbers on the face (its M is diagonal
    // there) and, with the shear of the corner's M, the same net force at the corner.
    EXPECT_NEAR(plain.net_force(middle, top, -1.0), 1.5, 1e-12);
    EXPECT_NEAR(plain.net_force(side, top, -1.0), 1.48, 5e-3);
    // A face's normal is an axis: the paper's halving.
    EXPECT_NEAR(corrected.net_force(middle, middle, +1.0), 1.0, 1e-12);
    EXPECT_NEAR(corrected.net_force(middle, top, -1.0), 1.0, 1e-12);
    // At the corner the neighbourhood's normal is the diagonal n = -(1, 1) / sqrt 2 (its first
    // moment: R W l of the left and lower nodes, R = 1/2, and of the diagonal one, R = 1 - sqrt 2 / 2).
    // All three lie on the inner side of it, so M gains S_n+ n n^T with
    // S_n+ = 2 (1/2)(1/2) + (1 - sqrt 2 / 2) = 1.5 - sqrt 2 / 2: each entry of M' - M is half that.
    const std::size_t c = corrected.node_at(side, top);
    const Mat<2> gained = corrected.normalisation(c).inverse() - plain.normalisation(c).inverse();
    const double expected = 0.5 * (1.5 - std::sqrt(2.0) / 2.0);
    EXPECT_NEAR(gained(0, 0), expected, 1e-12);
    EXPECT_NEAR(gained(1, 1), expected, 1e-12);
    EXPECT_NEAR(gained(0, 1), expected, 1e-12);
    // Not twice each axis, as the per-axis rule: the net force at the corner falls from 1.48 to
    // 1.23, not to 0.98.
    const double corner = corrected.net_force(side, top, -1.0);
    EXPECT_NEAR(corner, 1.229, 5e-4);
    // The face node is corrected the same way by both rules.
    const StressedBlock per_axis(true, false);
    const std::size_t face = per_axis.node_at(middle, top);
    EXPECT_NEAR(corrected.nodes.alpha[1][face], per_axis.nodes.alpha[1][face], 1e-14);
    EXPECT_NEAR(corrected.nodes.alpha_shear[0][face], 0.0, 1e-14);
}

// The option from the scene to the step: a prestressed axisymmetric bar without planes, run with
// and without the correction. The top face's alpha_z is halved at the start (its neighbours all
// lie below it, on the undeformed lattice), and over the run the momentum stays 0 and the
// energy balance closes to round-off, as without it.
TEST(SurfaceCorrection, AWholeRunHalvesTheFaceFactorAndKeepsMomentumAndEnergy) {
    const auto scene = [](bool corrected) {
        auto s = testing::elastic_bar_on_plane(1e-3, 10e-3, 5, 10.0);
        s.planes.clear();
        s.bodies[0].velocity = {0.0, 0.0, 0.0};
        s.bodies[0].initial_stress = {-1e8, 2e8, 5e7, 0.0, 0.0, 0.0};  // it must move
        s.solver.surface_correction = corrected;
        s.stop.max_steps = 300;
        return s;
    };
    Simulation plain(scene(false), 2), corrected(scene(true), 2);  // the set-up takes the factors at t = 0
    std::size_t highest = 0;  // a node of the top face
    for (std::size_t i = 0; i < plain.real_count(); ++i) {
        if (plain.nodes().initial_position[1][i] > plain.nodes().initial_position[1][highest]) highest = i;
    }
    ASSERT_EQ(corrected.nodes().id[highest], plain.nodes().id[highest]);  // the same node in both
    EXPECT_NEAR(corrected.nodes().alpha[1][highest], 0.5 * plain.nodes().alpha[1][highest],
                1e-12 * plain.nodes().alpha[1][highest]);
    while (!corrected.finished()) corrected.step();
    double momentum = 0.0, scale = 0.0;
    for (std::size_t i = 0; i < corrected.real_count(); ++i) {
        momentum += corrected.nodes().mass[i] * corrected.nodes().velocity[1][i];
        scale += corrected.nodes().mass[i] * std::abs(corrected.nodes().velocity[1][i]);
    }
    ASSERT_GT(scale, 0.0) << "the prestressed bar must be moving";
    EXPECT_NEAR(momentum, 0.0, 1e-13 * scale);
    // The compatible energy update books the work of the same forces the step applied.
    EXPECT_LT(std::abs(corrected.totals().energy_error), 1e-12);
}

}  // namespace
}  // namespace gpa
