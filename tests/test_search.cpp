// The cell-list search against an all-pairs loop on random clouds with unequal diameters, and
// the mixed rules (fixed centres, several bodies); the locality reordering.

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "gpa/engine/neighbours.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

NodeStore random_cloud(GeometryKind g, std::size_t count, std::uint64_t seed) {
    NodeStore n(g, count);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> pos(0.0, 1.0), dia(0.01, 0.05);
    for (std::size_t i = 0; i < count; ++i) {
        for (int c = 0; c < n.dim(); ++c) n.position[c][i] = pos(rng) * (c == 0 ? 1.0 : 0.6);
        n.position[0][i] += 0.01;  // keep axisymmetric radii positive
        n.diameter[i] = dia(rng);
        n.connectivity[i] = Connectivity::Variable;
    }
    return n;
}

void expect_same_sets(const CompressedRows& a, const CompressedRows& b) {
    ASSERT_EQ(a.rows(), b.rows());
    std::size_t total = 0;
    for (std::size_t i = 0; i < a.rows(); ++i) {
        std::vector<NodeIndex> x(a.row(i).begin(), a.row(i).end()), y(b.row(i).begin(), b.row(i).end());
        std::sort(x.begin(), x.end());
        std::sort(y.begin(), y.end());
        ASSERT_EQ(x, y) << "centre " << i;
        ASSERT_TRUE(std::adjacent_find(x.begin(), x.end()) == x.end()) << "centre " << i << " lists a node twice";
        total += x.size();
    }
    EXPECT_GT(total, a.rows()) << "clouds this sparse test nothing";
}

TEST(Search, CellListEqualsAllPairsIn2D) {
    for (double a : {0.8, 1.0, 1.5}) {
        auto n = random_cloud(GeometryKind::PlaneStrain, 3000, 1);
        expect_same_sets(find_neighbours(n, a, n.size()), find_neighbours_brute_force(n, a, n.size()));
    }
}

TEST(Search, CellListEqualsAllPairsIn3D) {
    for (double a : {0.8, 1.0, 1.5}) {
        auto n = random_cloud(GeometryKind::ThreeD, 2500, 2);
        for (auto& d : n.diameter) d *= 2.5;
        expect_same_sets(find_neighbours(n, a, n.size()), find_neighbours_brute_force(n, a, n.size()));
    }
}

TEST(Search, NeighbourAtExactlyTwoHIsExcluded) {
    NodeStore n(GeometryKind::PlaneStrain, 3);
    n.position[0] = {0.0, 2.0, 0.0};
    n.position[1] = {0.0, 0.0, 1.999999};
    n.diameter = {1.0, 1.0, 1.0};
    n.connectivity.assign(3, Connectivity::Variable);
    const auto lists = find_neighbours(n, 1.0, 3);
    ASSERT_EQ(lists.row_size(0), 1u);  // node 1 sits at exactly 2h, node 2 just inside
    EXPECT_EQ(lists.row(0)[0], 2u);
}

TEST(Search, FixedCentresKeepLatticeNeighboursAndFindOtherBodies) {
    // Two fixed-connectivity blocks touching at z = 0.3, and a variable block beside them.
    NodeStore n(GeometryKind::PlaneStrain);
    for (int b = 0; b < 3; ++b) {
        LatticeBlock blk;
        blk.spacing = {0.02, 0.02, 0.02};
        blk.origin = {b == 2 ? 0.3 : 0.0, b == 1 ? 0.3 : 0.0, 0.0};
        blk.last = {15, 15, 1};
        blk.body = b;
        blk.connectivity = b == 2 ? Connectivity::Variable : Connectivity::Fixed;
        fill_lattice(n, blk);
    }
    testing::jitter(n, 0.1, 0.02, 9);
    const auto fast = find_neighbours(n, 1.0, n.size());
    expect_same_sets(fast, find_neighbours_brute_force(n, 1.0, n.size()));
    // A fixed interior node of body 0 keeps exactly its 8 lattice neighbours.
    std::size_t interior = 7 * 15 + 7;
    EXPECT_EQ(fast.row_size(interior), 8u);
    // A fixed node of body 0 at the interface with body 1 gains body-1 neighbours by search.
    const std::size_t top_row = 14 * 15 + 7;
    EXPECT_GT(fast.row_size(top_row), n.fixed_neighbours.row_size(top_row));
}

TEST(Search, ResultDoesNotDependOnThreadCountOrScratchReuse) {
    auto n = random_cloud(GeometryKind::PlaneStrain, 5000, 3);
    const auto reference = find_neighbours(n, 1.0, n.size());
    NeighbourScratch scratch;
    CompressedRows out;
    find_neighbours(n, 1.0, n.size(), out, scratch);
    find_neighbours(n, 1.0, n.size(), out, scratch);
    EXPECT_EQ(out, reference);  // identical lists, identical order
}

TEST(Reorder, LocalityOrderIsAPermutationThatKeepsListsConsistent) {
    auto n = testing::make_lattice({GeometryKind::PlaneStrain, 20, 1.0, 0.0, Connectivity::Fixed, 8, 1.0});
    testing::jitter(n, 0.3, 1.0, 4);
    std::mt19937_64 rng(1);
    std::vector<NodeIndex> shuffle(n.size());
    std::iota(shuffle.begin(), shuffle.end(), 0u);
    std::shuffle(shuffle.begin(), shuffle.end(), rng);
    n.permute(shuffle);
    const auto before = find_neighbours(n, 1.0, n.size());
    const auto order = locality_order(n, 2.0, 0, n.size());
    std::vector<NodeIndex> sorted = order;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);
    auto m = n;
    m.permute(order);
    const auto after = find_neighbours(m, 1.0, m.size());
    // The same pairs, renamed: new node k is old node order[k].
    std::size_t far_before = 0, far_after = 0;
    for (std::size_t k = 0; k < m.size(); ++k) {
        std::vector<NodeIndex> renamed;
        for (NodeIndex j : after.row(k)) renamed.push_back(order[j]);
        std::vector<NodeIndex> original(before.row(order[k]).begin(), before.row(order[k]).end());
        std::sort(renamed.begin(), renamed.end());
        std::sort(original.begin(), original.end());
        ASSERT_EQ(renamed, original);
        for (NodeIndex j : after.row(k)) far_after += (j > k ? j - k : k - j) > 100;
        for (NodeIndex j : before.row(k)) far_before += (j > k ? j - k : k - j) > 100;
    }
    EXPECT_LT(far_after * 4, far_before) << "reordering should bring neighbours close in memory";
}

}  // namespace
}  // namespace gpa
