// The paper's numbers for a regular plane-strain lattice (spec section 7): unit nodes
// (d = 1, A = 1), influence distance 1, variable weights, uniform sigma_z = -1.

#include <gtest/gtest.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/neighbours.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

struct UnitLattice {
    NodeStore nodes = testing::make_lattice({GeometryKind::PlaneStrain, 7, 1.0, 0.0, Connectivity::Variable, 0, 1.0});
    CompressedRows lists;
    std::size_t centre = 0;

    UnitLattice() {
        lists = find_neighbours(nodes, 1.0, nodes.size());
        testing::set_uniaxial_stress_z(nodes, -1.0);
        centre = testing::node_at(nodes, 3.5, 3.5);
        compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, gradient_fields<2>(nodes, 1.0));
    }

    std::size_t node_at(double x, double z) const { return testing::node_at(nodes, x, z); }

    // The z-force that centre i's stress exerts on j (Eq. 22).
    double force_z(std::size_t i, std::size_t j) const {
        const auto f = force_fields<2>(const_cast<NodeStore&>(nodes), 1.0);
        const auto p = f.pairs.pair<GpaWeight>(i, j);
        const Vec<2> alpha(nodes.alpha[0][i], nodes.alpha[1][i]);
        const auto sigma = cauchy_stress<PlaneStrain>(f.deviatoric_stress, f.pressure, nullptr, i);
        return pair_force(p, nodes.volume[i], nodes.size_weight[j], alpha.cwiseProduct(p.dx).eval(), sigma, 0.0)[1];
    }
};

TEST(PaperLattice, InteriorNodeHasEightNeighboursAndNotTheOnesAtTwoH) {
    UnitLattice l;
    ASSERT_EQ(l.nodes.position[0][l.centre], 3.5);
    EXPECT_EQ(l.lists.row_size(l.centre), 8u);  // distance 1 and sqrt 2; distance 2 = 2h has weight 0
    EXPECT_EQ(find_neighbours_brute_force(l.nodes, 1.0, l.nodes.size()).row(l.centre).size(), 8u);
}

TEST(PaperLattice, GeometryFactorAndPairForcesMatchThePaper) {
    UnitLattice l;
    const std::size_t i = l.centre;
    // alpha_z = 1 / (2 * 0.5 + 4 * (1 - sqrt(2)/2) / 2) = 0.6306 (paper, to 4 decimals).
    EXPECT_NEAR(l.nodes.alpha[1][i], 0.6306, 5e-5);
    EXPECT_NEAR(l.nodes.alpha[0][i], 0.6306, 5e-5);
    const std::size_t above = l.node_at(3.5, 4.5), diagonal = l.node_at(4.5, 4.5), other_diagonal = l.node_at(2.5, 4.5);
    EXPECT_NEAR(l.force_z(i, diagonal), 0.0923, 5e-5);
    EXPECT_NEAR(l.force_z(i, above), 0.3153, 5e-5);
    // Net force between the node and the three above: 0.5 from its own stress pushing them up,
    // 0.5 from theirs pushing it down.
    const double own = l.force_z(i, above) + l.force_z(i, diagonal) + l.force_z(i, other_diagonal);
    const double theirs = l.force_z(above, i) + l.force_z(diagonal, i) + l.force_z(other_diagonal, i);
    EXPECT_NEAR(own, 0.5, 5e-5);
    EXPECT_NEAR(theirs, -0.5, 5e-5);
    EXPECT_NEAR(own - theirs, 1.0000, 5e-5);
}

TEST(PaperLattice, UniformStressGivesNoNetForceOnInteriorNodes) {
    UnitLattice l;
    l.nodes.viscous_pressure.assign(l.nodes.size(), 0.0);
    const auto plan = make_serial_plan(l.lists);
    compute_forces<PlaneStrain>(l.lists, plan, WeightKind::Gpa, nullptr, force_fields<2>(l.nodes, 1.0), l.nodes.size());
    for (std::size_t i = 0; i < l.nodes.size(); ++i) {
        const double x = l.nodes.position[0][i], z = l.nodes.position[1][i];
        if (x < 2.0 || x > 5.0 || z < 2.0 || z > 5.0) continue;  // complete neighbourhoods two deep
        EXPECT_NEAR(l.nodes.force[0][i], 0.0, 1e-14) << "node " << i;
        EXPECT_NEAR(l.nodes.force[1][i], 0.0, 1e-14) << "node " << i;
    }
}

}  // namespace
}  // namespace gpa
