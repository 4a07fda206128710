// Impossible input ends in an exception whose message says what and where; nothing divides by
// zero silently.

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

template <class E, class F>
std::string message_of(F&& f) {
    try {
        f();
    } catch (const E& e) {
        return e.what();
    }
    ADD_FAILURE() << "no exception of the expected type";
    return {};
}

NodeStore small_lattice(GeometryKind g = GeometryKind::PlaneStrain) {
    return testing::make_lattice({g, 5, 0.01, 0.0, Connectivity::Variable, 0, 7800.0});
}

TEST(BadInput, NonPositiveVolumeNamesTheNode) {
    auto n = small_lattice();
    n.volume[7] = -1e-6;
    const auto m = message_of<InputError>([&] { validate_nodes(n); });
    EXPECT_NE(m.find("node 7"), std::string::npos) << m;
    EXPECT_NE(m.find("volume"), std::string::npos) << m;
}

TEST(BadInput, ZeroMassNamesTheNode) {
    auto n = small_lattice();
    n.mass[3] = 0.0;
    const auto m = message_of<InputError>([&] { validate_nodes(n); });
    EXPECT_NE(m.find("node 3"), std::string::npos) << m;
    EXPECT_NE(m.find("mass"), std::string::npos) << m;
}

TEST(BadInput, NonFiniteCoordinateNamesTheNode) {
    auto n = small_lattice();
    n.position[1][11] = std::numeric_limits<double>::quiet_NaN();
    const auto m = message_of<InputError>([&] { validate_nodes(n); });
    EXPECT_NE(m.find("node 11"), std::string::npos) << m;
    EXPECT_NE(m.find("finite"), std::string::npos) << m;
}

TEST(BadInput, AxisymmetricNodeOnTheAxis) {
    auto n = small_lattice(GeometryKind::Axisymmetric);
    n.position[0][2] = 0.0;
    const auto m = message_of<InputError>([&] { validate_nodes(n); });
    EXPECT_NE(m.find("node 2"), std::string::npos) << m;
    EXPECT_NE(m.find("x > 0"), std::string::npos) << m;
}

TEST(BadInput, AThreeDNodeWithoutItsStretchTensorNamesTheNode) {
    auto n = small_lattice(GeometryKind::ThreeD);
    EXPECT_NO_THROW(validate_nodes(n));  // filled with B = I
    for (int c = 0; c < 6; ++c) n.left_cauchy_green[c][4] = 0.0;
    const auto m = message_of<InputError>([&] { validate_nodes(n); });
    EXPECT_NE(m.find("node 4"), std::string::npos) << m;
    EXPECT_NE(m.find("Cauchy-Green"), std::string::npos) << m;
}

TEST(BadInput, InfluenceDistanceOutsideItsRange) {
    auto n = small_lattice();
    for (double a : {0.79, 1.51, 0.0, -1.0, std::numeric_limits<double>::quiet_NaN()}) {
        const auto m = message_of<InputError>([&] { (void)find_neighbours(n, a, n.size()); });
        EXPECT_NE(m.find("influence distance"), std::string::npos) << m;
        EXPECT_NE(m.find("0.8-1.5"), std::string::npos) << m;
        EXPECT_THROW((void)gradient_fields<2>(n, a), InputError);
        // The checked value a run makes once (weights.hpp) refuses it where it is made.
        const auto typed = message_of<InputError>([&] { (void)InfluenceDistance(a); });
        EXPECT_NE(typed.find("0.8-1.5"), std::string::npos) << typed;
    }
    // In range: the typed and the plain overloads give the same views and the same lists.
    const InfluenceDistance checked(1.3);
    EXPECT_EQ(checked.value(), 1.3);
    EXPECT_EQ(pair_fields<2>(n, checked).influence_distance, pair_fields<2>(n, 1.3).influence_distance);
    CompressedRows typed_lists;
    NeighbourScratch scratch;
    find_neighbours(n, checked, n.size(), typed_lists, scratch);
    EXPECT_EQ(typed_lists, find_neighbours(n, 1.3, n.size()));
}

TEST(BadInput, EmptyNeighbourhoodNamesTheNode) {
    auto n = small_lattice();
    n.position[0][24] = 10.0;  // far from every other node
    const auto lists = find_neighbours(n, 1.0, n.size());
    ASSERT_EQ(lists.row_size(24), 0u);
    const auto m = message_of<InputError>(
        [&] { compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, gradient_fields<2>(n, 1.0)); });
    EXPECT_NE(m.find("node 24"), std::string::npos) << m;
    EXPECT_NE(m.find("empty neighbourhood"), std::string::npos) << m;
}

TEST(BadInput, FlatNeighbourhoodNamesTheNodeAndTheAxis) {
    // One row of nodes: no neighbour has a component along z, so alpha_z is undefined.
    NodeStore n(GeometryKind::PlaneStrain);
    LatticeBlock b;
    b.spacing = {0.01, 0.01, 0.01};
    b.last = {6, 1, 1};
    fill_lattice(n, b);
    const auto lists = find_neighbours(n, 1.0, n.size());
    const auto m = message_of<InputError>([&] {
        ThreadScope two(2);
        two.run([&] { compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, gradient_fields<2>(n, 1.0)); });
    });
    EXPECT_NE(m.find("node 0"), std::string::npos) << "the lowest failing node is reported: " << m;
    EXPECT_NE(m.find("alpha_z"), std::string::npos) << m;
}

TEST(BadInput, CoincidentNodesAreReported) {
    auto n = small_lattice();
    n.position[0][6] = n.position[0][5];
    n.position[1][6] = n.position[1][5];
    const auto lists = find_neighbours(n, 1.0, n.size());
    const auto m = message_of<NumericalError>(
        [&] { compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, gradient_fields<2>(n, 1.0)); });
    EXPECT_NE(m.find("coincide"), std::string::npos) << m;
}

TEST(BadInput, LatticeOptionsAreChecked) {
    NodeStore n(GeometryKind::PlaneStrain);
    LatticeBlock b;
    b.lattice_neighbours = 6;
    EXPECT_THROW(fill_lattice(n, b), InputError);
    b.lattice_neighbours = 8;
    b.spacing = {0.0, 1.0, 1.0};
    EXPECT_THROW(fill_lattice(n, b), InputError);
    b.spacing = {1.0, 1.0, 1.0};
    b.density = -5.0;
    EXPECT_THROW(fill_lattice(n, b), InputError);
    NodeStore axi(GeometryKind::Axisymmetric);
    LatticeBlock c;
    c.origin = {-0.5, 0.0, 0.0};  // first column centred on the axis
    const auto m = message_of<InputError>([&] { fill_lattice(axi, c); });
    EXPECT_NE(m.find("x > 0"), std::string::npos) << m;
    NodeStore three(GeometryKind::ThreeD);
    LatticeBlock d;
    d.spacing = {1.0, 1.0, 2.0};
    EXPECT_THROW(fill_lattice(three, d), InputError);
}

TEST(BadInput, BadPermutationAndThreadCount) {
    auto n = small_lattice();
    std::vector<NodeIndex> p(n.size(), 0);
    EXPECT_THROW(n.permute(p), InputError);
    EXPECT_THROW(ThreadScope(-1), InputError);
}

TEST(BadInput, MismatchedPlanIsRejected) {
    auto n = small_lattice();
    const auto lists = find_neighbours(n, 1.0, n.size());
    ScatterPlan empty;
    EXPECT_THROW(compute_forces<PlaneStrain>(lists, empty, WeightKind::Gpa, nullptr, force_fields<2>(n, 1.0), n.size()),
                 InputError);
    NodeStore three(GeometryKind::ThreeD, 4);
    EXPECT_THROW((void)force_fields<2>(three, 1.0), InputError);
}

}  // namespace
}  // namespace gpa

namespace gpa {
namespace {

// In a run a fragment may lose its neighbours (fracture, spall): with allow_degenerate the node
// gets no strain rate and no geometry factor along the missing axes instead of an error.
TEST(Degenerate, AnIsolatedNodeInARunFliesOn) {
    auto n = small_lattice(GeometryKind::Axisymmetric);
    n.position[0][24] = 10.0;  // far from every other node
    for (std::size_t i = 0; i < n.size(); ++i) n.velocity[0][i] = 3.0;
    update_size_weights(n, 0, n.size());
    const auto lists = find_neighbours(n, 1.0, n.size());
    auto f = gradient_fields<2>(n, 1.0);
    f.allow_degenerate = true;
    f.stable_length = n.stable_length.data();
    compute_velocity_gradient<Axisymmetric>(lists, WeightKind::Gpa, f);
    EXPECT_EQ(n.alpha[0][24], 0.0);
    EXPECT_EQ(n.alpha[1][24], 0.0);
    for (int c = 0; c < 4; ++c) EXPECT_EQ(n.velocity_gradient[c][24], 0.0);
    EXPECT_DOUBLE_EQ(n.volumetric_strain_rate[24], 3.0 / 10.0);  // the hoop rate u/x alone
    EXPECT_TRUE(std::isfinite(n.smallest_h[24]));
    EXPECT_GT(n.alpha[0][12], 0.0) << "the others keep their factors";
}

}  // namespace
}  // namespace gpa
