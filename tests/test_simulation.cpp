// Whole runs of the engine: energy and momentum balances, an elastic bar against a rigid plane,
// smoothing, thread independence, and the phases a scene's graph holds.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include <gtest/gtest.h>

#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/smoothing.hpp"
#include "support/lattices.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

double total_mass(const Simulation& sim) {
    double m = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) m += sim.nodes().mass[i];
    return m;
}

double axial_momentum(const Simulation& sim) {
    double p = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) p += sim.nodes().mass[i] * sim.nodes().velocity[1][i];
    return p;
}

// Elastic bar (nu = 0, so bar and dilatational speeds agree), 10 diameters long, no viscosity,
// lift-off allowed, 10 nodes across the radius (2000 nodes).
TEST(ElasticBar, ContactTimeAndReboundSpeedWithinTwoPercent) {
    const double radius = 1e-3, length = 20e-3, speed = 10.0;
    Simulation sim(testing::elastic_bar_on_plane(radius, length, 10, speed), 2);
    const double c = std::sqrt(200e9 / 7800.0), mass = total_mass(sim);
    double last_contact = 0.0;
    while (!sim.finished()) {
        sim.step();
        if (sim.totals().planes.at(0).reaction != 0.0) last_contact = sim.time();
    }
    ASSERT_GT(sim.time(), 1.2 * last_contact) << "the run must outlast the contact";
    const double rebound = axial_momentum(sim) / mass;
    std::printf("[ measured ] contact %.4g us vs 2L/c %.4g us (%+.2f %%), rebound %.4g m/s (%+.2f %%), energy error %.2g\n",
                last_contact * 1e6, 2 * length / c * 1e6, 100 * (last_contact * c / (2 * length) - 1), rebound,
                100 * (rebound / speed - 1), sim.totals().energy_error);
    // The acceptance: 2 % on both (measured at this resolution: about +0.6 % and -1.4 %).
    EXPECT_NEAR(last_contact, 2.0 * length / c, 0.02 * 2.0 * length / c);
    EXPECT_NEAR(rebound, speed, 0.02 * speed);
}

// The paper's Armco-iron cylinder (nodal viscosity) at 8 nodes across the radius, to 40 us.
TEST(ArmcoCylinder, EnergyBalanceClosesWithinOnePercent) {
    Simulation sim(testing::armco_cylinder(8, 40e-6), 2);
    const double e0 = sim.totals().initial_energy;
    double worst = 0.0;
    while (!sim.finished()) {
        sim.step();
        worst = std::max(worst, std::abs(sim.totals().energy_error));
    }
    const auto& t = sim.totals();
    std::printf("[ measured ] worst |KE + IE + boundary work - E0| / E0 = %.3g over %zu steps; final KE %.3g J, IE %.4g J "
                "(plastic %.4g J, viscous %.4g J), boundary %.3g J, E0 %.4g J; L %.3f mm, D %.3f mm\n",
                worst, t.step, t.kinetic_energy, t.internal_energy, t.plastic_work, t.viscous_work, t.boundary_work, e0,
                t.length * 1e3, t.footprint_diameter * 1e3);
    // Plastic and viscous work are booked in the internal energy (which also holds the work of the
    // thermal pressure, so it need not exceed their sum); the boundary work holds what the sliding
    // condition removed. The balance closes within the 1 % (the scheme's error is first
    // order in dt: 1.07 % at C_cfl 0.3, 0.56 % at 0.15 were measured for this run).
    EXPECT_GT(t.plastic_work, 0.5 * e0) << "most of the impact energy should become plastic work";
    EXPECT_GT(t.viscous_work, 0.0);
    EXPECT_LT(worst, 0.01);
    EXPECT_LT(t.kinetic_energy, 0.01 * e0) << "the bar should have come to rest by 40 us";
}

// With bond viscosity (Eq. 37-38) the compatible energy update books the bond-viscous forces'
// work at the same mean velocities as the stress work (EnergyLedger::compatible_powers), so the
// balance closes to round-off as with the nodal form; the force pass's own power, at the half-step
// velocities, left +0.27 % on the paper's cylinder at 40 us (scenes/armco-cylinder-bond.toml). An
// axisymmetric cylinder, a 3D bar, and a shot striking a bar across a sliding contact (whose pairs
// act along the contact normal), each checked at every step, on 1 and 2 threads alike.
TEST(BondViscosity, TheCompatibleUpdateBooksItsWorkAndTheBalanceClosesToRoundOff) {
    struct Case {
        const char* name;
        Scene scene;
        std::size_t steps;
    };
    Scene cylinder = testing::armco_cylinder(5, 1.0);
    Scene bar = testing::short_copper_bar(GeometryKind::ThreeD, 3);
    Scene struck = testing::struck_by_a_fast_body(testing::short_copper_bar(GeometryKind::PlaneStrain, 4), ConnectivityMode::Variable);
    ASSERT_TRUE(struck.solver.sliding_contact);
    std::vector<Case> cases{{"axisymmetric cylinder", cylinder, 400}, {"3D bar", bar, 120}, {"plane-strain bar struck across a sliding contact", struck, 300}};
    for (Case& c : cases) {
        c.scene.solver.viscosity = ViscosityKind::Bond;
        c.scene.stop.max_steps = c.steps;
        std::array<std::string, 2> bytes;
        for (const int threads : {1, 2}) {
            Simulation sim(c.scene, threads);
            double worst = 0.0;
            while (!sim.finished()) {
                sim.step();
                worst = std::max(worst, std::abs(sim.totals().energy_error));
            }
            const Totals& t = sim.totals();
            if (threads == 2) {
                std::printf("[ measured ] %s: worst |energy error| %.2g over %zu steps; viscous work %.4g J of E0 %.4g J\n",
                            c.name, worst, t.step, t.viscous_work, t.initial_energy);
            }
            // The viscosity must have acted, or the balance would close without it.
            EXPECT_GT(t.viscous_work, 1e-4 * t.initial_energy) << c.name;
            // Round-off of sums over the nodes (the nodal form's runs close to 1e-15-1e-14).
            EXPECT_LT(worst, 1e-12) << c.name;
            bytes[threads - 1] = testing::node_bytes(sim);
        }
        EXPECT_TRUE(bytes[0] == bytes[1]) << c.name << ": 1 and 2 threads";
    }
}

TEST(Momentum, AxialMomentumChangesOnlyByThePlaneImpulse) {
    Simulation sim(testing::armco_cylinder(6, 40e-6), 2);
    double p0 = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) p0 += sim.nodes().mass[i] * -305.0;
    for (int k = 0; k < 400; ++k) sim.step();
    const double impulse = sim.totals().planes.at(0).impulse;
    ASSERT_GT(impulse, 0.05 * std::abs(p0)) << "the plane must have pushed";
    // Velocities after step() are the half step ahead, and so is the impulse (spec section 11).
    EXPECT_NEAR(axial_momentum(sim) - p0, impulse, 1e-11 * std::abs(p0));
}

TEST(Momentum, WithoutPlanesItIsConservedToRoundOff) {
    auto scene = testing::elastic_bar_on_plane(1e-3, 10e-3, 5, 10.0);
    scene.planes.clear();
    scene.bodies[0].velocity = {0.0, 0.0, 0.0};
    scene.bodies[0].initial_stress = {-1e8, 2e8, 5e7, 0.0, 0.0, 0.0};  // it must move
    scene.solver.viscosity = ViscosityKind::Nodal;
    scene.stop.max_steps = 300;
    Simulation sim(scene, 2);
    for (int k = 0; k < 300; ++k) sim.step();
    double speed = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) speed = std::max(speed, std::abs(sim.nodes().velocity[1][i]));
    ASSERT_GT(speed, 1.0) << "the prestressed bar must be moving";
    EXPECT_NEAR(axial_momentum(sim), 0.0, 1e-13 * total_mass(sim) * speed);
}


TEST(Threads, AFullShortRunIsBitIdenticalOnOneAndTwoThreads) {
    for (bool smoothing : {false, true}) {
        auto scene = testing::armco_cylinder(6, 40e-6);
        if (smoothing) scene.solver.smoothing = SmoothingMode::Everywhere;
        scene.solver.reorder_interval = 50;
        Simulation one(scene, 1), two(scene, 2);
        for (int k = 0; k < 250; ++k) {
            one.step();
            two.step();
        }
        ASSERT_EQ(one.real_count(), two.real_count());
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two))
            << (smoothing ? "with smoothing" : "without smoothing");
        EXPECT_EQ(std::memcmp(&one.totals().energy_error, &two.totals().energy_error, sizeof(double)), 0);
    }
}

// Neighbour lists with a skin (SolverOptions::neighbour_skin): every step, the candidates cut to
// r < 2 h must be exactly the pairs a full search finds (check_neighbour_lists throws otherwise),
// with fewer searches than steps; and a run must not depend on the skin beyond round-off.
Scene three_d_cylinder(int radial_cells) {
    auto scene = testing::armco_cylinder(radial_cells, 40e-6);
    scene.geometry = GeometryKind::ThreeD;
    // A quarter of a square bar: a box on the symmetry planes x = 0 and y = 0, which give corner
    // (edge) ghosts along the z axis, and the anvil z = 0 below.
    auto& bar = scene.bodies[0];
    bar.shape = ShapeKind::Box;
    bar.size = {bar.radius, bar.radius, bar.length};
    bar.origin = {0.0, 0.0, 0.0};
    bar.velocity = {0.0, 0.0, -305.0};
    scene.planes[0].axis = 2;
    return testing::with_quarter_planes(scene);
}

// The 3D node diameter (SolverOptions::node_diameter, kernels.hpp): with "stretch" (the default)
// each node carries B = F F^T and its d is d0 (V/V0)^(1/3) times B's largest isochoric stretch;
// the impact face, spread radially, has the largest stretches. With "volume" B is not advanced at
// all (the rule that does not need it costs nothing) and d is d0 (V/V0)^(1/3). Both runs are
// bit-identical on 1 and 2 threads.
TEST(NodeDiameter3D, TheStretchRuleFollowsTheImpactFaceAndTheVolumeRuleLeavesBAlone) {
    for (NodeDiameter rule : {NodeDiameter::Stretch, NodeDiameter::Volume}) {
        auto scene = three_d_cylinder(5);
        scene.solver.node_diameter = rule;
        scene.solver.reorder_interval = 40;  // B is reordered with the other fields (three times)
        Simulation one(scene, 1), two(scene, 2);
        for (int k = 0; k < 150; ++k) {
            one.step();
            two.step();
        }
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
        const NodeStore& n = one.nodes();
        const double spacing = scene.bodies[0].spacing;
        double largest = 1.0, largest_height = 0.0;
        for (std::size_t i = 0; i < one.real_count(); ++i) {
            std::array<double, 6> b;
            for (int c = 0; c < 6; ++c) b[c] = n.left_cauchy_green[c][i];
            const double lambda = largest_isochoric_stretch(b);
            const double volume_rule = n.initial_diameter[i] * std::cbrt(1.0 + n.volumetric_strain[i]);
            // The diameters are those of the last geometry phase, before this step's stress update
            // advanced B and eps_v: within the step's increment (below 1 %) of the rule applied now.
            if (rule == NodeDiameter::Volume) {
                ASSERT_EQ(b, (std::array<double, 6>{1.0, 1.0, 1.0, 0.0, 0.0, 0.0})) << i;
                ASSERT_NEAR(n.diameter[i], volume_rule, 0.01 * n.diameter[i]) << i;
                continue;
            }
            ASSERT_NEAR(n.diameter[i], volume_rule * lambda, 0.01 * n.diameter[i]) << i;
            if (lambda > largest) {
                largest = lambda;
                largest_height = n.position[2][i];
            }
        }
        if (rule == NodeDiameter::Stretch) {
            // 150 steps (about 9 us) after impact at 305 m/s the face has spread: its nodes are
            // stretched well beyond 1, and the most stretched lies in the bottom two rows.
            EXPECT_GT(largest, 1.3);
            EXPECT_LT(largest_height, 2.0 * spacing);
        }
    }
}

// solver.hourglass_nodes: "all" damps every node whatever switch_plastic_strain says (the lattice
// regime's bound becomes infinite), "lattice" only the nodes below it, and "automatic" (the
// default) is "all" in 3D and "lattice" in 2D. The 3D bar of 5 cells, 150 steps after impact (its
// face has yielded beyond a plastic strain of 0.1): "all" with a bound of 1e-9 is bit for bit
// "lattice" with a bound no node reaches, and the default; "lattice" with the bound of 1e-9 spares
// the yielded nodes, and its hourglass damping does less work.
TEST(HourglassNodes, AllDampsEveryNodeWhateverTheSwitchingStrain) {
    struct Result {
        std::string bytes;
        double hourglass_work = 0.0;
        double largest_plastic_strain = 0.0;
    };
    const auto run = [](HourglassNodes which, double bound) {
        auto scene = three_d_cylinder(5);
        scene.solver.hourglass_nodes = which;
        scene.solver.switch_plastic_strain = bound;
        Simulation sim(scene, 2);
        for (int k = 0; k < 150; ++k) sim.step();
        Result r{testing::node_bytes(sim), sim.totals().hourglass_work};
        for (std::size_t i = 0; i < sim.real_count(); ++i) {
            r.largest_plastic_strain = std::max(r.largest_plastic_strain, sim.nodes().plastic_strain[i]);
        }
        return r;
    };
    const Result all = run(HourglassNodes::All, 1e-9);
    const Result everywhere = run(HourglassNodes::Lattice, 1e300);
    const Result lattice = run(HourglassNodes::Lattice, 1e-9);
    const Result automatic = run(HourglassNodes::Automatic, 1e-9);
    EXPECT_TRUE(all.bytes == everywhere.bytes);
    EXPECT_TRUE(automatic.bytes == all.bytes);
    EXPECT_EQ(SolverOptions{}.hourglass_nodes, HourglassNodes::Automatic);
    EXPECT_TRUE(hourglass_damps_every_node(SolverOptions{}, GeometryKind::ThreeD));
    EXPECT_FALSE(hourglass_damps_every_node(SolverOptions{}, GeometryKind::Axisymmetric));
    EXPECT_FALSE(hourglass_damps_every_node(SolverOptions{}, GeometryKind::PlaneStrain));
    EXPECT_GT(lattice.largest_plastic_strain, 0.1);  // the face has left any lattice regime
    EXPECT_FALSE(lattice.bytes == all.bytes);
    EXPECT_GT(all.hourglass_work, 0.0);
    EXPECT_LT(lattice.hourglass_work, all.hourglass_work);
}

// A scene of a test that checks its lists against a full search every step, for so many steps.
struct ListsCase {
    const char* name;
    Scene scene;
    int steps;
};

TEST(NeighbourSkin, CutCandidatesEqualAFullSearchEveryStep) {
    std::vector<ListsCase> cases;
    cases.push_back({"axisymmetric Taylor bar, variable", testing::armco_cylinder(6, 40e-6), 300});
    {
        auto scene = testing::armco_cylinder(6, 40e-6);
        scene.solver.connectivity = ConnectivityMode::Automatic;  // nodes switch between searches
        scene.solver.switch_plastic_strain = 0.05;
        cases.push_back({"axisymmetric Taylor bar, automatic switching", scene, 300});
    }
    {
        auto scene = testing::elastic_bar_on_plane(1e-3, 12e-3, 4, 100.0);  // lift-off: contacts come and go
        scene.stop = {};
        scene.stop.max_steps = 100000;
        cases.push_back({"elastic bar bouncing off a lift-off plane", scene, 600});
    }
    {
        // Starts 0.5 mm above the plane: no node has a ghost until the bar comes within reach.
        auto scene = testing::elastic_bar_on_plane(1e-3, 12e-3, 4, 300.0);
        scene.bodies[0].origin[1] += 0.5e-3;
        scene.stop = {};
        scene.stop.max_steps = 100000;
        // 4 nodes across at 300 m/s: the energy error of this coarse impact passes 3 % near step
        // 157; the case is here for its contacts, not its energy, so the energy guard is off.
        scene.stop.energy_error = 0.0;
        cases.push_back({"elastic bar arriving at a lift-off plane", scene, 600});
    }
    {
        auto scene = testing::armco_cylinder(6, 40e-6);
        scene.solver.reorder_interval = 7;
        scene.solver.neighbour_skin = 0.4;
        cases.push_back({"large skin, frequent reordering", scene, 100});
    }
    {
        auto scene = three_d_cylinder(3);
        scene.solver.connectivity = ConnectivityMode::Automatic;
        scene.solver.switch_plastic_strain = 0.05;
        cases.push_back({"3D quarter bar, automatic switching", scene, 150});
    }
    for (auto& c : cases) {
        SCOPED_TRACE(c.name);
        c.scene.solver.check_neighbour_lists = true;
        Simulation sim(c.scene, 2);
        for (int k = 0; k < c.steps && !sim.finished(); ++k) ASSERT_NO_THROW(sim.step()) << "step " << k;
        const std::size_t searches = sim.totals().neighbour_searches;
        std::printf("[ measured ] %s: %zu full searches in %zu steps, %zu pairs\n", c.name, searches, sim.steps(),
                    sim.totals().pairs);
        EXPECT_LT(searches, sim.steps()) << "the skin should spare some searches";
        EXPECT_GT(searches, 1u) << "the bar deforms: the candidates must go stale at some point";
    }
}

// Where no body is automatic, a fixed centre's row of lattice entries alone is kept whole by the cut
// without a look at its entries (filter_candidates, LatticeRowsKept); with automatic bodies only the
// quiet rows are, whose lattice neighbours a switch within reach sends to a new search first. The
// lists must be those of a full search every step (check_neighbour_lists throws otherwise), with the
// anvil's mirrored lattice rows in 2D and the symmetry planes' and the anvil's in a 3D quarter, and
// the same on 1 and 2 threads.
TEST(NeighbourSkin, LatticeRowsKeptWholeAreThoseOfAFullSearchEveryStep) {
    std::vector<ListsCase> cases;
    {
        auto scene = testing::armco_cylinder(6, 40e-6);
        scene.solver.connectivity = ConnectivityMode::Fixed;
        cases.push_back({"axisymmetric Taylor bar, fixed", scene, 200});  // its lattice cells collapse at step 222
    }
    {
        auto scene = three_d_cylinder(4);
        scene.solver.connectivity = ConnectivityMode::Fixed;
        cases.push_back({"3D quarter bar, fixed", scene, 120});
    }
    {
        auto scene = three_d_cylinder(4);
        scene.solver.connectivity = ConnectivityMode::Automatic;
        scene.solver.switch_plastic_strain = 0.02;  // nodes next to quiet centres switch early
        cases.push_back({"3D quarter bar, automatic switching", scene, 120});
    }
    for (auto& c : cases) {
        SCOPED_TRACE(c.name);
        c.scene.solver.check_neighbour_lists = true;
        Simulation one(c.scene, 1), two(c.scene, 2);
        for (int k = 0; k < c.steps && !one.finished(); ++k) {
            ASSERT_NO_THROW(one.step()) << "step " << k;
            ASSERT_NO_THROW(two.step()) << "step " << k;
        }
        const Totals& t = one.totals();
        std::printf("[ measured ] %s: %zu steps, %zu full searches, %zu variable nodes of %zu\n", c.name, one.steps(),
                    t.neighbour_searches, t.variable_nodes, t.real_nodes);
        EXPECT_EQ(one.steps(), static_cast<std::size_t>(c.steps)) << "the run must take every step";
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
        if (c.scene.solver.connectivity == ConnectivityMode::Automatic) {
            EXPECT_GT(t.variable_nodes, 0u) << "nodes must switch";
            EXPECT_LT(t.variable_nodes, t.real_nodes) << "and some stay fixed";
        }
    }
}

// A small fast body striking a resting one: only the nodes that move (the projectile and the
// face it strikes) use up the skin, and the rows of those nodes alone are searched again
// (NeighbourLists::search_rows), each pair found put into both rows. Every step's lists must
// still be exactly the pairs of a full search (check_neighbour_lists throws otherwise), in an
// axisymmetric scene (ghosts across the axis and a rigid plane) and in a 3D quarter (ghosts
// across two symmetry planes and their edge), with fixed, automatic and variable bodies; the
// runs are bit-identical on 1 and 2 threads.
TEST(NeighbourSkin, OnlyTheRowsOfNodesThatMovedAreSearchedAgainAndTheListsStayThoseOfAFullSearch) {
    struct Case {
        const char* name;
        Scene scene;
        bool mostly_rows;
    };
    std::vector<Case> cases;
    for (ConnectivityMode target : {ConnectivityMode::Automatic, ConnectivityMode::Variable}) {
        cases.push_back({target == ConnectivityMode::Automatic ? "axisymmetric, automatic target" : "axisymmetric, variable target",
                         testing::struck_by_a_fast_body(testing::armco_cylinder(12, 40e-6), target), true});
    }
    {
        Scene scene = testing::struck_by_a_fast_body(three_d_cylinder(5), ConnectivityMode::Automatic);
        scene.planes.erase(scene.planes.begin());  // the anvil: the bar rests in space, on its symmetry planes only
        cases.push_back({"3D quarter, automatic target", scene, false});
    }
    for (auto& c : cases) {
        SCOPED_TRACE(c.name);
        c.scene.solver.check_neighbour_lists = true;
        Simulation one(c.scene, 1), two(c.scene, 2);
        for (int k = 0; k < 120 && !one.finished(); ++k) {
            ASSERT_NO_THROW(one.step()) << "step " << k;
            ASSERT_NO_THROW(two.step()) << "step " << k;
        }
        const Totals& t = one.totals();
        std::printf("[ measured ] %s: %zu steps, %zu full searches, %zu searches of %zu rows in all (%zu real nodes)\n", c.name,
                    one.steps(), t.neighbour_searches, t.row_searches, t.rows_searched, t.real_nodes);
        EXPECT_GT(t.row_searches, 0u) << "the fast body must use up the skin of its own rows";
        // In 2D the struck face stays small beside the bar; in the 3D quarter the shot sits on
        // both symmetry planes and its face is a fifth of the bar's top, so full searches (more
        // than an eighth of the rows due, or the ghosts short) are as many there.
        if (c.mostly_rows) {
            EXPECT_LT(t.neighbour_searches, t.row_searches) << "most searches must be of some rows alone";
        }
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
    }
}

// A node that switches next to a quiet centre (a fixed centre whose candidates are its lattice row
// alone) gives that centre a pair its row lacks. The switched node's row is searched alone and the
// pair put into both rows (NeighbourLists::switched_near_quiet_rows, search_rows), not every row:
// a bar struck by a fast body, whose face switches to variable connectivity while the rest of the
// bar stays quiet, needs about the full searches of the same bar all-variable, which has no quiet
// rows (until 2026-12-07 a switch called a full search: 7 against all-variable's 1). Every step's
// lists are those of a full search (check_neighbour_lists), and the run is bit-identical on 1 and
// 2 threads.
TEST(NeighbourSkin, ASwitchNextToAQuietCentreSearchesTheSwitchedRowsAlone) {
    std::map<ConnectivityMode, Totals> totals;
    for (ConnectivityMode target : {ConnectivityMode::Variable, ConnectivityMode::Automatic}) {
        const char* name = target == ConnectivityMode::Variable ? "variable" : "automatic";
        SCOPED_TRACE(name);
        Scene scene = testing::struck_by_a_fast_body(testing::armco_cylinder(12, 40e-6), target);
        scene.solver.check_neighbour_lists = true;
        Simulation one(scene, 1), two(scene, 2);
        for (int k = 0; k < 120 && !one.finished(); ++k) {
            ASSERT_NO_THROW(one.step()) << "step " << k;
            ASSERT_NO_THROW(two.step()) << "step " << k;
        }
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
        totals[target] = one.totals();
        std::printf("[ measured ] %s target: %zu full searches, %zu searches of %zu rows, %zu variable nodes of %zu\n", name,
                    one.totals().neighbour_searches, one.totals().row_searches, one.totals().rows_searched,
                    one.totals().variable_nodes, one.totals().real_nodes);
    }
    const Totals& automatic = totals[ConnectivityMode::Automatic];
    const Totals& variable = totals[ConnectivityMode::Variable];
    // The shot's few nodes (it is two spacings across) and the bar's struck face.
    ASSERT_GT(automatic.variable_nodes, 40u) << "the struck face must switch";
    ASSERT_LT(automatic.variable_nodes, automatic.real_nodes / 4) << "the rest of the bar must stay fixed";
    // One more than all-variable: rows searched alone keep their old entries, and when the
    // candidates have grown by a quarter since the last full search (the quiet rows grow from
    // their lattice rows as their neighbours switch) a full search starts them afresh (choose_rows).
    EXPECT_LE(automatic.neighbour_searches, variable.neighbour_searches + 1) << "a switch must not make every row stale";
    EXPECT_GT(automatic.row_searches, variable.row_searches) << "the switched rows must have been searched alone";
}

TEST(NeighbourSkin, ARunDoesNotDependOnTheSkinBeyondRoundOff) {
    auto with = testing::armco_cylinder(6, 40e-6);
    auto without = with;
    without.solver.neighbour_skin = 0.0;
    Simulation a(with, 2), b(without, 2);
    for (int k = 0; k < 400; ++k) {
        a.step();
        b.step();
    }
    ASSERT_EQ(a.real_count(), b.real_count());
    EXPECT_LT(a.totals().neighbour_searches, 200u);
    EXPECT_EQ(b.totals().neighbour_searches, 401u);  // set-up and every step
    // The two runs add the same pairs in different orders: they may differ only by round-off,
    // amplified over 400 steps of plastic flow; 1e-9 of the bar length bounds that with a wide
    // margin and is far below any difference a missing or extra pair would make (~1e-3).
    double worst = 0.0;
    for (std::size_t i = 0; i < a.real_count(); ++i) {
        for (int c = 0; c < 2; ++c) worst = std::max(worst, std::abs(a.nodes().position[c][i] - b.nodes().position[c][i]));
    }
    EXPECT_LT(worst, 1e-9 * 15.2e-3);
    EXPECT_NEAR(a.totals().plastic_work, b.totals().plastic_work, 1e-9 * b.totals().plastic_work);
}

TEST(PhaseGraph, HoldsOnlyThePhasesTheSceneNeeds) {
    auto scene = testing::armco_cylinder(4, 1e-6);
    const auto plain = Simulation(scene, 1).phases();
    EXPECT_EQ(std::count(plain.begin(), plain.end(), "smoothing"), 0);
    EXPECT_EQ(std::count(plain.begin(), plain.end(), "switching"), 0);
    scene.solver.smoothing = SmoothingMode::Tension;
    scene.solver.connectivity = ConnectivityMode::Automatic;
    const auto full = Simulation(scene, 1).phases();
    EXPECT_EQ(std::count(full.begin(), full.end(), "smoothing"), 1);
    EXPECT_EQ(std::count(full.begin(), full.end(), "switching"), 1);
}

// Smoothing (Eq. 66-73) on an axisymmetric block against the axis and a rigid plane, with its
// ghosts in the lists: one application.
struct SmoothingSetup {
    NodeStore nodes{GeometryKind::Axisymmetric};
    std::size_t real = 0;
    CompressedRows lists;
    GhostSet ghosts;

    SmoothingSetup() {
        ghosts = GhostSet({{"axis", 0, 0.0, +1, false, false}, {"plane", 1, 0.0, +1, false, true}});
        LatticeBlock b;
        b.spacing = {1e-3, 1e-3, 1e-3};
        b.last = {10, 12, 1};
        b.density = 7800.0;
        b.mirror_planes = ghosts.mirror_planes();
        fill_lattice(nodes, b);
        real = nodes.size();
        testing::jitter(nodes, 0.1, 1e-3, 3);
        ghosts.update_contacts(nodes, real, true);
        ghosts.build(nodes, real, largest_interaction_radius(nodes, 1.0, real));
        NeighbourScratch scratch;
        find_neighbours(nodes, 1.0, real, lists, scratch, &ghosts.resolved_fixed_mirrors(nodes, real));
        ghosts.append_ghost_rows(lists, real);
    }

    double smooth(SmoothingMode mode) {
        SmoothingScratch scratch;
        const PositionView x{2, {nodes.position[0].data(), nodes.position[1].data(), nullptr}};
        const auto plan = make_slab_plan(lists, x);
        return smooth_velocities<Axisymmetric>(lists, plan, WeightKind::Gpa, pair_fields<2>(nodes, 1.0), real,
                                               {0.1, mode == SmoothingMode::Tension},
                                               {nodes.velocity[0].data(), nodes.velocity[1].data()}, nodes.mass.data(),
                                               nodes.pressure.data(), nodes.internal_energy.data(), scratch);
    }
};

TEST(Smoothing, LeavesAUniformFieldUnchanged) {
    SmoothingSetup s;
    for (std::size_t i = 0; i < s.nodes.size(); ++i) {
        s.nodes.velocity[0][i] = 3.0;
        s.nodes.velocity[1][i] = -250.0;
    }
    s.smooth(SmoothingMode::Everywhere);
    for (std::size_t i = 0; i < s.real; ++i) {
        EXPECT_NEAR(s.nodes.velocity[0][i], 3.0, 1e-12);
        EXPECT_NEAR(s.nodes.velocity[1][i], -250.0, 1e-12);
        EXPECT_NEAR(s.nodes.internal_energy[i], 0.0, 1e-9);
    }
}

TEST(Smoothing, ConservesMomentumAndTotalEnergyNextToPlaneAndAxis) {
    for (auto mode : {SmoothingMode::Everywhere, SmoothingMode::Tension}) {
        SmoothingSetup s;
        std::mt19937_64 rng(4);
        std::uniform_real_distribution<double> u(-100.0, 100.0);
        for (std::size_t i = 0; i < s.real; ++i) {
            s.nodes.velocity[0][i] = u(rng);
            s.nodes.velocity[1][i] = u(rng);
            s.nodes.pressure[i] = u(rng);  // about half the centres in tension
        }
        std::array<double, 2> p0{0, 0};
        double e0 = 0.0, scale = 0.0;
        for (std::size_t i = 0; i < s.real; ++i) {
            const double m = s.nodes.mass[i];
            for (int c = 0; c < 2; ++c) p0[c] += m * s.nodes.velocity[c][i];
            e0 += 0.5 * m * (std::pow(s.nodes.velocity[0][i], 2) + std::pow(s.nodes.velocity[1][i], 2)) + m * s.nodes.internal_energy[i];
            scale += m * 100.0;
        }
        const double moved = s.smooth(mode);
        ASSERT_GT(moved, 1e-3 * e0) << "smoothing did nothing measurable";
        std::array<double, 2> p1{0, 0};
        double e1 = 0.0;
        for (std::size_t i = 0; i < s.real; ++i) {
            const double m = s.nodes.mass[i];
            for (int c = 0; c < 2; ++c) p1[c] += m * s.nodes.velocity[c][i];
            e1 += 0.5 * m * (std::pow(s.nodes.velocity[0][i], 2) + std::pow(s.nodes.velocity[1][i], 2)) + m * s.nodes.internal_energy[i];
        }
        for (int c = 0; c < 2; ++c) EXPECT_NEAR(p1[c], p0[c], 1e-13 * scale) << "component " << c;
        EXPECT_NEAR(e1, e0, 1e-13 * e0);
    }
}

}  // namespace
}  // namespace gpa
