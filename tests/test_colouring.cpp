// Scatter plans: no two groups of one colour write the same node, and forces are bit-identical
// on 1, 2 and 4 threads for every plan.

#include <cstring>
#include <random>

#include "gpa/engine/lattice.hpp"

#include <gtest/gtest.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

PositionView view(const NodeStore& n) {
    PositionView v;
    v.dim = n.dim();
    for (int c = 0; c < n.dim(); ++c) v.component[c] = n.position[c].data();
    return v;
}

struct Body {
    NodeStore nodes;
    CompressedRows lists;
};

Body make_body(GeometryKind g, Connectivity c) {
    testing::LatticeOptions o;
    o.geometry = g;
    o.cells = g == GeometryKind::ThreeD ? 14 : 60;
    o.spacing = 0.001;
    o.connectivity = c;
    Body b{testing::make_lattice(o), {}};
    testing::jitter(b.nodes, 0.15, o.spacing, 8);
    testing::vary_diameters(b.nodes, 0.1, 2);
    testing::randomise_state(b.nodes, 6);
    b.lists = find_neighbours(b.nodes, 1.0, b.nodes.size());
    return b;
}

TEST(Colouring, EveryPlanIsConflictFree) {
    for (auto g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        for (auto c : {Connectivity::Fixed, Connectivity::Variable}) {
            const auto b = make_body(g, c);
            for (auto s : {ScatterScheme::Slabs, ScatterScheme::Cells, ScatterScheme::Graph, ScatterScheme::Serial}) {
                const auto plan = make_plan(s, b.lists, view(b.nodes), b.nodes.size());
                EXPECT_TRUE(plan_is_conflict_free(plan, b.lists, b.nodes.size()))
                    << name_of(g) << " " << name_of(s) << " " << (c == Connectivity::Fixed ? "fixed" : "variable");
                if (s != ScatterScheme::Serial) {
                    // At least two groups per colour on average, or nothing runs in parallel.
                    EXPECT_GE(plan.groups(), 2 * plan.colours()) << name_of(g) << " " << name_of(s);
                }
            }
        }
    }
}

TEST(Colouring, TheCheckCatchesAConflict) {
    const auto b = make_body(GeometryKind::PlaneStrain, Connectivity::Variable);
    // Two neighbouring centres in separate groups of one colour write the same nodes.
    ScatterPlan bad;
    bad.scheme = ScatterScheme::Graph;
    for (std::size_t i = 0; i < b.lists.rows(); ++i) {
        bad.centres.push_back(static_cast<NodeIndex>(i));
        bad.group_offsets.push_back(bad.centres.size());
    }
    bad.colour_offsets.push_back(bad.groups());
    EXPECT_FALSE(plan_is_conflict_free(bad, b.lists, b.nodes.size()));
}

template <class G>
std::vector<double> forces_on(Body& b, const ScatterPlan& plan, int threads, bool bond) {
    ThreadScope scope(threads);
    const BondViscosityParameters params;
    return scope.run([&] {
        compute_velocity_gradient<G>(b.lists, WeightKind::Gpa, gradient_fields<G::dim>(b.nodes, 1.0));
        compute_forces<G>(b.lists, plan, WeightKind::Gpa, bond ? &params : nullptr, force_fields<G::dim>(b.nodes, 1.0),
                          b.nodes.size());
        // Forces first (the first dim * n values), then what the gather wrote.
        std::vector<double> out;
        for (int c = 0; c < G::dim; ++c) out.insert(out.end(), b.nodes.force[c].begin(), b.nodes.force[c].end());
        for (int c = 0; c < G::dim; ++c) out.insert(out.end(), b.nodes.alpha[c].begin(), b.nodes.alpha[c].end());
        for (int c = 0; c < G::dim * G::dim; ++c) {
            out.insert(out.end(), b.nodes.velocity_gradient[c].begin(), b.nodes.velocity_gradient[c].end());
        }
        return out;
    });
}

TEST(Colouring, ForcesAreBitIdenticalOnOneTwoAndFourThreads) {
    for (auto g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        for (auto c : {Connectivity::Fixed, Connectivity::Variable}) {
            auto b = make_body(g, c);
            for (auto s : {ScatterScheme::Slabs, ScatterScheme::Cells, ScatterScheme::Graph}) {
                const auto plan = make_plan(s, b.lists, view(b.nodes), b.nodes.size());
                for (bool bond : {false, true}) {
                    dispatch_geometry(g, [&](auto tag) {
                        using G = decltype(tag);
                        const auto one = forces_on<G>(b, plan, 1, bond);
                        const auto two = forces_on<G>(b, plan, 2, bond);
                        const auto four = forces_on<G>(b, plan, 4, bond);
                        ASSERT_EQ(one.size(), two.size());
                        EXPECT_EQ(0, std::memcmp(one.data(), two.data(), one.size() * sizeof(double)))
                            << name_of(g) << " " << name_of(s) << " 1 vs 2 threads";
                        EXPECT_EQ(0, std::memcmp(one.data(), four.data(), one.size() * sizeof(double)))
                            << name_of(g) << " " << name_of(s) << " 1 vs 4 threads";
                        // Plans differ only in the order of summation: round-off apart.
                        const auto serial = forces_on<G>(b, make_serial_plan(b.lists), 1, bond);
                        double worst = 0.0, scale = 0.0;
                        for (std::size_t k = 0; k < G::dim * b.nodes.size(); ++k) {
                            worst = std::max(worst, std::abs(one[k] - serial[k]));
                            scale = std::max(scale, std::abs(serial[k]));
                        }
                        EXPECT_LE(worst, 1e-12 * scale) << name_of(s) << " differs from the serial twin";
                    });
                }
            }
        }
    }
}

}  // namespace
}  // namespace gpa

namespace gpa {
namespace {

// Regular lattices put centres exactly on slab and cell boundaries (the reach is a whole number
// of spacings): rounding must not put one in the wrong group.
TEST(Colouring, RegularLatticesWithRandomOriginsAndSpacingsAreConflictFree) {
    std::mt19937_64 rng(12);
    std::uniform_real_distribution<double> spacing(1e-4, 2e-3), origin(-0.05, 0.05);
    std::uniform_int_distribution<int> cells(6, 30);
    for (int trial = 0; trial < 4000; ++trial) {
        NodeStore n(GeometryKind::PlaneStrain);
        LatticeBlock b;
        const double dx = spacing(rng);
        b.spacing = {dx, dx, dx};
        b.origin = {origin(rng), origin(rng), 0.0};
        b.last = {cells(rng), cells(rng), 1};
        b.connectivity = Connectivity::Fixed;
        fill_lattice(n, b);
        const auto lists = find_neighbours(n, 1.0, n.size());
        for (auto s : {ScatterScheme::Slabs, ScatterScheme::Cells}) {
            ASSERT_TRUE(plan_is_conflict_free(make_plan(s, lists, view(n), n.size()), lists, n.size()))
                << name_of(s) << " trial " << trial << " dx " << dx;
        }
    }
}

}  // namespace
}  // namespace gpa
