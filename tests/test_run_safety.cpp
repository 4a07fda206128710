// Runs that go wrong say where: a failing step names its number (the first step is 1), time,
// phase, node, body, position and field; the energy guard stops an unstable run; sizes from the
// input are checked against the memory limit before they are allocated.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/simulation.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

// Runs until a step fails; returns its report (and fails the test if none did).
StepFailure first_failure(Simulation& sim, int max_steps) {
    for (int k = 0; k < max_steps && !sim.finished(); ++k) {
        try {
            sim.step();
        } catch (const StepFailure& f) {
            return f;
        }
    }
    ADD_FAILURE() << "no step failed in " << max_steps << " steps";
    return StepFailure("none", {});
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(StepFailures, NameTheStepTheTimeThePhaseAndTheNode) {
    // 10 km/s into the anvil with the guard off: a node is crushed within a few steps.
    auto scene = testing::elastic_bar_on_plane(1e-3, 4e-3, 4, 1e4);
    scene.stop.energy_error = 0.0;
    Simulation sim(scene, 2);
    const std::size_t steps_before = [&] {
        Simulation probe(scene, 1);
        std::size_t done = 0;
        try {
            while (!probe.finished()) {
                probe.step();
                ++done;
            }
        } catch (const StepFailure&) {
        }
        return done;
    }();
    const StepFailure f = first_failure(sim, 1000);
    const FailureSite& s = f.site();
    EXPECT_EQ(s.step, steps_before + 1) << "the failing step is counted from 1, one more than the steps done";
    EXPECT_EQ(s.step, sim.steps() + 1);
    EXPECT_EQ(s.time, sim.time());
    const auto phases = sim.phases();
    EXPECT_NE(std::find(phases.begin(), phases.end(), s.phase), phases.end()) << s.phase;
    ASSERT_TRUE(s.node.has_value()) << f.what();
    EXPECT_LT(*s.node, sim.nodes().size());
    EXPECT_EQ(s.body, "bar");
    EXPECT_FALSE(s.field.empty());
    for (int c = 0; c < 2; ++c) EXPECT_EQ(s.position[c], sim.nodes().position[c][*s.node]);
    const std::string m = f.what();
    EXPECT_TRUE(has(m, "step " + std::to_string(s.step)) && has(m, "phase \"" + s.phase + "\"") &&
                has(m, "node " + std::to_string(*s.node)) && has(m, "body \"bar\"") && has(m, "field " + s.field))
        << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << "one line: " << m;
    // The state is half-updated: no further step.
    EXPECT_THROW(sim.step(), NumericalError);
}

TEST(EnergyGuard, StopsARunWithTooLongATimeStep) {
    auto scene = testing::elastic_bar_on_plane(1e-3, 4e-3, 4, 50.0);
    scene.solver.cfl = 1.0;  // past the stable range (docs/scene-format.md, solver.cfl)
    // The compatible energy update conserves energy even while the run goes unstable (it then stops
    // when a node collapses); the guard is for the point update's own energy equation.
    scene.solver.energy_update = EnergyUpdate::Point;
    scene.stop = {};
    scene.stop.max_steps = 2000;
    Simulation sim(scene, 1);
    const StepFailure f = first_failure(sim, 2000);
    const FailureSite& s = f.site();
    EXPECT_EQ(s.phase, "totals");
    EXPECT_EQ(s.field, "total energy");
    EXPECT_EQ(s.body, "bar");
    EXPECT_EQ(s.step, sim.steps()) << "the guard checks a completed step";
    EXPECT_GT(std::abs(sim.totals().energy_error), 0.03);
    EXPECT_TRUE(has(f.what(), "stop.energy_error = 3 %")) << f.what();
    EXPECT_THROW(sim.step(), NumericalError);

    // The same run at the default C_cfl stays within the guard for all 2000 steps.
    scene.solver.cfl = SolverOptions{}.cfl;
    Simulation stable(scene, 1);
    for (int k = 0; k < 2000 && !stable.finished(); ++k) ASSERT_NO_THROW(stable.step()) << "step " << k + 1;
    EXPECT_LT(std::abs(stable.totals().energy_error), 0.03);
}

TEST(EnergyGuard, ZeroTurnsItOff) {
    auto scene = testing::elastic_bar_on_plane(1e-3, 4e-3, 4, 50.0);
    scene.solver.cfl = 1.0;
    scene.solver.energy_update = EnergyUpdate::Point;  // see StopsARunWithTooLongATimeStep
    scene.stop = {};
    scene.stop.max_steps = 40;
    scene.stop.energy_error = 0.0;
    Simulation sim(scene, 1);
    double worst = 0.0;
    for (int k = 0; k < 40 && !sim.finished(); ++k) {
        try {
            sim.step();
        } catch (const StepFailure&) {
            break;  // another kind of failure may end it; the guard is not what stops it
        }
        worst = std::max(worst, std::abs(sim.totals().energy_error));
    }
    EXPECT_GT(worst, 0.03) << "the unguarded run passes the 3 % the guard would have stopped";
}

TEST(EnergyGuard, IsAValidatedSceneOption) {
    auto scene = testing::elastic_bar_on_plane(1e-3, 4e-3, 4, 50.0);
    scene.stop.energy_error = -0.1;
    EXPECT_THROW(validate_scene(scene), InputError);
    scene.stop.energy_error = std::nan("");
    EXPECT_THROW(validate_scene(scene), InputError);
}

TEST(MemoryLimit, NodesBeyondItAreRefusedBeforeTheyAreMade) {
    auto scene = testing::elastic_bar_on_plane(1e-3, 4e-3, 4, 50.0);
    const double nodes = estimated_node_count(scene);
    EXPECT_EQ(nodes, 4.0 * 16.0);  // 4 cells across the radius, 16 along the length
    MemoryLimit limit{1000, "a test limit"};
    try {
        Simulation sim(scene, 1, limit);
        ADD_FAILURE() << "a 1000-byte limit was accepted";
    } catch (const LimitError& e) {
        const std::string m = e.what();
        EXPECT_TRUE(has(m, "64 nodes") && has(m, "1000 B") && has(m, "a test limit")) << m;
    }
    // A spacing of 1 nm on the same bar: 10^6 x 4 10^6 cells, refused at once.
    scene.bodies[0].spacing = 1e-9;
    EXPECT_THROW(Simulation(scene, 1), LimitError);
    EXPECT_GT(estimated_node_count(scene), 1e12);
}

TEST(MemoryLimit, NeighbourListsAreCheckedAsASearchMakesThem) {
    // At the largest influence distance the lists hold about twice the pairs per node that the
    // set-up estimate assumes: a limit just above that estimate passes set-up's check of the
    // nodes and refuses the first search (in set-up) at the wave of rows that takes its entries
    // past the limit, before that wave is placed in the lists (find_neighbours).
    auto scene = testing::armco_cylinder(10, 40e-6);
    scene.solver.influence_distance = 1.5;
    const double nodes = estimated_node_count(scene);
    const auto bytes = static_cast<std::uint64_t>(
        1.02 * nodes * (bytes_per_node_besides_lists(2) + list_entries_per_node(2) * bytes_per_list_entry));
    try {
        Simulation sim(scene, 1, MemoryLimit{bytes, "a test limit"});
        ADD_FAILURE() << "lists of twice the estimated pairs per node fitted";
    } catch (const LimitError& e) {
        EXPECT_TRUE(has(e.what(), "neighbour lists")) << e.what();
    }
    // With room for them, it runs.
    EXPECT_NO_THROW(Simulation(scene, 1, MemoryLimit{bytes * 100, "a test limit"}));
}

TEST(MemoryLimit, RoomForTheListsButNotTheirKeptPairTermsRunsWithoutThemToTheSameNumbers) {
    // Without a skin every step searches, and each search checks the limit with the nodes (ghosts
    // included) and the entries of the lists it makes. The smallest limit that lets the lists of
    // every step fit (bytes_per_list_entry) leaves no room for the terms a step keeps per pair
    // (bytes_per_kept_pair): the run goes without them, its sweeps make them again, and the numbers
    // are the same bit for bit.
    auto scene = testing::armco_cylinder(10, 40e-6);
    scene.solver.neighbour_skin = 0.0;
    constexpr int steps = 40;
    Simulation free(scene, 1);
    const auto lists_bytes = [](const Simulation& sim, double per_entry) {
        return double(sim.nodes().size()) * bytes_per_node_besides_lists(2) +
               double(sim.neighbour_lists().offsets[sim.real_count()]) * per_entry;
    };
    double limit = lists_bytes(free, bytes_per_list_entry);
    for (int k = 0; k < steps; ++k) {
        free.step();
        limit = std::max(limit, lists_bytes(free, bytes_per_list_entry));
    }
    // At least the last search has no room for the kept terms (else the test would show nothing;
    // searches before it may have had room and kept them, to the same numbers).
    ASSERT_LT(limit, lists_bytes(free, bytes_per_list_entry + bytes_per_kept_pair));
    Simulation tight(scene, 1, MemoryLimit{static_cast<std::uint64_t>(std::ceil(limit)), "a test limit"});
    for (int k = 0; k < steps; ++k) tight.step();
    const auto kept_bytes = [](const Simulation& sim) {
        for (const ArrayMemory& a : sim.memory_use()) {
            if (a.array == "neighbour lists: kept pair terms") return a.bytes;
        }
        return std::size_t{0};
    };
    EXPECT_GT(kept_bytes(free), 0u);
    EXPECT_EQ(kept_bytes(tight), 0u);
    ASSERT_EQ(free.nodes().size(), tight.nodes().size());
    for (std::size_t i = 0; i < free.real_count(); ++i) {
        for (int c = 0; c < 2; ++c) {
            ASSERT_EQ(free.nodes().position[c][i], tight.nodes().position[c][i]) << "node " << i;
            ASSERT_EQ(free.nodes().velocity[c][i], tight.nodes().velocity[c][i]) << "node " << i;
        }
        ASSERT_EQ(free.nodes().internal_energy[i], tight.nodes().internal_energy[i]) << "node " << i;
    }
}

std::size_t bytes_of(const Simulation& sim, const std::string& array) {
    for (const ArrayMemory& a : sim.memory_use()) {
        if (a.array == array) return a.bytes;
    }
    ADD_FAILURE() << "no array \"" << array << "\" in the memory table";
    return 0;
}

// A quarter of a 3D copper bar on its anvil (the symmetry planes x = 0 and y = 0 and the anvil),
// with `connectivity`.
Scene quarter_bar(ConnectivityMode connectivity) {
    Scene s = testing::short_copper_bar(GeometryKind::ThreeD, 4);
    s.bodies[0].connectivity = connectivity;
    return testing::with_quarter_planes(s);
}

// What a scene does not need costs no memory (docs/performance.md section 3): without fixed nodes
// there are no lattice lists (an offset per node each: 24 bytes per node with the ghosts' resolved
// mirrors), and the map from node ids to nodes is made only when a program looks a node up.
TEST(MemoryUse, ASceneWithoutFixedNodesCarriesNoLatticeListsAndNoIdMapUntilALookUp) {
    Simulation sim(quarter_bar(ConnectivityMode::Variable), 2);
    for (int k = 0; k < 3; ++k) sim.step();
    const std::size_t real = sim.real_count();
    const std::size_t ghosts = sim.nodes().size() - real;
    ASSERT_GT(ghosts, 0u);
    // The one offset of no rows each (8 bytes), not one per node.
    EXPECT_LE(bytes_of(sim, "nodes: fixed neighbours"), 8u);
    EXPECT_LE(bytes_of(sim, "nodes: fixed mirrors"), 8u);
    EXPECT_LE(bytes_of(sim, "ghosts: resolved lattice mirrors"), 8u);
    EXPECT_EQ(bytes_of(sim, "external loads: node ids"), 0u);
    // A look-up makes the map, and finds each node (after the set-up's reorder) by its id.
    for (const std::uint64_t id : {std::uint64_t{0}, std::uint64_t{real / 2}, std::uint64_t{real - 1}}) {
        EXPECT_EQ(sim.nodes().id[sim.index_of(id)], id);
    }
    EXPECT_EQ(bytes_of(sim, "external loads: node ids"), 4 * real);
    EXPECT_THROW((void)sim.index_of(real), InputError);
}

// index_of only reads as far as a program can tell (docs/api.md: several threads may call it between
// steps), though its first call after a reorder makes the map. Without the lock around that, the
// threads would build the map over one another: a wrong node or a crash here, a data race under a
// thread sanitizer (which CI does not run).
TEST(MemoryUse, ThreadsLookingNodesUpAtOnceAfterAReorderEachFindEveryNode) {
    Scene scene = quarter_bar(ConnectivityMode::Variable);
    scene.solver.reorder_interval = 2;
    Simulation sim(scene, 2);
    for (int k = 0; k < 5; ++k) sim.step();
    const std::size_t real = sim.real_count();
    std::vector<std::vector<std::size_t>> found(4, std::vector<std::size_t>(real));
    std::vector<std::thread> threads;
    for (auto& mine : found) {
        threads.emplace_back([&sim, &mine, real] {
            for (std::size_t id = 0; id < real; ++id) mine[id] = sim.index_of(id);
        });
    }
    for (auto& t : threads) t.join();
    for (std::size_t id = 0; id < real; ++id) {
        for (const auto& mine : found) ASSERT_EQ(sim.nodes().id[mine[id]], id) << "id " << id;
    }
}

// The off-diagonal normalisation (alpha_shear, three arrays in 3D) is carried only by a run with
// the moment matrix, which writes and reads it: with the per-direction normalisation (the default)
// it is not in the memory table at all, and the run steps without it.
TEST(MemoryUse, OnlyTheMomentMatrixCarriesTheOffDiagonalNormalisation) {
    const auto has_array = [](const Simulation& sim, const std::string& array) {
        const MemoryUse use = sim.memory_use();
        return std::any_of(use.begin(), use.end(), [&](const ArrayMemory& a) { return a.array == array; });
    };
    Scene per_direction = quarter_bar(ConnectivityMode::Variable);
    Simulation plain(per_direction, 2);
    for (int k = 0; k < 3; ++k) plain.step();
    EXPECT_FALSE(has_array(plain, "nodes: alpha_shear"));
    EXPECT_FALSE(plain.nodes().carries_shear_normalisation());
    Scene full = per_direction;
    full.solver.normalisation = Normalisation::MomentMatrix;
    Simulation moment(full, 2);
    for (int k = 0; k < 3; ++k) moment.step();
    EXPECT_GE(bytes_of(moment, "nodes: alpha_shear"), 3 * 8 * moment.nodes().size());
    // It is written: some node's normalisation has off-diagonal entries once the bar has moved.
    double largest = 0.0;
    for (std::size_t i = 0; i < moment.real_count(); ++i) largest = std::max(largest, std::abs(moment.nodes().alpha_shear[2][i]));
    EXPECT_GT(largest, 0.0);
}

TEST(MemoryUse, ASceneWithFixedNodesKeepsItsLatticeLists) {
    Simulation sim(quarter_bar(ConnectivityMode::Automatic), 2);
    for (int k = 0; k < 3; ++k) sim.step();
    EXPECT_GE(bytes_of(sim, "nodes: fixed neighbours"), 8 * sim.real_count());  // an offset per node and the entries
    EXPECT_GT(bytes_of(sim, "nodes: fixed mirrors"), 0u);
}

}  // namespace
}  // namespace gpa
