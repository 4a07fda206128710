// NodeStore: resizing, permuting and the set-up of lattice nodes (spec section 12).

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <random>

#include <gtest/gtest.h>

#include "gpa/engine/kernels.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/memory_use.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/weights.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

TEST(NodeStore, PermuteMovesEveryFieldAndRenamesFixedLists) {
    auto n = testing::make_lattice({GeometryKind::Axisymmetric, 6, 0.5, 0.0, Connectivity::Fixed, 8, 2.0});
    testing::randomise_state(n, 1);
    for (std::size_t i = 0; i < n.size(); ++i) n.plastic_strain[i] = static_cast<double>(i);
    const auto original = n;
    std::vector<NodeIndex> order(n.size());
    std::iota(order.begin(), order.end(), 0u);
    std::mt19937_64 rng(2);
    std::shuffle(order.begin(), order.end(), rng);
    n.permute(order);
    for (std::size_t k = 0; k < n.size(); ++k) {
        const std::size_t old = order[k];
        EXPECT_EQ(n.plastic_strain[k], original.plastic_strain[old]);
        EXPECT_EQ(n.position[0][k], original.position[0][old]);
        EXPECT_EQ(n.velocity[1][k], original.velocity[1][old]);
        EXPECT_EQ(n.deviatoric_stress[3][k], original.deviatoric_stress[3][old]);
        EXPECT_EQ(n.mass[k], original.mass[old]);
        ASSERT_EQ(n.fixed_neighbours.row_size(k), original.fixed_neighbours.row_size(old));
        for (std::size_t m = 0; m < n.fixed_neighbours.row_size(k); ++m) {
            EXPECT_EQ(order[n.fixed_neighbours.row(k)[m]], original.fixed_neighbours.row(old)[m]);
        }
    }
}

// A store that dropped alpha_shear leaves it out of resizing and reordering, and the gradient
// refuses the full normalisation on it with an error instead of writing through a null pointer.
TEST(NodeStore, ADroppedShearNormalisationStaysEmptyAndTheFullNormalisationIsRefused) {
    auto n = testing::make_lattice({GeometryKind::PlaneStrain, 6, 0.5, 0.0, Connectivity::Variable, 8, 1.0});
    ASSERT_TRUE(n.carries_shear_normalisation());
    ASSERT_EQ(n.alpha_shear[0].size(), n.size());
    n.drop_shear_normalisation();
    EXPECT_FALSE(n.carries_shear_normalisation());
    n.resize(n.size() + 3);
    n.resize(n.size() - 3);
    std::vector<NodeIndex> order(n.size());
    std::iota(order.rbegin(), order.rend(), 0u);
    n.permute(order);
    EXPECT_EQ(n.alpha_shear[0].capacity(), 0u);
    MemoryUse use;
    n.memory_use(use);
    EXPECT_TRUE(std::none_of(use.begin(), use.end(), [](const ArrayMemory& a) { return a.array == "nodes: alpha_shear"; }));
    const CompressedRows lists = find_neighbours(n, 1.0, n.size());
    auto f = gradient_fields<2>(n, 1.0);
    f.full_normalisation = true;
    EXPECT_THROW(compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, f), InputError);
    f.full_normalisation = false;
    EXPECT_NO_THROW(compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, f));
}

TEST(Lattice, NodesSitAtCellCentresWithTheirRingVolumes) {
    NodeStore n(GeometryKind::Axisymmetric);
    LatticeBlock b;
    b.spacing = {0.001, 0.002, 0.0};
    b.last = {3, 2, 1};
    b.density = 8000.0;
    fill_lattice(n, b);
    ASSERT_EQ(n.size(), 6u);
    for (std::size_t i = 0; i < n.size(); ++i) {
        const double x = n.position[0][i];
        EXPECT_NEAR(std::fmod(x / 0.001, 1.0), 0.5, 1e-9);
        const double v0 = 2.0 * std::numbers::pi * x * 0.001 * 0.002;
        EXPECT_DOUBLE_EQ(n.volume[i], v0);
        EXPECT_DOUBLE_EQ(n.mass[i], 8000.0 * v0);
        EXPECT_DOUBLE_EQ(n.size_weight[i], 0.001 * 0.002);  // A = V / (2 pi x), Eq. 4
        EXPECT_DOUBLE_EQ(n.diameter[i], std::sqrt(0.001 * 0.002));
    }
    EXPECT_EQ(n.fixed_neighbours.row_size(0), 3u);  // a corner of a 3 x 2 block, 8-neighbour stencil
    EXPECT_EQ(n.fixed_neighbours.row_size(1), 5u);
}

TEST(Lattice, StencilsHaveTheirNeighbourCountsInTheInterior) {
    for (int s : {6, 18, 26}) {
        NodeStore n(GeometryKind::ThreeD);
        LatticeBlock b;
        b.last = {3, 3, 3};
        b.lattice_neighbours = s;
        fill_lattice(n, b);
        EXPECT_EQ(n.fixed_neighbours.row_size(13), static_cast<std::size_t>(s));
    }
    for (int s : {4, 8}) {
        NodeStore n(GeometryKind::PlaneStrain);
        LatticeBlock b;
        b.last = {3, 3, 1};
        b.lattice_neighbours = s;
        fill_lattice(n, b);
        EXPECT_EQ(n.fixed_neighbours.row_size(4), static_cast<std::size_t>(s));
    }
}

TEST(Kernels, VolumetricStrainAndDiameterUpdates) {
    // Eq. 13 integrates V/V0 exactly for a constant rate in the limit of small steps:
    // (1 + eps_v) -> exp(rate t).
    double eps = 0.0;
    const double rate = -2000.0, dt = 1e-9;
    for (int k = 0; k < 100000; ++k) eps = advance_volumetric_strain(eps, rate, dt);
    EXPECT_NEAR(1.0 + eps, std::exp(rate * 1e-4), 1e-6);
    // Eq. 3: an axisymmetric ring that keeps its volume but moves out to twice its radius has half
    // its cross-section, so its diameter falls by sqrt 2.
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0), std::sqrt(0.5));
    EXPECT_DOUBLE_EQ(node_diameter<PlaneStrain>(1.0, 0.21, 0.0, 0.0), 1.1);
    EXPECT_NEAR(node_diameter<ThreeD>(1.0, 0.331, 0.0, 0.0), 1.1, 1e-15);
}

TEST(Kernels, ArtificialViscosityActsOnlyInCompression) {
    EXPECT_EQ(nodal_viscosity(1.0, 1000.0, 5000.0, 0.001, 0.2, 4.0), 0.0);
    // Eq. 36: Q = C_L rho c h |e| + C_Q rho h^2 e^2
    EXPECT_DOUBLE_EQ(nodal_viscosity(-1e4, 1000.0, 5000.0, 0.001, 0.2, 4.0),
                     0.2 * 1000.0 * 5000.0 * 0.001 * 1e4 + 4.0 * 1000.0 * 1e-6 * 1e8);
    EXPECT_EQ(bond_viscosity(0.5, 1000.0, 5000.0, 0.2, 4.0), 0.0);
    EXPECT_DOUBLE_EQ(bond_viscosity(-2.0, 1000.0, 5000.0, 0.2, 4.0), 0.2 * 1000.0 * 5000.0 * 2.0 + 4.0 * 1000.0 * 4.0);
    // Eq. 38: approaching nodes have mu < 0, receding ones mu > 0 (h 1 mm, the pair 2 mm apart
    // along x, closing at 1 m/s; the same along a diagonal, where only the projection counts).
    const Vec<2> dx(0.002, 0.0);
    EXPECT_LT(bond_compression_rate<2>(0.001, dx, Vec<2>(-1.0, 0.0), 0.01), 0.0);
    EXPECT_GT(bond_compression_rate<2>(0.001, dx, Vec<2>(1.0, 0.0), 0.01), 0.0);
    EXPECT_NEAR(bond_compression_rate<2>(0.001, dx, Vec<2>(-1.0, 0.0), 0.01), -0.001 * 0.002 / (0.002 * 0.002 + 0.01 * 1e-6), 1e-15);
    const Vec<2> diagonal(0.002 / std::sqrt(2.0), 0.002 / std::sqrt(2.0));
    EXPECT_NEAR(bond_compression_rate<2>(0.001, diagonal, Vec<2>(-1.0, 3.0), 0.01),
                0.001 * (2.0 * 0.002 / std::sqrt(2.0)) / (0.002 * 0.002 + 0.01 * 1e-6), 1e-15);
}

TEST(Kernels, WeightsVanishAtTwoH) {
    EXPECT_EQ(GpaWeight::value(2.0), 0.0);
    EXPECT_EQ(SphNsfWeight::value(2.0), 0.0);
    EXPECT_DOUBLE_EQ(GpaWeight::value(1.0), 0.5);
    EXPECT_DOUBLE_EQ(SphNsfWeight::value(1.0), 0.75);  // continuous at q = 1: 3 - 9/4 = 3/4 (1)(1)^2
    EXPECT_NEAR(SphNsfWeight::value(1.0 - 1e-9), SphNsfWeight::value(1.0 + 1e-9), 1e-8);
}

}  // namespace
}  // namespace gpa
