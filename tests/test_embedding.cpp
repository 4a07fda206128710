// What a program that embeds gpa does (docs/api.md): it addresses nodes by id through reordering,
// applies external forces and sets velocities between steps with their work booked, sets a
// prescribed region's velocity, and gets each bad call refused with its reason; the loads it left
// waiting are in the checkpoint. The run loop of `gpa run` as a library class (io/run_loop.hpp):
// the same files as the program, a stop request and a resume, a hook that throws.

#include <cmath>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/run_loop.hpp"
#include "gpa/io/units.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

namespace fs = std::filesystem;

// A plane-strain elastic strip at rest, 2 mm wide and 6 mm long, with nothing holding it.
Scene free_strip() {
    Scene s = testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 6e-3, 4, 0.0, 0.0, 0.3);
    s.prescribed_velocities.clear();
    s.stop = {};
    s.stop.max_steps = 1000;
    return s;
}

// The message of the InputError `call` throws ("" when it throws none).
template <class F>
std::string refusal_of(F&& call) {
    try {
        call();
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(Embedding, AnExternalForceChangesTheMomentumByItsImpulseAndTheEnergyBalanceCloses) {
    Simulation sim(free_strip(), 1);
    const std::uint64_t corner = 0, middle = sim.real_count() / 2;
    std::array<double, 2> impulse{0, 0};
    for (int n = 0; n < 60; ++n) {
        // A load that changes from step to step, on two nodes (one of them twice: loads add up).
        const double fx = 40.0 * std::sin(0.1 * n), fz = 25.0 + 10.0 * n;
        sim.apply_force(corner, {fx, 0.5 * fz, 0.0});
        sim.apply_force(middle, {-0.5 * fx, 0.25 * fz, 0.0});
        sim.apply_force(middle, {0.0, 0.25 * fz, 0.0});
        sim.step();
        // The step's velocity update: dt_avg = (dt^{n+1/2} + dt^{n+3/2}) / 2.
        const double dt_avg = 0.5 * (sim.totals().time_step + sim.next_time_step());
        impulse[0] += dt_avg * 0.5 * fx;
        impulse[1] += dt_avg * fz;
    }
    const Totals& t = sim.totals();
    // The internal forces are pairwise and cancel to round-off (spec section 4): the momentum is the
    // external impulse; round-off of the sums over the nodes, 1e-12 of it.
    EXPECT_NEAR(t.momentum[0], impulse[0], 1e-12 * std::abs(impulse[1]));
    EXPECT_NEAR(t.momentum[1], impulse[1], 1e-12 * std::abs(impulse[1]));
    // The work is booked in the leapfrog's own form, so the balance (compatible update) closes to
    // round-off: the strip started at rest and everything it holds came from the loads.
    EXPECT_GT(t.external_work, 0.0);
    EXPECT_DOUBLE_EQ(t.energy_given, t.external_work);
    EXPECT_LT(std::abs(t.energy_error), 1e-10);
    EXPECT_NEAR(t.boundary_work, -t.external_work, 1e-12 * t.external_work);
}

TEST(Embedding, ASetVelocityIsBookedAsExternalWork) {
    Simulation sim(free_strip(), 1);
    for (int n = 0; n < 5; ++n) sim.step();
    const std::size_t i = sim.index_of(7);
    sim.set_velocity(7, {3.0, -2.0, 0.0});
    EXPECT_EQ(sim.nodes().velocity[0][i], 3.0);
    EXPECT_EQ(sim.nodes().velocity[1][i], -2.0);
    EXPECT_DOUBLE_EQ(sim.totals().external_work, 0.0);  // reported with the next step's totals
    for (int n = 0; n < 40; ++n) sim.step();
    const Totals& t = sim.totals();
    EXPECT_DOUBLE_EQ(t.external_work, 0.5 * sim.nodes().mass[i] * 13.0);
    EXPECT_LT(std::abs(t.energy_error), 1e-10);
}

// The kinetic energy of the half-step velocities (those of the real nodes, v^{n+3/2}).
double half_step_kinetic(const Simulation& sim) {
    double k = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        for (int c = 0; c < sim.nodes().dim(); ++c) k += 0.5 * sim.nodes().mass[i] * sim.nodes().velocity[c][i] * sim.nodes().velocity[c][i];
    }
    return k;
}

// With the point energy update the balance takes the kinetic energy at t^{n+1} (the mean of the
// half steps), so a step's external work is half done by then; once the loads stop all of it is,
// as with the compatible update (which takes the half step ahead). And the kinetic energy reported
// after a set velocity is the mean of the changed half step and the next. (The point update's
// own energy error under such a kick, some 5-9 % of the energy given here, is not the booking's:
// its kinetic energy and external work are the compatible run's, its internal energy is not.)
TEST(Embedding, ThePointUpdateBooksExternalWorkAsTheCompatibleOneOnceTheLoadsStop) {
    Scene scene = free_strip();
    scene.stop.energy_error = 0.0;  // the point update's own error is not checked here
    std::array<std::vector<double>, 2> work, kinetic;
    for (int mode = 0; mode < 2; ++mode) {
        Scene s = scene;
        if (mode == 1) s.solver.energy_update = EnergyUpdate::Point;
        Simulation sim(s, 1);
        for (int n = 0; n < 12; ++n) {
            if (n < 3) sim.apply_force(5, {0.0, 500.0, 0.0});
            if (n == 6) sim.set_velocity(9, {0.0, 2.0, 0.0});
            const double before = half_step_kinetic(sim);
            sim.step();
            // The kinetic energy reported at t^{n+1}: the mean of the half steps around it.
            const double after = half_step_kinetic(sim);
            EXPECT_NEAR(sim.totals().kinetic_energy, 0.5 * (before + after), 1e-12 * std::max(before, after)) << "step " << n + 1;
            work[mode].push_back(sim.totals().external_work);
            kinetic[mode].push_back(sim.totals().kinetic_energy);
        }
    }
    for (std::size_t n = 0; n < work[0].size(); ++n) {
        // The linear elastic strip's pressure does not depend on its internal energy: the two runs
        // move alike, to round-off.
        EXPECT_NEAR(kinetic[1][n], kinetic[0][n], 1e-9 * kinetic[0][n]);
        if (n >= 3) {
            EXPECT_NEAR(work[1][n], work[0][n], 1e-9 * work[0][n]) << "step " << n + 1;
        } else {
            EXPECT_LT(work[1][n], work[0][n]) << "step " << n + 1 << ": half of the last load's work is not done at t^{n+1}";
        }
    }
}

TEST(Embedding, NodesKeepTheirIdsThroughReordering) {
    Scene scene = free_strip();
    scene.solver.reorder_interval = 3;
    scene.bodies[0].velocity = {5.0, -7.0, 0.0};
    Simulation sim(scene, 2);
    std::vector<std::array<double, 2>> start(sim.real_count());
    for (std::uint64_t id = 0; id < sim.real_count(); ++id) {
        const std::size_t i = sim.index_of(id);
        start[id] = {sim.nodes().initial_position[0][i], sim.nodes().initial_position[1][i]};
    }
    bool moved = false;
    for (int n = 0; n < 10; ++n) {
        sim.step();
        for (std::uint64_t id = 0; id < sim.real_count(); ++id) {
            const std::size_t i = sim.index_of(id);
            ASSERT_EQ(sim.nodes().id[i], id);
            moved = moved || i != id;
            // The node is the same node: its initial position goes with it.
            ASSERT_EQ(sim.nodes().initial_position[0][i], start[id][0]);
            ASSERT_EQ(sim.nodes().initial_position[1][i], start[id][1]);
        }
    }
    EXPECT_TRUE(moved) << "the reordering should have moved some nodes";
}

TEST(Embedding, BadCallsAreRefusedWithTheirReason) {
    Simulation sim(testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 6e-3, 4, 1.0, 1e-7, 0.3), 1);
    const std::uint64_t count = sim.real_count();
    EXPECT_NE(refusal_of([&] { (void)sim.index_of(count); }).find(fmt::format("node id {}: no particle node has it", count)), std::string::npos);
    EXPECT_NE(refusal_of([&] { sim.apply_force(count + 5, {1, 0, 0}); }).find("no particle node"), std::string::npos);
    EXPECT_NE(refusal_of([&] { sim.apply_force(0, {std::nan(""), 0, 0}); }).find("not finite"), std::string::npos);
    EXPECT_NE(refusal_of([&] { sim.apply_force(0, {0, 0, 1.0}); }).find("third component"), std::string::npos);
    // The bottom rows are the clamp's: their z velocity is the region's.
    std::uint64_t clamped = count;
    for (std::uint64_t id = 0; id < count && clamped == count; ++id) {
        if (sim.nodes().velocity_region[sim.index_of(id)] == 2) clamped = id;
    }
    ASSERT_LT(clamped, count);
    EXPECT_NE(refusal_of([&] { sim.set_velocity(clamped, {0, 1, 0}); }).find("held along z by the prescribed-velocity region \"clamp\""),
              std::string::npos);

    const std::string unknown = refusal_of([&] { sim.set_region_velocity("piston", {0, 1, 0}); });
    EXPECT_NE(unknown.find("no prescribed-velocity region \"piston\""), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("\"grip\", \"clamp\""), std::string::npos) << unknown;
    EXPECT_NE(refusal_of([&] { sim.set_region_velocity("grip", {1, 1, 0}); }).find("leaves component x free"), std::string::npos);
    // Nothing refused changed the run: no load waits, no velocity moved.
    sim.step();
    EXPECT_EQ(sim.totals().external_work, 0.0);
    // A held node's free component may be set, the held one keeping its value.
    const std::size_t c = sim.index_of(clamped);
    EXPECT_EQ(refusal_of([&] { sim.set_velocity(clamped, {0.25, sim.nodes().velocity[1][c], 0}); }), "");
    EXPECT_EQ(sim.nodes().velocity[0][c], 0.25);
}

TEST(Embedding, ARegionVelocitySetBetweenStepsIsHeldFromTheNextStep) {
    Simulation sim(testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 6e-3, 4, 1.0, 1e-6, 0.3), 1);
    for (int n = 0; n < 3; ++n) sim.step();
    sim.set_region_velocity("grip", {0.0, 3.5, 0.0});
    sim.step();
    std::size_t held = 0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (sim.nodes().velocity_region[i] != 1) continue;
        ++held;
        EXPECT_EQ(sim.nodes().velocity[1][i], 3.5);
    }
    EXPECT_GT(held, 0u);
    EXPECT_EQ(sim.totals().regions[0].velocity[1], 3.5);
    EXPECT_EQ(sim.scene().prescribed_velocities[0].ramp, 0.0);
    // The region's displacement is its nodes' (the step after a change still moves them with the
    // velocity imposed before it; the change would put it dt * 4.5 m/s, some 1e-8 m, ahead), to
    // round-off of the positions: 6 mm has an ulp of 8.7e-19 m, over ten steps.
    sim.set_region_velocity("grip", {0.0, -1.0, 0.0});
    for (int n = 0; n < 5; ++n) sim.step();
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (sim.nodes().velocity_region[i] != 1) continue;
        EXPECT_NEAR(sim.nodes().position[1][i] - sim.nodes().initial_position[1][i], sim.totals().regions[0].displacement[1], 1e-16);
    }
}

TEST(Embedding, ADamagedCountOfWaitingLoadsIsACheckpointErrorNotAnAllocation) {
    const Scene scene = testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 6e-3, 4, 1.0, 1e-6, 0.3);
    Simulation a(scene, 1);
    a.step();
    a.apply_force(3, {1.0, 2.0, 0.0});
    std::stringstream file;
    a.save_checkpoint(file, "test");
    std::string bytes = file.str();
    const std::size_t tag = bytes.find("EXTL");
    ASSERT_NE(tag, std::string::npos);
    for (const std::uint64_t count : {std::uint64_t(1) << 32, std::uint64_t(1) << 27, std::uint64_t(2)}) {
        std::string damaged = bytes;
        std::memcpy(damaged.data() + tag + 4, &count, sizeof count);
        Simulation b(scene, 1);
        std::istringstream in(damaged);
        EXPECT_THROW(b.restore_checkpoint(in, damaged.size(), "damaged", "test"), CheckpointError) << count;
    }
    // A load on a node the scene does not have.
    std::string damaged = bytes;
    const std::uint32_t id = 1u << 30;
    std::memcpy(damaged.data() + tag + 4 + 8, &id, sizeof id);
    Simulation b(scene, 1);
    std::istringstream in(damaged);
    EXPECT_THROW(b.restore_checkpoint(in, damaged.size(), "damaged", "test"), CheckpointError);
}

TEST(Embedding, LoadsWaitingForTheNextStepAndRegionVelocitiesAreInTheCheckpoint) {
    const Scene scene = testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 6e-3, 4, 1.0, 1e-6, 0.3);
    const auto drive = [](Simulation& sim, int n) {
        sim.apply_force(3, {10.0 * n, -5.0, 0.0});
        sim.set_region_velocity("grip", {0.0, 0.1 * n, 0.0});
    };
    Simulation a(scene, 1);
    for (int n = 0; n < 8; ++n) {
        drive(a, n);
        a.step();
    }
    drive(a, 8);  // waiting when the checkpoint is written
    std::stringstream file;
    a.save_checkpoint(file, "test");
    const std::string bytes = file.str();
    Simulation b(scene, 2);
    std::istringstream in(bytes);
    b.restore_checkpoint(in, bytes.size(), "test checkpoint", "test");
    for (int n = 9; n < 20; ++n) {
        a.step();
        b.step();
        drive(a, n);
        drive(b, n);
    }
    EXPECT_EQ(testing::node_bytes(a), testing::node_bytes(b));
    EXPECT_EQ(a.totals().external_work, b.totals().external_work);
    EXPECT_EQ(a.totals().regions[0].work, b.totals().regions[0].work);
}

// docs/api.md, "Building a scene in code", as written there.
TEST(Embedding, TheApiPagesSceneBuiltInCodeRuns) {
    using gpa::io::parse_quantity;
    using gpa::io::Dimension;
    gpa::Scene scene;
    scene.name = "copper bar";
    scene.geometry = gpa::GeometryKind::Axisymmetric;
    scene.materials.push_back(gpa::io::builtin_material("OFHC copper"));
    gpa::BodySpec bar;
    bar.name = "bar";
    bar.material = "OFHC copper";
    bar.radius = parse_quantity("3.81 mm", Dimension::Length);
    bar.length = parse_quantity("25.4 mm", Dimension::Length);
    bar.spacing = parse_quantity("0.635 mm", Dimension::Length);
    bar.velocity = {0.0, -parse_quantity("190 m/s", Dimension::Velocity), 0.0};
    scene.bodies.push_back(bar);
    gpa::PlaneSpec anvil;
    anvil.name = "anvil";
    scene.planes.push_back(anvil);
    scene.stop.end_time = 80e-6;
    gpa::Simulation sim(scene, /*threads=*/0);
    for (int n = 0; n < 20; ++n) sim.step();
    EXPECT_EQ(sim.real_count(), 6u * 40u);          // 3.81 / 0.635 across, 25.4 / 0.635 along
    EXPECT_GT(sim.totals().planes.at(0).impulse, 0.0);  // it stands on the anvil
    // A mistake in it is refused with the reader's words.
    scene.bodies[0].spacing = -1.0;
    EXPECT_NE(refusal_of([&] { gpa::Simulation bad(scene, 1); }).find("spacing"), std::string::npos);
}

// --- the run loop ------------------------------------------------------------------------------

const fs::path tiny_scene = fs::path(GPA_SOURCE_DIR) / "tests" / "cli" / "tiny.toml";

fs::path scratch(const std::string& name) {
    const fs::path p = fs::temp_directory_path() / ("gpa_test_embedding_" + name);
    fs::remove_all(p);
    fs::remove_all(p.string() + ".partial");
    return p;
}

std::string read_file(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

io::RunSettings settings_for(const fs::path& folder) {
    io::RunSettings s;
    s.output = folder;
    s.threads = 1;
    return s;
}

#ifdef GPA_CLI
// summary.json without its timings (wall and output seconds, speeds), which differ from run to run.
std::string without_timings(const std::string& text) {
    std::istringstream in(text);
    std::string out, line;
    while (std::getline(in, line)) {
        if (line.find("_seconds") == std::string::npos && line.find("_per_second") == std::string::npos) out += line + "\n";
    }
    return out;
}

TEST(RunLoopLibrary, WritesTheSameFilesAsTheProgram) {
    const fs::path by_program = scratch("program"), by_library = scratch("library");
    const std::string command = fmt::format("\"{}\" run -q --threads 1 -o \"{}\" \"{}\" > /dev/null", GPA_CLI, by_program.string(),
                                            tiny_scene.string());
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    io::RunLoop run(io::SceneSource::from_file(tiny_scene), settings_for(by_library));
    const io::RunResult result = run.run();
    ASSERT_EQ(result.status, io::RunStatus::Finished) << result.message;
    EXPECT_EQ(result.folder, by_library);
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(by_program)) {
        const std::string name = entry.path().filename().string();
        const fs::path other = by_library / name;
        ASSERT_TRUE(fs::exists(other)) << name;
        ++files;
        if (name == "summary.json") {
            EXPECT_EQ(without_timings(read_file(entry.path())), without_timings(read_file(other))) << name;
        } else {
            EXPECT_EQ(read_file(entry.path()), read_file(other)) << name;
        }
    }
    // scene.toml, history.csv, summary.json, profile.csv, particles.pvd and the snapshots of the
    // first and the last step (a scene without an end time).
    EXPECT_GE(files, 7u);
    EXPECT_EQ(files, static_cast<std::size_t>(std::distance(fs::directory_iterator(by_library), fs::directory_iterator())));
    fs::remove_all(by_program);
    fs::remove_all(by_library);
}
#endif

TEST(RunLoopLibrary, AStopRequestLeavesACheckpointAndTheResumedRunEndsWhereAnUnbrokenOneDoes) {
    const fs::path whole = scratch("whole"), broken = scratch("broken");
    io::RunLoop reference(io::SceneSource::from_file(tiny_scene), settings_for(whole));
    ASSERT_EQ(reference.run().status, io::RunStatus::Finished);

    {
        io::RunLoop first(io::SceneSource::from_file(tiny_scene), settings_for(broken));
        io::RunHooks hooks;
        hooks.stop_requested = [&] { return first.simulation().steps() == 7 ? io::StopRequest{42, "the test"} : io::StopRequest{}; };
        const io::RunResult stopped = first.run(hooks);
        ASSERT_EQ(stopped.status, io::RunStatus::Interrupted) << stopped.message;
        EXPECT_EQ(stopped.stop_code, 42);
        EXPECT_TRUE(stopped.resumable);
        EXPECT_EQ(stopped.message, "stopped by the test after step 7 at t = " +
                                       fmt::format("{:.6g}", first.simulation().time() * 1e6) + " us");
        EXPECT_NE(read_file(first.partial_folder() / "summary.json").find("stopped by the test"), std::string::npos);
        // Its folder stays locked while the loop exists: a second run is refused.
        EXPECT_THROW(io::RunLoop::resume(broken, std::nullopt, settings_for({})), io::OutputError);
    }

    auto second = io::RunLoop::resume(broken, std::nullopt, settings_for({}));
    EXPECT_TRUE(second->resumed());
    EXPECT_EQ(second->simulation().steps(), 7u);
    const io::RunResult done = second->run();
    ASSERT_EQ(done.status, io::RunStatus::Finished) << done.message;
    EXPECT_EQ(read_file(whole / "history.csv"), read_file(broken / "history.csv"));
    EXPECT_EQ(testing::node_bytes(reference.simulation()), testing::node_bytes(second->simulation()));
    fs::remove_all(whole);
    fs::remove_all(broken);
}

TEST(RunLoopLibrary, AHookThatThrowsFailsTheRunAndKeepsWhatWasWritten) {
    const fs::path folder = scratch("hook");
    io::RunLoop run(io::SceneSource::from_file(tiny_scene), settings_for(folder));
    io::RunHooks hooks;
    hooks.after_step = [](Simulation& sim) {
        if (sim.steps() == 5) throw std::runtime_error("the coupled model diverged");
    };
    const io::RunResult result = run.run(hooks);
    EXPECT_EQ(result.status, io::RunStatus::Failed);
    EXPECT_EQ(result.message, "the coupled model diverged");
    EXPECT_FALSE(result.failure.has_value());
    EXPECT_EQ(result.folder, run.partial_folder());
    const std::string summary = read_file(run.partial_folder() / "summary.json");
    EXPECT_NE(summary.find("\"failed\""), std::string::npos);
    EXPECT_NE(summary.find("the coupled model diverged"), std::string::npos);
    EXPECT_FALSE(fs::exists(folder));  // not committed
    EXPECT_THROW((void)run.run(), std::logic_error);
    fs::remove_all(run.partial_folder());
}

TEST(RunLoopLibrary, WarningsGoToTheCallbackOrAreKept) {
    io::SceneSource source = io::SceneSource::from_file(tiny_scene);
    source.text += "\n[reference]\nelements = \"no-such.elements.toml\"\n";
    const fs::path folder = scratch("warnings");
    {
        io::RunLoop kept(source, settings_for(folder));
        ASSERT_EQ(kept.warnings().size(), 1u);
        EXPECT_NE(kept.warnings()[0].find("no-such.elements.toml"), std::string::npos) << kept.warnings()[0];
    }
    std::vector<std::string> told;
    io::RunSettings settings = settings_for(folder);
    settings.warning = [&](const std::string& w) { told.push_back(w); };
    io::RunLoop run(source, settings);
    EXPECT_TRUE(run.warnings().empty());
    ASSERT_EQ(told.size(), 1u);
    EXPECT_NE(told[0].find("no-such.elements.toml"), std::string::npos);
    ASSERT_EQ(run.run().status, io::RunStatus::Finished);
    // The run goes on without the reference; its report is the run's.
    EXPECT_NE(io::run_report(run.simulation()).find("20 steps"), std::string::npos);
    fs::remove_all(folder);
}

// Warnings of the steps: an automatic Armco bar whose threshold is never reached (as in
// LatticeCells.CollapsedCellsOfAnAutomaticBodySwitchAtOnce) switches the nodes of its collapsed
// impact-face cells; each step that does is told to the hook, or kept with the set-up's warnings.
TEST(RunLoopLibrary, StepWarningsGoToTheirHookOrAreKept) {
    io::SceneSource source;
    source.name = source.label = "collapse.toml";
    source.text = R"(
name = "collapse"
geometry = "axisymmetric"
[[body]]
name = "cylinder"
shape = "cylinder"
material = "Armco iron"
radius = "5.1 mm"
length = "15.2 mm"
spacing = "0.85 mm"
velocity = [0, "-305 m/s"]
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
lift_off = false
[solver]
connectivity = "automatic"
switch_plastic_strain = 100
viscosity = "nodal"
[stop]
end_time = "20 us"
[output]
snapshots = 0
)";
    const fs::path folder = scratch("step_warnings");
    std::vector<std::string> told;
    std::size_t switched = 0;
    {
        io::RunLoop run(source, settings_for(folder));
        io::RunHooks hooks;
        hooks.step_warning = [&](const std::string& w) { told.push_back(w); };
        hooks.after_step = [&](Simulation& sim) { switched += sim.totals().collapse_switches; };
        ASSERT_EQ(run.run(hooks).status, io::RunStatus::Finished);
        EXPECT_TRUE(run.warnings().empty());
    }
    ASSERT_FALSE(told.empty()) << "no lattice cell collapsed: the test needs another case";
    EXPECT_NE(told[0].find("switched to variable connectivity because a lattice cell collapsed; first: body \"cylinder\", node "),
              std::string::npos) << told[0];
    EXPECT_EQ(told[0].rfind("step ", 0), 0u) << told[0];
    std::size_t counted = 0;  // the messages' counts add up to the switches of the steps
    for (const std::string& w : told) counted += std::stoul(w.substr(w.find(": ") + 2));
    EXPECT_EQ(counted, switched);
    // Without the hook they join the set-up's warnings.
    io::RunSettings settings = settings_for(folder);
    settings.overwrite = true;
    io::RunLoop kept(source, settings);
    ASSERT_EQ(kept.run().status, io::RunStatus::Finished);
    EXPECT_EQ(kept.warnings(), told);
    fs::remove_all(folder);
}

TEST(RunLoopLibrary, ResumeRefusesAFolderWithoutACheckpointAndAnotherScene) {
    const fs::path folder = scratch("resume");
    fs::create_directories(folder.string() + ".partial");
    try {
        (void)io::RunLoop::resume(folder, std::nullopt, settings_for({}));
        ADD_FAILURE() << "an empty folder was resumed";
    } catch (const io::OutputError& e) {
        EXPECT_NE(std::string(e.what()).find("there is nothing to resume"), std::string::npos) << e.what();
    }
    fs::remove_all(folder.string() + ".partial");
    // A run stopped after 3 steps, resumed with a scene that is not its own.
    {
        io::RunLoop first(io::SceneSource::from_file(tiny_scene), settings_for(folder));
        io::RunHooks hooks;
        hooks.stop_requested = [&] { return first.simulation().steps() == 3 ? io::StopRequest{2, "the test"} : io::StopRequest{}; };
        ASSERT_EQ(first.run(hooks).status, io::RunStatus::Interrupted);
    }
    io::SceneSource other = io::SceneSource::from_file(tiny_scene);
    other.text += "\n# changed\n";
    other.name = "changed tiny.toml";
    EXPECT_THROW((void)io::RunLoop::resume(folder, other, settings_for({})), CheckpointError);
    // The folder is as it was: its own scene still resumes it.
    EXPECT_EQ(io::RunLoop::resume(folder, std::nullopt, settings_for({}))->run().status, io::RunStatus::Finished);
    fs::remove_all(folder);
}

TEST(RunLoopLibrary, AProgressHookThatThrowsFailsTheRunAndTheProgramsDataComesBackOnResume) {
    const fs::path folder = scratch("progress");
    {
        io::RunLoop run(io::SceneSource::from_file(tiny_scene), settings_for(folder));
        io::RunHooks hooks;
        hooks.progress = [](const Simulation& sim, bool) {
            if (sim.steps() == 4) throw 42;  // not even a std::exception
        };
        const io::RunResult result = run.run(hooks);
        EXPECT_EQ(result.status, io::RunStatus::Failed);
        EXPECT_NE(result.message.find("not a std::exception"), std::string::npos) << result.message;
        EXPECT_TRUE(fs::exists(run.partial_folder() / "summary.json"));
    }
    const std::string data("support state\n\0\xff", 16);
    {
        io::RunSettings settings = settings_for(folder);
        settings.overwrite = true;
        io::RunLoop run(io::SceneSource::from_file(tiny_scene), settings);
        io::RunHooks hooks;
        hooks.stop_requested = [&] { return run.simulation().steps() == 6 ? io::StopRequest{1, "the test"} : io::StopRequest{}; };
        hooks.checkpoint_data = [&] { return data; };
        EXPECT_TRUE(run.checkpoint_data().empty());
        ASSERT_EQ(run.run(hooks).status, io::RunStatus::Interrupted);
    }
    auto resumed = io::RunLoop::resume(folder, std::nullopt, settings_for({}));
    EXPECT_EQ(resumed->checkpoint_data(), data);
    EXPECT_EQ(resumed->run().status, io::RunStatus::Finished);
    fs::remove_all(folder);
}

TEST(RunLoopLibrary, RefusesARunWithoutAFolderAndASceneWithMistakesBeforeWritingAnything) {
    EXPECT_NE(refusal_of([] { io::RunLoop run(io::SceneSource::from_file(tiny_scene), io::RunSettings{}); }).find("output folder"),
              std::string::npos);
    const fs::path folder = scratch("bad");
    io::SceneSource bad = io::SceneSource::from_file(tiny_scene);
    bad.text.replace(bad.text.find("\"0.25 mm\""), 9, "\"-1 mm\"");
    bad.name = "edited tiny.toml";
    const std::string message = refusal_of([&] { io::RunLoop run(bad, settings_for(folder)); });
    EXPECT_NE(message.find("edited tiny.toml"), std::string::npos) << message;
    EXPECT_FALSE(fs::exists(folder));
    EXPECT_FALSE(fs::exists(folder.string() + ".partial"));
}

}  // namespace
}  // namespace gpa
