// Bodies that touch without welding and cracks that open (separation.hpp, docs/contact.md), and
// the per-body results of body_report.hpp.

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include "gpa/engine/body_report.hpp"
#include "gpa/engine/colouring.hpp"
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/engine/separation.hpp"
#include "gpa/engine/simulation.hpp"
#include "support/lattices.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

// A jittered plane-strain lattice in two bodies (left and right half), random stresses and
// velocities: every pair across the halves is separable, and about half of them open.
NodeStore two_body_lattice(std::uint64_t seed) {
    testing::LatticeOptions o;
    o.cells = 14;
    o.spacing = 0.01;
    NodeStore n = testing::make_lattice(o);
    testing::jitter(n, 0.2, o.spacing, seed);
    testing::randomise_state(n, seed + 1);
    for (std::size_t i = 0; i < n.size(); ++i) n.body[i] = n.position[0][i] < 0.07 ? 0 : 1;
    return n;
}

TEST(Separation, BothEndsOfEveryPairGiveTheSameAnswerAndTheListsStaySymmetric) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        NodeStore n = two_body_lattice(seed);
        // Some failed nodes inside one body too.
        for (std::size_t i = 0; i < n.size(); i += 7) n.failed[i] = 1;
        CompressedRows lists = find_neighbours(n, 1.0, n.size());
        std::size_t open = 0, separable = 0;
        for (std::size_t i = 0; i < n.size(); ++i) {
            for (NodeIndex j : lists.row(i)) {
                ASSERT_EQ(pair_is_open(n, i, j, true), pair_is_open(n, j, i, true)) << i << " " << j;
                open += pair_is_open(n, i, j, true);
                separable += n.body[i] != n.body[j] || n.failed[i] || n.failed[j];
            }
        }
        // The random state must exercise both outcomes, or the test would see nothing (about one
        // separable pair in eight opens: both conditions hold for a quarter, minus the failed ones).
        EXPECT_GT(open, separable / 20);
        EXPECT_LT(open, separable);
        const SeparationCounts counts = remove_open_pairs(lists, n, n.size(), true);
        EXPECT_EQ(counts.open, open);
        EXPECT_EQ(counts.closed + counts.open, separable);
        std::set<std::pair<NodeIndex, NodeIndex>> pairs;
        for (std::size_t i = 0; i < n.size(); ++i) {
            for (NodeIndex j : lists.row(i)) pairs.insert({static_cast<NodeIndex>(i), j});
        }
        for (const auto& [i, j] : pairs) ASSERT_TRUE(pairs.count({j, i})) << "pair " << i << "-" << j << " kept on one side only";
    }
}

TEST(Separation, BlocksOfRowsCutInParallelGiveTheRowByRowListsOnOneAndTwoThreads) {
    // remove_open_pairs cuts blocks of 1024 rows in parallel, each inside its own stretch of the
    // entries, then moves the blocks together. 60 x 60 cells (3721 rows: four blocks, the last
    // short), with failed nodes scattered through both bodies so that every block loses entries:
    // the rows must be, entry for entry and in order, a row-by-row filter by pair_is_open, and the
    // closing speeds and contact directions the same on 1 and 2 threads.
    testing::LatticeOptions o;
    o.cells = 60;
    o.spacing = 0.01;
    NodeStore n = testing::make_lattice(o);
    testing::jitter(n, 0.2, o.spacing, 7);
    testing::randomise_state(n, 8);
    for (std::size_t i = 0; i < n.size(); ++i) n.body[i] = n.position[0][i] < 0.3 ? 0 : 1;
    for (std::size_t i = 0; i < n.size(); i += 11) n.failed[i] = 1;
    ASSERT_GT(n.size(), 3u * 1024u);
    const CompressedRows searched = find_neighbours(n, 1.0, n.size());
    CompressedRows expected;
    expected.offsets.assign(1, 0);
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (NodeIndex j : searched.row(i)) {
            if (!pair_is_open(n, i, j, true)) expected.indices.push_back(j);
        }
        expected.offsets.push_back(expected.indices.size());
    }
    ASSERT_LT(expected.indices.size(), searched.indices.size() - 200) << "too few pairs open to see a block's move";
    std::vector<std::vector<double>> closing(2), direction(2);
    for (int threads : {1, 2}) {
        CompressedRows lists = searched;
        std::vector<double> speed(n.size(), -1.0), x(n.size(), -1.0), z(n.size(), -1.0);
        ThreadScope scope(threads);
        scope.run([&] { remove_open_pairs(lists, n, n.size(), true, speed.data(), {x.data(), z.data(), nullptr}, 1.0); });
        ASSERT_EQ(lists.offsets, expected.offsets) << threads << " thread(s)";
        ASSERT_EQ(lists.indices, expected.indices) << threads << " thread(s)";
        closing[threads - 1] = speed;
        direction[threads - 1] = x;
        direction[threads - 1].insert(direction[threads - 1].end(), z.begin(), z.end());
    }
    EXPECT_EQ(closing[0], closing[1]);
    EXPECT_EQ(direction[0], direction[1]);
    EXPECT_GT(*std::max_element(closing[0].begin(), closing[0].end()), 0.0) << "some pair must be closing";
}

TEST(Separation, APairOpensOnlyWhenItSeparatesWithoutCompression) {
    NodeStore n = two_body_lattice(4);
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (int c = 0; c < 4; ++c) n.deviatoric_stress[c][i] = 0.0;
        n.pressure[i] = 0.0;
        n.viscous_pressure[i] = 0.0;
        n.velocity[0][i] = n.velocity[1][i] = 0.0;
    }
    // Two neighbours across the interface along x.
    const CompressedRows lists = find_neighbours(n, 1.0, n.size());
    std::size_t i = 0, j = 0;
    for (std::size_t k = 0; k < n.size() && !j; ++k) {
        for (NodeIndex m : lists.row(k)) {
            if (n.body[k] == 0 && n.body[m] == 1) {
                i = k;
                j = m;
                break;
            }
        }
    }
    ASSERT_NE(i, j);
    const double dx = n.position[0][j] - n.position[0][i];
    ASSERT_GT(dx, 0.0);
    EXPECT_TRUE(pair_is_open(n, i, j, false)) << "at rest and stress-free: open (no force either way)";
    n.velocity[0][i] = 1.0;  // i moves towards j
    EXPECT_FALSE(pair_is_open(n, i, j, false)) << "approaching: closed";
    n.velocity[0][i] = -1.0;  // moving apart
    n.pressure[i] = n.pressure[j] = -1e6;  // in tension
    EXPECT_TRUE(pair_is_open(n, i, j, false)) << "separating in tension: open";
    n.pressure[i] = 3e6;  // compression at one end outweighs the tension at the other
    EXPECT_FALSE(pair_is_open(n, i, j, false)) << "separating but compressed: closed";
    // Same body: never separable unless a node has failed.
    n.body[j] = n.body[i];
    n.pressure[i] = -1e6;
    EXPECT_FALSE(pair_is_open(n, i, j, false));
    n.failed[j] = 1;
    EXPECT_FALSE(pair_is_open(n, i, j, false)) << "failed pairs only with failed_pairs_separate";
    EXPECT_TRUE(pair_is_open(n, i, j, true));
}

// A target (body 1) at rest under a projectile (body 0) moving down, both plane-strain lattices;
// a crater is cut by failing the target's nodes within `crater_radius` of the top centre.
struct CraterCase {
    NodeStore nodes{GeometryKind::PlaneStrain};
    double spacing = 0.5e-3, width = 20e-3, thickness = 8e-3;
};

CraterCase crater_case(double crater_radius, double spacing) {
    CraterCase c;
    c.spacing = spacing;
    LatticeBlock target;
    target.origin = {-0.5 * c.width, 0.0, 0.0};
    target.spacing = {spacing, spacing, spacing};
    target.first = {0, 0, 0};
    target.last = {static_cast<int>(std::lround(c.width / spacing)), static_cast<int>(std::lround(c.thickness / spacing)), 1};
    target.density = 7800.0;
    target.connectivity = Connectivity::Variable;
    target.body = 1;
    fill_lattice(c.nodes, target);
    LatticeBlock projectile = target;
    projectile.origin = {-2e-3, c.thickness + 1e-3, 0.0};
    projectile.last = {static_cast<int>(std::lround(4e-3 / spacing)), static_cast<int>(std::lround(4e-3 / spacing)), 1};
    projectile.body = 0;
    fill_lattice(c.nodes, projectile);
    c.nodes.initial_position = c.nodes.position;
    c.nodes.initial_diameter = c.nodes.diameter;
    for (std::size_t i = 0; i < c.nodes.size(); ++i) {
        const double x = c.nodes.position[0][i], z = c.nodes.position[1][i] - c.thickness;
        if (c.nodes.body[i] == 1 && std::hypot(x, z) < crater_radius) c.nodes.failed[i] = 1;
    }
    return c;
}

TEST(BodyReport, CraterDepthAndDiameterFollowTheCutToWithinASpacingAtEveryResolution) {
    const double radius = 3e-3;
    for (double spacing : {0.5e-3, 0.25e-3, 0.125e-3}) {
        CraterCase c = crater_case(radius, spacing);
        const std::vector<std::array<double, 3>> velocity{{0.0, -1000.0, 0.0}, {0.0, 0.0, 0.0}};
        const ImpactFrame frame = impact_frame(c.nodes, c.nodes.size(), velocity, false);
        ASSERT_TRUE(frame.defined);
        EXPECT_EQ(frame.projectile, 0);
        // Levels count against the impact direction u = -z, so the front face is the top, z = thickness.
        EXPECT_NEAR(frame.front_level[1], c.thickness, 1e-12);
        const CompressedRows lists = find_neighbours(c.nodes, 1.0, c.nodes.size());
        std::vector<BodyTotals> bodies(2);
        measure_bodies(c.nodes, c.nodes.size(), lists, frame, bodies);
        EXPECT_FALSE(bodies[0].target);
        ASSERT_TRUE(bodies[1].target);
        EXPECT_FALSE(bodies[1].perforated);
        // A lattice approximates the cut circle by whole nodes: within one spacing (the rule's promise).
        EXPECT_NEAR(bodies[1].crater_depth, radius, spacing) << "spacing " << spacing;
        EXPECT_NEAR(bodies[1].crater_diameter, 2.0 * radius, 2.0 * spacing) << "spacing " << spacing;
        EXPECT_EQ(bodies[1].pieces, 1u);
        EXPECT_EQ(bodies[0].pieces, 1u);
    }
}

TEST(BodyReport, ResidualVelocityLeavesOutFailedNodesAndSeparatedFragments) {
    CraterCase c = crater_case(0.0, 0.5e-3);
    const std::size_t n = c.nodes.size();
    // The projectile moves down at 1000 m/s; three of its nodes have failed and fly at 5000 m/s,
    // and a fragment of its top row, cut off by failed nodes, flies up.
    double top = -1.0;
    for (std::size_t i = 0; i < n; ++i) {
        if (c.nodes.body[i] == 0) {
            c.nodes.velocity[1][i] = -1000.0;
            top = std::max(top, c.nodes.position[1][i]);
        }
    }
    std::size_t failed = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (c.nodes.body[i] != 0) continue;
        const bool top_row = std::abs(c.nodes.position[1][i] - top) < 1e-9;
        const bool below_top = std::abs(c.nodes.position[1][i] - (top - c.spacing)) < 1e-9;
        const bool below_below = std::abs(c.nodes.position[1][i] - (top - 2.0 * c.spacing)) < 1e-9;
        if (top_row) c.nodes.velocity[1][i] = +300.0;
        if (below_top || below_below) {  // two rows, so no pair within 2 h reaches across
            c.nodes.failed[i] = 1;
            c.nodes.velocity[1][i] = -5000.0;
            ++failed;
        }
    }
    ASSERT_GT(failed, 0u);
    const std::vector<std::array<double, 3>> velocity{{0.0, -1000.0, 0.0}, {0.0, 0.0, 0.0}};
    const ImpactFrame frame = impact_frame(c.nodes, n, velocity, false);
    const CompressedRows lists = find_neighbours(c.nodes, 1.0, n);
    std::vector<BodyTotals> bodies(2);
    measure_bodies(c.nodes, n, lists, frame, bodies);
    EXPECT_EQ(bodies[0].pieces, 2u);
    EXPECT_NEAR(bodies[0].residual_velocity[1], -1000.0, 1e-9);
    EXPECT_NEAR(bodies[0].residual_speed_along_axis, 1000.0, 1e-9);
}

// Spec section 2, "[spec] Sliding contact": the contact directions of a separation pass and the
// pair fields that read them.
struct SlidingSetUp {
    NodeStore nodes;
    CompressedRows lists;
    std::array<std::vector<double>, 3> towards;
};

SlidingSetUp sliding_set_up(NodeStore n, bool failed_pairs_separate) {
    SlidingSetUp s{std::move(n), {}, {}};
    s.lists = find_neighbours(s.nodes, 1.0, s.nodes.size());
    std::array<double*, 3> out{};
    for (int c = 0; c < s.nodes.dim(); ++c) {
        s.towards[c].assign(s.nodes.size(), 0.0);
        out[c] = s.towards[c].data();
    }
    remove_open_pairs(s.lists, s.nodes, s.nodes.size(), failed_pairs_separate, nullptr, out, 1.0);
    return s;
}

PairFields<2> sliding_pairs(const SlidingSetUp& s, bool failed_pairs_separate) {
    PairFields<2> p = pair_fields<2>(s.nodes, 1.0);
    p.sliding_contact = true;
    p.failed_pairs_separate = failed_pairs_separate;
    p.failed = s.nodes.failed.data();
    for (int c = 0; c < 2; ++c) p.contact_direction[c] = s.towards[c].data();
    return p;
}

TEST(SlidingContact, OnAFlatInterfaceEveryPairActsAlongTheSurfaceNormal) {
    // Two regular lattices, one above the other, pressed together (P > 0, so no pair opens).
    testing::LatticeOptions o;
    o.cells = 16;
    NodeStore n = testing::make_lattice(o);
    for (std::size_t i = 0; i < n.size(); ++i) {
        n.body[i] = n.position[1][i] < 8.0 ? 0 : 1;
        n.pressure[i] = 1.0;
        // The upper body slid by 0.3 of a spacing: no node has a partner straight across.
        if (n.body[i] == 1) n.position[0][i] += 0.3;
    }
    const SlidingSetUp s = sliding_set_up(std::move(n), false);
    const PairFields<2> p = sliding_pairs(s, false);
    std::size_t checked = 0, diagonal = 0;
    for (std::size_t i = 0; i < s.nodes.size(); ++i) {
        // Away from the lattice's sides, where the interface ends.
        if (s.nodes.position[0][i] < 3.0 || s.nodes.position[0][i] > 13.0) continue;
        for (NodeIndex j : s.lists.row(i)) {
            if (s.nodes.body[i] == s.nodes.body[j]) continue;
            ASSERT_TRUE(p.sliding(i, j));
            const PairGeometry<2> g = p.pair<GpaWeight>(i, j);
            const Vec<2> normal = p.sliding_normal(i, j, g.l);
            // From i towards j's body: straight down from the upper body, up from the lower.
            const double down = s.nodes.body[i] == 1 ? -1.0 : 1.0;
            EXPECT_NEAR(normal[0], 0.0, 1e-15) << i << "-" << j;
            EXPECT_NEAR(normal[1], down, 1e-15) << i << "-" << j;
            // Both ends project alike: n_ji = -n_ij.
            EXPECT_EQ(p.sliding_normal(j, i, (-g.l).eval()), (-normal).eval());
            diagonal += g.l[0] != 0.0;
            ++checked;
        }
    }
    // With the offset no pair is straight across: every one's own direction differs from the normal.
    EXPECT_EQ(diagonal, checked);
    EXPECT_GT(checked, 40u);
}

TEST(SlidingContact, ForcesStayEqualAndOppositeAndTheirPowerIsMinusTheStressPower) {
    // Jittered bodies with failed nodes and random states: pairs across the bodies and through
    // failed nodes slide. The energy identity of spec section 5 must hold with the projection in
    // both kernels (round-off), and momentum too.
    for (std::uint64_t seed : {4u, 5u}) {
        NodeStore n = two_body_lattice(seed);
        for (std::size_t i = 0; i < n.size(); i += 9) n.failed[i] = 1;
        for (std::size_t i = 0; i < n.size(); ++i) n.pressure[i] += 2.0;  // most pairs closed
        SlidingSetUp s = sliding_set_up(std::move(n), true);
        NodeStore& nodes = s.nodes;
        std::size_t sliding = 0, tilted = 0;
        {
            const PairFields<2> p = sliding_pairs(s, true);
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                for (NodeIndex j : s.lists.row(i)) {
                    if (!p.sliding(i, j)) continue;
                    ++sliding;
                    const auto g = p.pair<GpaWeight>(i, j);
                    tilted += (p.sliding_normal(i, j, g.l) - g.l).norm() > 1e-3;
                }
            }
        }
        ASSERT_GT(sliding, 50u);
        ASSERT_GT(tilted, 10u) << "contact normals must differ from the pairs' own directions somewhere";
        auto g = gradient_fields<2>(nodes, 1.0);
        g.pairs = sliding_pairs(s, true);
        compute_velocity_gradient<PlaneStrain>(s.lists, WeightKind::Gpa, g, nodes.size());
        auto f = force_fields<2>(nodes, 1.0);
        f.pairs = g.pairs;
        compute_forces<PlaneStrain>(s.lists, make_serial_plan(s.lists), WeightKind::Gpa, nullptr, f, nodes.size());
        double force_power = 0.0, stress_power = 0.0, scale = 0.0;
        std::array<double, 2> total{0.0, 0.0};
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            for (int c = 0; c < 2; ++c) {
                force_power += nodes.force[c][i] * nodes.velocity[c][i];
                total[c] += nodes.force[c][i];
                scale += std::abs(nodes.force[c][i] * nodes.velocity[c][i]);
            }
            const double p = nodes.pressure[i] + nodes.viscous_pressure[i];
            const double sxx = nodes.deviatoric_stress[0][i] - p, szz = nodes.deviatoric_stress[1][i] - p,
                         sxz = nodes.deviatoric_stress[2][i];
            const double lxx = nodes.velocity_gradient[0][i], lxz = nodes.velocity_gradient[1][i],
                         lzx = nodes.velocity_gradient[2][i], lzz = nodes.velocity_gradient[3][i];
            stress_power -= nodes.volume[i] * (sxx * lxx + szz * lzz + sxz * (lxz + lzx));
        }
        EXPECT_NEAR(force_power, stress_power, 1e-12 * scale) << "seed " << seed;
        EXPECT_NEAR(total[0], 0.0, 1e-12 * scale);
        EXPECT_NEAR(total[1], 0.0, 1e-12 * scale);
        // The compatible booking's stress power at other velocities is the force power there.
        std::vector<double> power(nodes.size()), viscous(nodes.size());
        std::array<std::vector<double>, 2> w{nodes.velocity[1], nodes.velocity[0]};
        compute_stress_power<PlaneStrain>(s.lists, WeightKind::Gpa, f, {w[0].data(), w[1].data()}, nodes.size(), power.data(),
                                          viscous.data());
        double booked = 0.0, at_w = 0.0;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            booked += power[i];
            at_w += nodes.force[0][i] * w[0][i] + nodes.force[1][i] * w[1][i];
        }
        EXPECT_NEAR(booked, at_w, 1e-12 * scale) << "seed " << seed;
    }
}

// Two equal blocks, one sliding across the other at 20 m/s while pressed onto it at 5 m/s: the
// tangential impulse the lower block has received after 6 us, and the largest normal impulse.
struct Impulses {
    double tangential = 0.0, normal = 0.0;
};

Impulses sliding_blocks(double width, bool sliding_contact) {
    Scene s;
    s.name = "sliding blocks";
    s.geometry = GeometryKind::PlaneStrain;
    s.materials.push_back(testing::elastic_material("elastic steel", 7800.0, 200e9, 0.3));
    BodySpec base;
    base.name = "base";
    base.shape = ShapeKind::Rectangle;
    base.origin = {0.0, 0.0, 0.0};
    base.size = {width, 4e-3, 0.0};
    base.spacing = 0.5e-3;
    base.material = "elastic steel";
    BodySpec slider = base;
    slider.name = "slider";
    slider.origin = {0.0, 4e-3, 0.0};  // touching (node centres one spacing apart)
    slider.velocity = {20.0, -5.0, 0.0};
    s.bodies = {base, slider};
    s.solver.viscosity = ViscosityKind::Nodal;
    s.solver.connectivity = ConnectivityMode::Variable;
    s.solver.sliding_contact = sliding_contact;
    s.stop.end_time = 6e-6;
    Simulation sim(s, 2);
    Impulses out;
    while (!sim.finished()) {
        sim.step();
        out.normal = std::max(out.normal, -sim.totals().bodies[0].momentum[1]);
    }
    out.tangential = sim.totals().bodies[0].momentum[0];
    return out;
}

TEST(SlidingContact, PressedFacesSlideWithoutFrictionAndOnlyTheirEndsDrag) {
    const Impulses slide = sliding_blocks(24e-3, true), slide_long = sliding_blocks(48e-3, true);
    const Impulses stick = sliding_blocks(24e-3, false), stick_long = sliding_blocks(48e-3, false);
    std::printf("tangential / normal impulse, 24 and 48 mm: sliding %.4g / %.4g, %.4g / %.4g; sticking %.4g / %.4g, %.4g / %.4g\n",
                slide.tangential, slide.normal, slide_long.tangential, slide_long.normal, stick.tangential, stick.normal,
                stick_long.tangential, stick_long.normal);
    // Twice the face carries twice the normal load in both models (the slider is pressed the same
    // way along its length; 10 %: the ends, a spacing each, are a twentieth of the longer face).
    EXPECT_NEAR(slide_long.normal / slide.normal, 2.0, 0.2);
    EXPECT_NEAR(stick_long.normal / stick.normal, 2.0, 0.2);
    // Where pairs carry shear, the face grips along its whole length: the drag grows with it.
    EXPECT_GT(stick_long.tangential / stick.tangential, 1.6);
    EXPECT_GT(stick.tangential, 2.0 * slide.tangential);
    // Sliding contact: the faces themselves transmit no tangential force, only the four corners
    // at the ends of the contact, where the two bodies' normals differ, do: the drag is the same
    // whatever the length of the face (10 %: the corners' loads differ with the wave pattern).
    EXPECT_NEAR(slide_long.tangential / slide.tangential, 1.0, 0.1);
}

// Two elastic plane-strain blocks, one at 20 m/s, the other at rest, meet face to face.
Scene colliding_blocks(double spacing) {
    Scene s;
    s.name = "colliding blocks";
    s.geometry = GeometryKind::PlaneStrain;
    s.materials.push_back(testing::elastic_material("elastic steel", 7800.0, 200e9, 0.3));
    BodySpec a;
    a.name = "striker";
    a.shape = ShapeKind::Rectangle;
    a.origin = {0.0, 0.0, 0.0};
    a.size = {10e-3, 4e-3, 0.0};
    a.spacing = spacing;
    a.material = "elastic steel";
    a.velocity = {20.0, 0.0, 0.0};
    // Touching at the start (node centres one spacing apart): from a gap, the pairs across it act
    // from r = 2 h on, one spacing before the surfaces meet, and at 20 m/s that soft approach would
    // take 25 us (docs/contact.md, "Stand-off").
    BodySpec b = a;
    b.name = "struck";
    b.origin = {10e-3, 0.0, 0.0};
    b.velocity = {0.0, 0.0, 0.0};
    s.bodies = {a, b};
    s.solver.viscosity = ViscosityKind::Nodal;
    s.solver.connectivity = ConnectivityMode::Variable;
    s.stop.end_time = 12e-6;  // contact lasts about 2 L / c = 4 us
    return s;
}

double closest_approach(const NodeStore& n, std::size_t real) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < real; ++i) {
        if (n.body[i] != 0 || n.position[0][i] < 9e-3) continue;
        for (std::size_t j = 0; j < real; ++j) {
            if (n.body[j] != 1 || n.position[0][j] > 12e-3) continue;
            best = std::min(best, std::hypot(n.position[0][j] - n.position[0][i], n.position[1][j] - n.position[1][i]));
        }
    }
    return best;
}

TEST(Contact, ElasticBlocksMeetExchangeMomentumAndSeparateWithoutWelding) {
    const double spacing = 0.5e-3;
    Simulation sim(colliding_blocks(spacing), 2);
    const double p0 = sim.totals().momentum[0];
    double closest = std::numeric_limits<double>::infinity();
    bool touched = false;
    while (!sim.finished()) {
        sim.step();
        const double d = closest_approach(sim.nodes(), sim.real_count());
        closest = std::min(closest, d);
        touched |= sim.totals().bodies[1].kinetic_energy > 1e-3 * sim.totals().initial_kinetic_energy;
        // Momentum: the pair forces are equal and opposite whatever opens (round-off).
        ASSERT_NEAR(sim.totals().momentum[0], p0, 1e-10 * std::abs(p0));
    }
    ASSERT_TRUE(touched);
    // No node of one block gets within half a spacing of the other's.
    EXPECT_GT(closest, 0.5 * spacing);
    sim.measure_bodies();
    const auto& striker = sim.totals().bodies[0];
    const auto& struck = sim.totals().bodies[1];
    // Equal elastic bars exchange velocities; the blocks are 2.5 times longer than tall, so part of
    // the energy stays in lateral vibration: the struck block leaves at more than 80 % of 20 m/s,
    // and the striker keeps less than 20 % of it.
    EXPECT_GT(struck.centre_velocity[0], 16.0);
    EXPECT_LT(std::abs(striker.centre_velocity[0]), 4.0);
    // They have separated: the struck block is faster and they are more than a spacing apart.
    EXPECT_GT(struck.centre_velocity[0] - striker.centre_velocity[0], 12.0);
    EXPECT_GT(closest_approach(sim.nodes(), sim.real_count()), spacing);
    EXPECT_EQ(striker.pieces, 1u);
    EXPECT_EQ(struck.pieces, 1u);
    // The compatible energy update conserves energy to the kinetic-energy change of one step: the
    // bound is a hundredth of a percent.
    EXPECT_LT(std::abs(sim.totals().energy_error), 1e-4);
}

TEST(Contact, TwoBodyRunsWithFailureAreBitIdenticalOnOneAndTwoThreads) {
    Scene s = colliding_blocks(0.5e-3);
    s.bodies[0].velocity = {400.0, 0.0, 0.0};
    s.materials[0].failure.spall_pressure = 0.5e9;
    s.solver.failure = true;
    s.solver.connectivity = ConnectivityMode::Automatic;
    s.stop.end_time = 4e-6;
    Simulation one(s, 1), two(s, 2);
    while (!one.finished()) one.step();
    while (!two.finished()) two.step();
    EXPECT_GT(one.totals().failed_nodes, 0u) << "the test must see failed nodes";
    EXPECT_EQ(testing::node_bytes(one), testing::node_bytes(two));
}

}  // namespace
}  // namespace gpa
