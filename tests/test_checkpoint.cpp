// Checkpoints (Simulation::save_checkpoint / restore_checkpoint): a run stopped at any step and
// continued from its checkpoint, on another thread count, ends with node data identical byte
// for byte to a run never stopped; a checkpoint of another scene, build or format, or a damaged
// one, is refused with a message.

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

// The totals a history row and a summary print, as bytes.
std::string totals_bytes(const Totals& t) {
    std::string out;
    const auto add = [&](const auto& v) { out.append(reinterpret_cast<const char*>(&v), sizeof v); };
    for (const double v : {t.time, t.time_step, t.kinetic_energy, t.internal_energy, t.plastic_work, t.viscous_work,
                           t.boundary_work, t.energy_error, t.momentum[0], t.momentum[1], t.momentum[2], t.length,
                           t.footprint_diameter, t.footprint_narrowest, t.footprint_widest}) {
        add(v);
    }
    for (const std::size_t v : {t.step, t.real_nodes, t.ghost_nodes, t.variable_nodes, t.failed_nodes, t.pairs,
                                t.neighbour_searches, t.row_searches, t.rows_searched}) {
        add(v);
    }
    for (const auto& p : t.planes) {
        add(p.reaction);
        add(p.impulse);
        add(p.friction_work);
    }
    add(t.energy_given);
    for (const auto& r : t.regions) {
        add(r.nodes);
        add(r.work);
        for (int c = 0; c < 3; ++c) {
            for (const double v : {r.velocity[c], r.displacement[c], r.reaction[c], r.impulse[c]}) add(v);
        }
    }
    return out;
}

std::string checkpoint_of(const Simulation& sim, const std::string& fingerprint = "scene-a", const std::string& user = "") {
    std::ostringstream out;
    sim.save_checkpoint(out, fingerprint, user);
    return out.str();
}

std::string restore(Simulation& sim, const std::string& bytes, const std::string& fingerprint = "scene-a") {
    std::istringstream in(bytes);
    return sim.restore_checkpoint(in, bytes.size(), "test", fingerprint);
}

Scene three_d_quarter_bar(int radial_cells) {
    auto scene = testing::armco_cylinder(radial_cells, 40e-6);
    scene.geometry = GeometryKind::ThreeD;
    auto& bar = scene.bodies[0];
    bar.shape = ShapeKind::Box;
    bar.size = {bar.radius, bar.radius, bar.length};
    bar.origin = {0.0, 0.0, 0.0};
    bar.velocity = {0.0, 0.0, -305.0};
    scene.planes[0].axis = 2;
    for (int axis : {0, 1}) {
        PlaneSpec p;
        p.name = axis == 0 ? "x = 0" : "y = 0";
        p.kind = PlaneKind::Symmetry;
        p.axis = axis;
        scene.planes.push_back(p);
    }
    return scene;
}

struct Case {
    const char* name;
    Scene scene;
    int stop_at;  // the step of the checkpoint
    int steps;    // the steps of the whole run
    bool both_ways = false;  // stopped on 1 thread and resumed on 2, and the other way round; else 1 -> 2
};

std::vector<Case> cases() {
    std::vector<Case> out;
    {
        // About 4800 nodes: every parallel loop and reduction is split over several ranges.
        auto scene = testing::armco_cylinder(40, 40e-6);
        scene.solver.reorder_interval = 20;  // reorderings before and after the checkpoint
        out.push_back({"axisymmetric Taylor bar, variable, skin, reordering", scene, 27, 45, true});
    }
    {
        auto scene = testing::armco_cylinder(12, 40e-6);
        scene.solver.connectivity = ConnectivityMode::Automatic;  // switching: searches forced mid-skin
        scene.solver.switch_plastic_strain = 0.05;
        scene.solver.smoothing = SmoothingMode::Everywhere;
        out.push_back({"automatic switching with smoothing", scene, 131, 180});
    }
    {
        auto scene = testing::elastic_bar_on_plane(1e-3, 12e-3, 8, 100.0);  // lift-off contacts come and go
        scene.solver.viscosity = ViscosityKind::Bond;  // largest_bond_q is read by the next step's time step
        scene.solver.smoothing = SmoothingMode::Tension;
        scene.stop = {};
        scene.stop.max_steps = 100000;
        out.push_back({"elastic bar on a lift-off plane, bond viscosity", scene, 211, 300});
        // The same on a plane with Coulomb friction: the ring slides out along it and sticks.
        scene.planes[0].friction_dynamic = 0.3;
        scene.planes[0].friction_static = 0.5;
        out.push_back({"elastic bar on a plane with friction", scene, 151, 260});
    }
    {
        // A fast shot into a resting bar: rows searched alone before and after the checkpoint,
        // each row from its own reference (NeighbourLists::search_rows).
        auto scene = testing::struck_by_a_fast_body(testing::armco_cylinder(12, 40e-6), ConnectivityMode::Automatic);
        out.push_back({"a bar struck by a fast shot, rows searched alone", scene, 61, 110});
    }
    {
        auto scene = three_d_quarter_bar(4);
        scene.solver.connectivity = ConnectivityMode::Automatic;
        scene.solver.switch_plastic_strain = 0.05;
        out.push_back({"3D quarter bar on symmetry planes, automatic", scene, 47, 70});
    }
    {
        // The relaxing stiffness on every flowing node, both fits quadratic: the reference positions
        // are a node field of their own (mirrored to the ghosts of the symmetry planes, reordered),
        // and the kept curvature of the fits feeds the energy booking.
        auto scene = three_d_quarter_bar(4);
        scene.solver.hourglass_fit = HourglassFitOrder::Quadratic;
        scene.solver.hourglass_stiffness = 0.01;
        scene.solver.hourglass_stiffness_relaxation = 2e-6;
        scene.solver.reorder_interval = 20;
        out.push_back({"3D quarter bar, relaxing stiffness and quadratic fits", scene, 31, 60, true});
    }
    {
        // Prescribed velocities: the work booked up to the last step and that step's own, the
        // impulses and displacements, the held nodes renumbered by reorderings.
        auto scene = testing::pulled_elastic_bar(GeometryKind::Axisymmetric, 1e-3, 10e-3, 10, 5.0, 0.2e-6, 0.3);
        scene.solver.smoothing = SmoothingMode::Tension;
        scene.solver.reorder_interval = 20;
        scene.stop = {};
        scene.stop.max_steps = 100000;
        out.push_back({"pulled bar with a grip and a clamp, smoothing in tension", scene, 37, 80, true});
    }
    {
        auto scene = testing::armco_cylinder(10, 40e-6);
        scene.solver.neighbour_skin = 0.0;  // a search and a plan every step
        scene.solver.scatter = ScatterScheme::Graph;
        out.push_back({"no skin, graph colouring", scene, 0, 60});  // a checkpoint before the first step
    }
    return out;
}

TEST(Checkpoint, AResumedRunIsBitIdenticalToOneNeverStoppedOnOneAndTwoThreads) {
    for (auto& c : cases()) {
        SCOPED_TRACE(c.name);
        std::vector<std::pair<int, int>> threads{{1, 2}};
        if (c.both_ways) threads.push_back({2, 1});
        for (const auto& [first, second] : threads) {
            SCOPED_TRACE(::testing::Message() << "stopped on " << first << " thread(s), resumed on " << second);
            // The run that is never stopped writes the checkpoint on its way (writing one
            // changes nothing: WritingOneChangesNothing); another Simulation resumes from it.
            Simulation never_stopped(c.scene, first);
            for (int k = 0; k < c.stop_at; ++k) never_stopped.step();
            const std::string saved = checkpoint_of(never_stopped, "scene-a", "user data");
            Simulation resumed(c.scene, second);
            ASSERT_EQ(restore(resumed, saved), "user data");
            ASSERT_EQ(resumed.steps(), static_cast<std::size_t>(c.stop_at));
            for (int k = c.stop_at; k < c.steps; ++k) never_stopped.step();
            for (int k = c.stop_at; k < c.steps; ++k) resumed.step();
            ASSERT_EQ(never_stopped.steps(), resumed.steps());
            EXPECT_TRUE(testing::node_bytes(never_stopped) == testing::node_bytes(resumed))
                << "node data differ after " << c.steps << " steps";
            EXPECT_TRUE(totals_bytes(never_stopped.totals()) == totals_bytes(resumed.totals()));
            EXPECT_TRUE(never_stopped.neighbour_lists() == resumed.neighbour_lists());
            EXPECT_EQ(never_stopped.node_steps(), resumed.node_steps());
        }
    }
}

// The sections of a checkpoint, in the order Simulation::Impl::write_state writes them: the nodes
// and ghosts, each part of the step that keeps state of its own (neighbour lists, measures, energy
// ledger, prescribed-velocity regions), the step's own time and totals.
std::vector<std::pair<std::string, std::string>> sections_of(const std::string& bytes) {
    static const std::vector<std::string> tags{"SIMU", "LIST", "TIME", "MEAS", "ENRG", "PVEL", "TOTL", "END."};
    std::vector<std::pair<std::string, std::string>> out;
    std::size_t from = 0;
    std::vector<std::size_t> at;
    for (const auto& tag : tags) {
        const std::size_t found = bytes.find(tag, from);
        if (found == std::string::npos) {
            ADD_FAILURE() << "no section " << tag;
            return out;
        }
        at.push_back(found);
        from = found + tag.size();
    }
    for (std::size_t k = 0; k + 1 < tags.size(); ++k) out.emplace_back(tags[k], bytes.substr(at[k], at[k + 1] - at[k]));
    return out;
}

// A checkpoint cut at the starts of its fields: each field's bytes, the section it is in (the last
// tag before it; "head" before the first) and its place in that section.
struct CheckpointField {
    std::string section;
    std::size_t index = 0;
    std::string bytes;
};

std::vector<CheckpointField> fields_of(const std::string& file, const std::vector<std::uint64_t>& starts) {
    static const std::vector<std::string> tags{"SIMU", "GHST", "LIST", "TIME", "MEAS", "ENRG", "PVEL", "EXTL", "ELEM", "TOTL", "END."};
    std::vector<CheckpointField> out;
    const std::size_t end = file.size() - sizeof(std::uint64_t);  // the checksum is no field
    std::string section = "head";
    std::size_t index = 0;
    for (std::size_t k = 0; k < starts.size(); ++k) {
        const std::size_t from = starts[k], to = k + 1 < starts.size() ? starts[k + 1] : end;
        if (from > to || to > end) {
            ADD_FAILURE() << "field " << k << " lies outside the file";
            return out;
        }
        std::string bytes = file.substr(from, to - from);
        if (bytes.size() == 4 && std::find(tags.begin(), tags.end(), bytes) != tags.end()) {
            section = bytes;
            index = 0;
        }
        out.push_back({section, index++, std::move(bytes)});
    }
    return out;
}

TEST(Checkpoint, EveryPartRestoresItsOwnSectionExactly) {
    // Each part of the step saves and restores its own section (simulation.cpp, engine/src/step/):
    // a run restored from a checkpoint writes the same checkpoint again, section by section, so no
    // part leaves out a member or restores one it recomputes differently. The cases of the
    // resume test cover the lists with and without a skin, ghosts, contacts, bond viscosity,
    // regions, switching and 3D; one more adds the hourglass stiffness's stored energy.
    auto all = cases();
    {
        auto scene = testing::pulled_elastic_bar(GeometryKind::PlaneStrain, 1e-3, 10e-3, 8, 5.0, 0.2e-6, 0.3);
        scene.solver.connectivity = ConnectivityMode::Fixed;
        scene.solver.hourglass_stiffness = 0.05;
        scene.stop = {};
        scene.stop.max_steps = 100000;
        all.push_back({"pulled plane-strain bar, fixed, hourglass stiffness", scene, 40, 40});
    }
    for (auto& c : all) {
        SCOPED_TRACE(c.name);
        Simulation first(c.scene, 2);
        for (int k = 0; k < c.stop_at; ++k) first.step();
        const std::string saved = checkpoint_of(first);
        Simulation restored(c.scene, 1);
        restore(restored, saved);
        const std::string again = checkpoint_of(restored);
        const auto a = sections_of(saved), b = sections_of(again);
        ASSERT_EQ(a.size(), 7u);
        ASSERT_EQ(b.size(), a.size());
        for (std::size_t k = 0; k < a.size(); ++k) {
            EXPECT_TRUE(a[k].second == b[k].second) << "section " << a[k].first << " differs after a round trip ("
                                                    << a[k].second.size() << " and " << b[k].second.size() << " bytes)";
        }
        // Field by field, as each part lists its fields (Simulation::checkpoint_field_starts):
        // the same fields, in the same places, with the same bytes; a difference names its part's
        // section and the field's place in it.
        const auto fields_a = fields_of(saved, first.checkpoint_field_starts("scene-a"));
        const auto fields_b = fields_of(again, restored.checkpoint_field_starts("scene-a"));
        ASSERT_GT(fields_a.size(), 150u);  // the header's, the tags, every node field and the parts' (199 in 2D)
        ASSERT_EQ(fields_a.size(), fields_b.size());
        for (std::size_t k = 0; k < fields_a.size(); ++k) {
            EXPECT_EQ(fields_a[k].section, fields_b[k].section);
            EXPECT_TRUE(fields_a[k].bytes == fields_b[k].bytes)
                << "section " << fields_a[k].section << ", field " << fields_a[k].index << " differs after a round trip ("
                << fields_a[k].bytes.size() << " and " << fields_b[k].bytes.size() << " bytes)";
        }
        EXPECT_TRUE(saved == again);
        if (c.name == std::string("pulled plane-strain bar, fixed, hourglass stiffness")) {
            EXPECT_GT(first.totals().hourglass_energy, 0.0);  // the stiffness section holds something
            EXPECT_EQ(first.totals().hourglass_energy, restored.totals().hourglass_energy);
        }
    }
}

// The state of a run's element bodies as the checkpoint encodes it (ElementPart::write_state).
std::string element_bytes(const Simulation& sim) {
    std::ostringstream out;
    StateWriter w(out);
    sim.elements()->write_state(w);
    return out.str();
}

Scene with_element_bodies(Scene scene) {
    for (auto& b : scene.bodies) {
        b.discretisation = Discretisation::Elements;
        b.connectivity.reset();
        b.lattice_neighbours = 0;
    }
    scene.stop = {};
    scene.stop.max_steps = 100000;
    return scene;
}

TEST(Checkpoint, AnElementRunResumesBitIdenticallyOnOneAndTwoThreads) {
    // Element bodies (elements.hpp) checkpoint their own section: a run stopped and resumed, on
    // another thread count, ends with every element field and every total identical byte for
    // byte to a run never stopped. The bar bounces on a lift-off plane (plane contacts come and go,
    // reactions and impulses); the pulled bar holds element nodes in prescribed regions.
    struct ElementCase {
        const char* name;
        Scene scene;
        int stop_at, steps;
    };
    const std::vector<ElementCase> element_cases{
        {"element bar on a lift-off plane", with_element_bodies(testing::elastic_bar_on_plane(1e-3, 12e-3, 6, 100.0)), 150, 260},
        {"pulled element bar with a grip and a clamp",
         with_element_bodies(testing::pulled_elastic_bar(GeometryKind::Axisymmetric, 1e-3, 10e-3, 6, 5.0, 0.2e-6, 0.3)), 60, 120},
    };
    for (const auto& c : element_cases) {
        SCOPED_TRACE(c.name);
        for (const auto& [first, second] : std::vector<std::pair<int, int>>{{1, 2}, {2, 1}}) {
            SCOPED_TRACE(::testing::Message() << "stopped on " << first << " thread(s), resumed on " << second);
            Simulation never_stopped(c.scene, first);
            ASSERT_NE(never_stopped.elements(), nullptr);
            ASSERT_TRUE(never_stopped.can_checkpoint());
            for (int k = 0; k < c.stop_at; ++k) never_stopped.step();
            const std::string saved = checkpoint_of(never_stopped);
            Simulation resumed(c.scene, second);
            restore(resumed, saved);
            ASSERT_EQ(resumed.steps(), static_cast<std::size_t>(c.stop_at));
            EXPECT_TRUE(element_bytes(never_stopped) == element_bytes(resumed)) << "element state differs right after the restore";
            for (int k = c.stop_at; k < c.steps; ++k) never_stopped.step();
            for (int k = c.stop_at; k < c.steps; ++k) resumed.step();
            EXPECT_TRUE(element_bytes(never_stopped) == element_bytes(resumed)) << "element state differs after " << c.steps << " steps";
            EXPECT_TRUE(totals_bytes(never_stopped.totals()) == totals_bytes(resumed.totals()));
            EXPECT_EQ(never_stopped.element_steps(), resumed.element_steps());
            // The run moved: the comparison is not of two states at rest.
            EXPECT_GT(never_stopped.totals().kinetic_energy, 0.0);
        }
    }
}

TEST(Checkpoint, WritingOneChangesNothing) {
    // A run that writes checkpoints is the run that does not: save_checkpoint only reads.
    const auto scene = testing::armco_cylinder(12, 40e-6);
    Simulation plain(scene, 2), saving(scene, 2);
    for (int k = 0; k < 120; ++k) {
        plain.step();
        saving.step();
        if (k % 7 == 0) (void)checkpoint_of(saving);
    }
    EXPECT_TRUE(testing::node_bytes(plain) == testing::node_bytes(saving));
}

template <class F>
std::string refusal(F&& f) {
    try {
        f();
    } catch (const CheckpointError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no CheckpointError";
    return {};
}

TEST(Checkpoint, ThoseOfAnotherSceneBuildOrFormatAreRefusedBeforeAnythingChanges) {
    const auto scene = testing::armco_cylinder(8, 40e-6);
    Simulation a(scene, 1);
    for (int k = 0; k < 30; ++k) a.step();
    const std::string saved = checkpoint_of(a);
    const auto info_of = [](const std::string& bytes) {
        std::istringstream in(bytes);
        return Simulation::checkpoint_info(in, bytes.size(), "test");
    };
    EXPECT_EQ(info_of(saved).step, 30u);
    EXPECT_EQ(info_of(saved).scene_fingerprint, "scene-a");
    EXPECT_EQ(info_of(saved).format, Simulation::checkpoint_format);

    Simulation b(scene, 1);
    const std::string before = testing::node_bytes(b);
    auto m = refusal([&] { restore(b, saved, "scene-b"); });
    EXPECT_NE(m.find("another scene"), std::string::npos) << m;
    // Another build: the build id is the first text of the header.
    std::string other_build = saved;
    const auto at = other_build.find("gpa ");
    ASSERT_NE(at, std::string::npos);
    other_build[at + 4] = 'X';
    m = refusal([&] { restore(b, other_build); });
    EXPECT_NE(m.find("written by"), std::string::npos) << m;
    // Another format version (bytes 8-11).
    std::string other_format = saved;
    other_format[8] = 99;
    m = refusal([&] { restore(b, other_format); });
    EXPECT_NE(m.find("format 99"), std::string::npos) << m;
    m = refusal([&] { restore(b, std::string("not a checkpoint at all")); });
    EXPECT_NE(m.find("not a gpa checkpoint"), std::string::npos) << m;
    // None of these touched b: it still steps like a fresh run.
    EXPECT_TRUE(testing::node_bytes(b) == before);
    EXPECT_NO_THROW(b.step());
}

TEST(Checkpoint, DamagedOnesAreRefusedAndLeaveTheSimulationUnusable) {
    const auto scene = testing::armco_cylinder(8, 40e-6);
    Simulation a(scene, 1);
    for (int k = 0; k < 30; ++k) a.step();
    const std::string saved = checkpoint_of(a);
    std::string flipped = saved;
    flipped[saved.size() / 2] ^= 0x10;  // one bit in the node data
    Simulation b(scene, 1);
    auto m = refusal([&] { restore(b, flipped); });
    EXPECT_NE(m.find("damaged"), std::string::npos) << m;
    EXPECT_THROW(b.step(), NumericalError);

    for (const std::size_t cut : {std::size_t{1}, std::size_t{100}, saved.size() / 3}) {
        Simulation c(scene, 1);
        m = refusal([&] { restore(c, saved.substr(0, saved.size() - cut)); });
        EXPECT_FALSE(m.empty());
    }
    // A checkpoint of another scene under the same fingerprint (a caller's mistake) is refused
    // too, not read into arrays of another size.
    Simulation other(testing::armco_cylinder(10, 40e-6), 1);
    m = refusal([&] { restore(other, saved); });
    EXPECT_NE(m.find("nodes"), std::string::npos) << m;
}

TEST(Checkpoint, AnElementCheckpointOfAnotherMeshIsRefused) {
    // The mesh comes from the scene; a checkpoint of a mesh of another size is refused by name.
    const auto coarse = with_element_bodies(testing::elastic_bar_on_plane(1e-3, 12e-3, 6, 100.0));
    const auto fine = with_element_bodies(testing::elastic_bar_on_plane(1e-3, 12e-3, 8, 100.0));
    Simulation a(coarse, 1);
    for (int k = 0; k < 5; ++k) a.step();
    const std::string saved = checkpoint_of(a);
    Simulation b(fine, 1);
    const std::string message = refusal([&] { restore(b, saved); });
    EXPECT_NE(message.find("its element mesh has"), std::string::npos) << message;
}

}  // namespace
}  // namespace gpa
