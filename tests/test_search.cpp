// The cell-list search against an all-pairs loop on random clouds with unequal diameters, and
// the mixed rules (fixed centres, several bodies); the locality reordering.

#include <algorithm>
#include <random>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/memory_use.hpp"
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

// Two fixed-connectivity blocks of 15 x 15 nodes touching at z = 0.3 (bodies 0 and 1), and a
// variable block beside them at x = 0.3 (body 2).
NodeStore two_fixed_blocks_and_a_variable_one() {
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
    return n;
}

TEST(Search, FixedCentresKeepLatticeNeighboursAndFindOtherBodies) {
    NodeStore n = two_fixed_blocks_and_a_variable_one();
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

// A cloud whose every 50th node has grown 10 to 30 times (debris of a fractured body): such
// nodes sit in a grid of their own, and every pair is still found, from both ends.
void make_outsized(NodeStore& n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> growth(10.0, 30.0);
    for (std::size_t i = 0; i < n.size(); i += 50) n.diameter[i] *= growth(rng);
}

TEST(Search, OutsizedNodesHaveAGridOfTheirOwnAndEveryPairIsFound) {
    for (const GeometryKind g : {GeometryKind::PlaneStrain, GeometryKind::ThreeD}) {
        for (double a : {0.8, 1.0, 1.5}) {
            auto n = random_cloud(g, 1500, 4);
            if (g == GeometryKind::ThreeD) {
                for (auto& d : n.diameter) d *= 2.5;
            }
            make_outsized(n, 5);
            const DiameterSpread spread = diameter_spread(n, n.size());
            ASSERT_TRUE(spread.any_outsized());
            EXPECT_LT(spread.bulk, spread.cut);
            EXPECT_LT(spread.cut, spread.largest);
            NeighbourScratch scratch;
            CompressedRows fast;
            find_neighbours(n, a, n.size(), fast, scratch);
            EXPECT_EQ(scratch.outsized.size(), 30u) << "every 50th node, and no other";
            expect_same_sets(fast, find_neighbours_brute_force(n, a, n.size()));
        }
    }
}

TEST(Search, WithoutOutsizedNodesTheBulkIsEveryNode) {
    auto n = random_cloud(GeometryKind::PlaneStrain, 1000, 6);  // diameters within a factor of 5: none above twice the mean
    const DiameterSpread spread = diameter_spread(n, n.size());
    EXPECT_FALSE(spread.any_outsized());
    EXPECT_EQ(spread.bulk, spread.largest);
    EXPECT_EQ(bulk_interaction_radius(n, 1.3, n.size()), largest_interaction_radius(n, 1.3, n.size()));
}

// Ghosts given to the nodes within reach of the pairs (GhostSet::pair_reach) make the same pairs
// as ghosts given to every node within the largest interaction radius, with outsized nodes
// about, and far fewer ghosts.
TEST(Search, GhostsWithinThePairsReachGiveEveryPairOfGhostsWithinTheLargestReach) {
    for (double a : {1.0, 1.5}) {
        NodeStore base = random_cloud(GeometryKind::Axisymmetric, 2500, 7);
        // Debris away from the planes grown 4 to 8 times, as in an impact's ejecta, and one
        // outsized node close to the axis, whose reach crosses it.
        std::mt19937_64 rng(8);
        std::uniform_real_distribution<double> growth(4.0, 8.0);
        for (std::size_t i = 0; i < base.size(); i += 20) {
            if (std::min(base.position[0][i], base.position[1][i]) > 0.45) base.diameter[i] *= growth(rng);
        }
        base.diameter[100] = 0.2;
        base.position[0][100] = 0.05;
        ASSERT_TRUE(diameter_spread(base, base.size()).any_outsized());
        const std::size_t real = base.size();
        GhostSet set({{"axis", 0, 0.0, +1, false, false}, {"floor", 1, 0.0, +1, false, false}});
        const auto pairs_with = [&](GhostReach reach, std::size_t& ghosts) {
            NodeStore n = base;
            GhostSet g = set;
            g.update_contacts(n, real, true);
            g.build(n, real, reach);
            ghosts = g.count();
            NeighbourScratch scratch;
            CompressedRows lists;
            find_neighbours(n, a, real, lists, scratch);
            // Each entry as (source, planes): the two sets number their ghosts differently.
            std::vector<std::vector<std::uint64_t>> keys(real);
            for (std::size_t i = 0; i < real; ++i) {
                for (NodeIndex j : lists.row(i)) {
                    keys[i].push_back(j < real ? j : (std::uint64_t{g.planes_of(j - real)} << 40) | g.source(j - real));
                }
                std::sort(keys[i].begin(), keys[i].end());
            }
            return keys;
        };
        std::size_t wide_ghosts = 0, reach_ghosts = 0;
        const auto wide = pairs_with(GhostReach{largest_interaction_radius(base, a, real), 0.0}, wide_ghosts);
        NodeStore probe = base;
        const auto reach = set.pair_reach(probe, real, a, 0.0);
        EXPECT_EQ(reach.per_diameter, a);
        const auto tight = pairs_with(reach, reach_ghosts);
        std::size_t ghost_pairs = 0;
        for (std::size_t i = 0; i < real; ++i) {
            ASSERT_EQ(tight[i], wide[i]) << "centre " << i << ", a = " << a;
            for (auto k : tight[i]) ghost_pairs += k >= (std::uint64_t{1} << 40);
        }
        EXPECT_GT(ghost_pairs, 100u) << "the planes must be in reach of many pairs";
        EXPECT_LT(reach_ghosts * 2, wide_ghosts) << "a = " << a;
    }
}

// The ghosts' look-up (GhostSet::image_like) finds every ghost of a node across each combination
// of planes and nothing else, and its table takes memory per source node, not per real node: a
// cloud of 20000 nodes with two planes (three combinations: each plane and the corner) has a few
// hundred nodes near them, and a table per real node would take 12 bytes for each of the 20000.
TEST(Search, TheGhostTableFindsEveryGhostAndGrowsWithTheGhostsNotTheNodes) {
    NodeStore n = random_cloud(GeometryKind::Axisymmetric, 20000, 11);
    const std::size_t real = n.size();
    GhostSet g({{"axis", 0, 0.0, +1, false, false}, {"floor", 1, 0.0, +1, false, false}});
    g.update_contacts(n, real, true);
    g.build(n, real, 0.03);
    ASSERT_GT(g.count(), 200u);
    ASSERT_LT(g.count(), real / 10);
    // One ghost of each combination, as the `like` argument of image_like.
    std::vector<NodeIndex> like_of_mask(8, 0);
    std::vector<bool> seen(8, false);
    for (std::size_t k = 0; k < g.count(); ++k) {
        const auto m = g.planes_of(k);
        if (!seen[m]) like_of_mask[m] = static_cast<NodeIndex>(real + k), seen[m] = true;
    }
    ASSERT_TRUE(seen[1] && seen[2] && seen[3]) << "each plane and the corner have ghosts";
    // Every (node, combination) -> the ghost whose source and planes they are, or -1.
    std::vector<std::int64_t> expected(real * 8, -1);
    for (std::size_t k = 0; k < g.count(); ++k) expected[g.source(k) * 8 + g.planes_of(k)] = static_cast<std::int64_t>(real + k);
    for (std::size_t i = 0; i < real; ++i) {
        for (std::uint8_t m : {1, 2, 3}) {
            ASSERT_EQ(g.image_like(real, like_of_mask[m], static_cast<NodeIndex>(i)), expected[i * 8 + m]) << "node " << i << ", planes " << int(m);
        }
    }
    MemoryUse use;
    g.memory_use(use);
    const auto table = std::find_if(use.begin(), use.end(), [](const ArrayMemory& a) { return a.array == "ghosts: index per plane combination"; });
    ASSERT_NE(table, use.end());
    // Three slots of 4 bytes per source node, and no node has more than three ghosts.
    EXPECT_LE(table->bytes, 3 * 4 * g.count());
    EXPECT_LT(table->bytes, real);  // a table per real node: 12 * real
}

// With candidates that outlive switching, a fixed centre whose cells within reach hold only fixed
// nodes of its body is quiet: its row is its lattice row alone. Next to another body or a
// variable node it is not, and its row holds every node within reach.
TEST(Search, AFixedCentreFarFromOtherBodiesAndVariableNodesIsQuiet) {
    NodeStore n = two_fixed_blocks_and_a_variable_one();
    NeighbourScratch scratch;
    CompressedRows candidates;
    find_neighbours(n, 1.0, n.size(), candidates, scratch, nullptr, 0.01, true);
    ASSERT_EQ(scratch.quiet.size(), n.size());
    const std::size_t deep = 3 * 15 + 3, top = 14 * 15 + 3, side = 7 * 15 + 14;  // of body 0
    EXPECT_EQ(scratch.quiet[deep], 1);
    EXPECT_EQ(candidates.row_size(deep), n.fixed_neighbours.row_size(deep));
    EXPECT_EQ(scratch.quiet[top], 0) << "body 1 is within reach";
    EXPECT_GT(candidates.row_size(top), n.fixed_neighbours.row_size(top));
    EXPECT_EQ(scratch.quiet[side], 0) << "the variable body 2 is within reach";
    for (std::size_t i = 2 * 225; i < n.size(); ++i) ASSERT_EQ(scratch.quiet[i], 0) << "a variable centre is never quiet";
    std::size_t quiet = 0;
    for (auto q : scratch.quiet) quiet += q;
    EXPECT_GT(quiet, 100u);
    // Without candidates nothing is flagged, and the lists are those of the all-pairs loop.
    CompressedRows lists;
    find_neighbours(n, 1.0, n.size(), lists, scratch);
    EXPECT_TRUE(scratch.quiet.empty());
    expect_same_sets(lists, find_neighbours_brute_force(n, 1.0, n.size()));
}

// A fixed centre one of whose lattice neighbours has switched is not quiet, even where that
// neighbour has left its cells: the cut keeps a quiet row whole (filter_candidates), and the
// switched neighbour is a pair only within reach. Here the neighbour of a deep node of body 0 has
// been carried far below the blocks; the cut of the candidates must give the all-pairs lists,
// without that pair (until 2026-12-07 the deep node was quiet and kept it).
TEST(Search, AFixedCentreWhoseLatticeNeighbourSwitchedIsNotQuiet) {
    NodeStore n = two_fixed_blocks_and_a_variable_one();
    const std::size_t deep = 3 * 15 + 3, neighbour = 3 * 15 + 4;
    const auto lattice = n.fixed_neighbours.row(deep);
    ASSERT_NE(std::find(lattice.begin(), lattice.end(), static_cast<NodeIndex>(neighbour)), lattice.end());
    n.connectivity[neighbour] = Connectivity::Variable;
    n.position[1][neighbour] = -0.5;  // 25 spacings below the blocks, far beyond reach
    NeighbourScratch scratch;
    CompressedRows candidates, cut;
    find_neighbours(n, 1.0, n.size(), candidates, scratch, nullptr, 0.01, true);
    EXPECT_EQ(scratch.quiet[deep], 0) << "a lattice neighbour has switched";
    EXPECT_EQ(scratch.quiet[3 * 15 + 10], 1) << "a deep node whose lattice neighbours are fixed stays quiet";
    std::vector<std::uint32_t> lattice_entries(n.size(), 0);
    for (std::size_t i = 0; i < n.size(); ++i) {
        if (n.connectivity[i] == Connectivity::Fixed) lattice_entries[i] = static_cast<std::uint32_t>(n.fixed_neighbours.row_size(i));
    }
    std::vector<std::uint64_t> keep;
    LatticeRowsKept kept;
    kept.switching = true;
    kept.quiet = scratch.quiet.data();
    kept.quiet_rows = scratch.quiet.size();
    filter_candidates(n, 1.0, candidates, lattice_entries, cut, keep, kept);
    const auto row = cut.row(deep);
    EXPECT_EQ(std::find(row.begin(), row.end(), static_cast<NodeIndex>(neighbour)), row.end());
    expect_same_sets(cut, find_neighbours_brute_force(n, 1.0, n.size()));
}

// The rows of some centres alone (find_neighbours with `only`, NeighbourLists::search_rows) are
// entry for entry the rows a search of every centre gives them: lattice rows, quiet and not,
// candidates with a skin, outsized nodes; centres that do not ascend are refused.
TEST(Search, TheRowsOfSomeCentresAloneAreThoseOfAFullSearch) {
    NodeStore blocks = two_fixed_blocks_and_a_variable_one();
    NodeStore cloud = random_cloud(GeometryKind::PlaneStrain, 3000, 7);
    make_outsized(cloud, 7);
    for (NodeStore* n : {&blocks, &cloud}) {
        for (double skin : {0.0, 0.05}) {
            NeighbourScratch scratch;
            CompressedRows all, some;
            find_neighbours(*n, InfluenceDistance(1.2), n->size(), all, scratch, nullptr, skin, true);
            const std::vector<std::uint8_t> quiet_all = scratch.quiet;
            std::vector<NodeIndex> only;
            for (std::size_t i = 1; i < n->size(); i += 7) only.push_back(static_cast<NodeIndex>(i));
            find_neighbours(*n, InfluenceDistance(1.2), n->size(), some, scratch, nullptr, skin, true, only);
            ASSERT_EQ(some.rows(), only.size());
            for (std::size_t k = 0; k < only.size(); ++k) {
                const auto a = all.row(only[k]), b = some.row(k);
                ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << "centre " << only[k] << ", skin " << skin;
                if (!quiet_all.empty()) {
                    ASSERT_EQ(scratch.quiet[only[k]], quiet_all[only[k]]) << "centre " << only[k];
                }
            }
        }
    }
    NeighbourScratch scratch;
    CompressedRows out;
    const std::vector<NodeIndex> descending{5, 3};
    EXPECT_THROW(find_neighbours(blocks, InfluenceDistance(1.0), blocks.size(), out, scratch, nullptr, 0.0, false, descending),
                 InputError);
    const std::vector<NodeIndex> beyond{static_cast<NodeIndex>(blocks.size())};
    EXPECT_THROW(find_neighbours(blocks, InfluenceDistance(1.0), blocks.size(), out, scratch, nullptr, 0.0, false, beyond),
                 InputError);
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

// A search makes its rows in waves of blocks of 1024 centres (four blocks per thread or a
// thirty-second of them, whichever is more): the lists must not depend on where the waves fall,
// nor on how large the lists were before.
TEST(Search, RowsMadeInWavesAreOneSearchWhateverTheThreadsAndTheListsBefore) {
    // Diameters that grow with the index, so that the first wave's rows are the sparsest and the
    // lists grow in the later waves: about 3 to 80 neighbours per node at a = 1.2.
    auto n = random_cloud(GeometryKind::PlaneStrain, 40000, 11);
    for (std::size_t i = 0; i < n.size(); ++i) n.diameter[i] *= 0.05 + 0.2 * static_cast<double>(i) / static_cast<double>(n.size());
    const auto search_on = [](const NodeStore& nodes, int threads, double a, CompressedRows& out, NeighbourScratch& scratch) {
        tbb::task_arena arena(threads);
        arena.execute([&] { find_neighbours(nodes, a, nodes.size(), out, scratch); });
    };
    // 40 blocks: ten waves on one thread, five on two.
    CompressedRows one, two;
    NeighbourScratch scratch_one, scratch_two;
    std::vector<std::size_t> seen;  // what the memory check is shown, wave after wave
    scratch_one.check_entries = [&](std::size_t entries) { seen.push_back(entries); };
    search_on(n, 1, 1.2, one, scratch_one);
    search_on(n, 2, 1.2, two, scratch_two);
    EXPECT_EQ(one, two);  // identical lists, identical order
    EXPECT_GT(one.entries(), 10 * n.size());
    // First the guess from every 32nd row, then the entries made so far after each of the ten
    // waves. The guess: a sample of 1250 rows whose sizes change smoothly with the index, so within
    // a tenth of the lists.
    ASSERT_EQ(seen.size(), 11u);
    EXPECT_NEAR(static_cast<double>(seen.front()) / static_cast<double>(one.entries()), 1.0, 0.1);
    EXPECT_TRUE(std::is_sorted(seen.begin() + 1, seen.end()));
    EXPECT_EQ(seen.back(), one.entries());
    // The lists' room is guessed from every 32nd row; with those rows' nodes made small, the guess
    // falls short and the lists outgrow their room in a later wave, as they do after a smaller
    // search in the same arrays.
    auto m = n;
    for (std::size_t i = 0; i < m.size(); i += 32) m.diameter[i] *= 0.01;
    CompressedRows fresh, grown;
    NeighbourScratch fresh_scratch, scratch;
    search_on(m, 2, 1.2, fresh, fresh_scratch);
    search_on(m, 2, 0.8, grown, scratch);
    const std::size_t before = grown.indices.capacity();
    search_on(m, 2, 1.2, grown, scratch);
    EXPECT_LT(before, grown.entries());
    EXPECT_EQ(grown, fresh);
    // A guess beyond the memory limit refuses nothing: with every 32nd node three times as large,
    // the guess is several times the lists, and a limit between the two lets the search end with
    // the lists of a search without a limit.
    auto big = n;
    for (std::size_t i = 0; i < big.size(); i += 32) big.diameter[i] *= 3.0;
    CompressedRows unlimited, limited;
    NeighbourScratch unlimited_scratch, limited_scratch;
    std::vector<std::size_t> guesses;
    unlimited_scratch.check_entries = [&](std::size_t entries) { guesses.push_back(entries); };
    search_on(big, 2, 1.2, unlimited, unlimited_scratch);
    ASSERT_GT(guesses.front(), 2 * unlimited.entries());
    const std::size_t limit = unlimited.entries() + unlimited.entries() / 2;
    limited_scratch.check_entries = [&](std::size_t entries) {
        if (entries > limit) throw LimitError("a test limit");
    };
    search_on(big, 2, 1.2, limited, limited_scratch);
    EXPECT_EQ(limited, unlimited);
    EXPECT_LT(limited.indices.capacity(), guesses.front());  // no room made for the guess
    // Against all pairs on a cloud of six blocks, in two waves on one thread.
    auto small = random_cloud(GeometryKind::ThreeD, 6000, 12);
    for (auto& d : small.diameter) d *= 0.8;
    CompressedRows waves;
    NeighbourScratch small_scratch;
    tbb::task_arena arena(1);
    arena.execute([&] { find_neighbours(small, 1.2, small.size(), waves, small_scratch); });
    expect_same_sets(waves, find_neighbours_brute_force(small, 1.2, small.size()));
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
