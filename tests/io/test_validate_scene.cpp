// validate_scene gives an embedder who builds a Scene in code the same rules a scene file gets,
// with messages naming the body, plane, material or option.

#include <filesystem>
#include <functional>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa {
namespace {

// A Taylor bar on an anvil, built in code.
Scene taylor_scene() {
    Scene s;
    s.geometry = GeometryKind::Axisymmetric;
    s.materials.push_back(io::builtin_material("OFHC copper"));
    BodySpec bar;
    bar.name = "bar";
    bar.shape = ShapeKind::Cylinder;
    bar.radius = 0.00381;
    bar.length = 0.0254;
    bar.spacing = 0.000254;
    bar.material = "OFHC copper";
    bar.velocity = {0, -190, 0};
    s.bodies.push_back(bar);
    PlaneSpec anvil;
    anvil.name = "anvil";
    anvil.axis = 1;
    anvil.position = 0.0;
    anvil.lift_off = false;
    s.planes.push_back(anvil);
    s.stop.end_time = 150e-6;
    return s;
}

// Applies `change` to the Taylor scene and returns validate_scene's message ("" if it passed).
std::string message_after(const std::function<void(Scene&)>& change) {
    Scene s = taylor_scene();
    change(s);
    try {
        validate_scene(s);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

#define EXPECT_MESSAGE_HAS(change, fragment)                                                  \
    do {                                                                                     \
        const std::string message_ = message_after(change);                                  \
        EXPECT_NE(message_.find(fragment), std::string::npos) << "message: \"" << message_ << "\""; \
    } while (0)

TEST(ValidateScene, TaylorSceneBuiltInCodePasses) { EXPECT_NO_THROW(validate_scene(taylor_scene())); }

// Implausible but valid values are warned about, one message each, naming what to check; the
// shipped scenes and the Taylor scene have none.
TEST(SceneWarnings, NameImplausibleSpeedsSizesAndEndTimes) {
    EXPECT_TRUE(scene_warnings(taylor_scene()).empty());
    const auto warned = [](const std::function<void(Scene&)>& change) {
        Scene s = taylor_scene();
        change(s);
        EXPECT_NO_THROW(validate_scene(s)) << "a warning is no refusal";
        return scene_warnings(s);
    };
    auto w = warned([](Scene& s) { s.bodies[0].velocity = {0, -190e3, 0}; });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("body \"bar\" (body[0]): a speed of 190 km/s"), std::string::npos) << w[0];
    EXPECT_NE(w[0].find("check its unit"), std::string::npos) << w[0];
    EXPECT_TRUE(warned([](Scene& s) { s.bodies[0].velocity = {0, -19e3, 0}; }).empty()) << "19 km/s may be meant";
    w = warned([](Scene& s) {
        s.bodies[0].radius = 3.81;  // the copper bar in m where mm were meant
        s.bodies[0].length = 25.4;
        s.bodies[0].spacing = 0.254;
    });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("it is 25.4 m across, larger than"), std::string::npos) << w[0];
    w = warned([](Scene& s) {
        s.bodies[0].radius = 3.81e-6;  // and in um
        s.bodies[0].length = 25.4e-6;
        s.bodies[0].spacing = 0.254e-6;
    });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("it is 7.62 um across, smaller than"), std::string::npos) << w[0];
    w = warned([](Scene& s) { s.stop.end_time = 150.0; });
    ASSERT_EQ(w.size(), 1u);
    EXPECT_NE(w[0].find("stop.end_time: 150 s"), std::string::npos) << w[0];
    for (const auto& entry : std::filesystem::directory_iterator(GPA_SCENES_DIR)) {
        if (entry.path().extension() != ".toml") continue;
        EXPECT_TRUE(scene_warnings(io::load_scene(entry.path())).empty()) << entry.path();
    }
}

TEST(ValidateScene, BodiesMayTouchButNotOverlap) {
    // A second bar stacked on the first: touching end to end passes; moved down by one lattice
    // spacing, its lowest row of nodes (cell centres half a spacing above its base) lies inside the
    // first bar and the scene is refused, naming both bars and the 15 nodes of that row (3.81 mm
    // radius at 0.254 mm: 15 cells across the radius).
    const auto stacked = [](double gap) {
        return [gap](Scene& s) {
            BodySpec top = s.bodies[0];
            top.name = "top";
            top.origin[1] = top.length + gap;
            s.bodies.push_back(top);
        };
    };
    EXPECT_EQ(message_after(stacked(0.0)), "");
    EXPECT_EQ(message_after(stacked(1e-3)), "");
    EXPECT_EQ(message_after(stacked(-0.254e-3)),
              "body \"bar\" (body[0]) overlaps body \"top\" (body[1]): 15 of its nodes lie inside it, the first at "
              "(x, z) = (0.127, 25.273) mm; bodies may touch but not overlap (move one, or make it smaller)");
    // A hollow sphere's core is not inside it: a short bar in the cavity passes (its corners are
    // 4.47 mm from the centre, the cavity's radius is 5 mm).
    EXPECT_EQ(message_after([](Scene& s) {
                  BodySpec shell;
                  shell.name = "shell";
                  shell.shape = ShapeKind::Sphere;
                  shell.origin = {0.0, 0.0127, 0.0};
                  shell.radius = 0.008;
                  shell.inner_radius = 0.005;
                  shell.spacing = 0.000254;
                  shell.material = "OFHC copper";
                  s.bodies[0].radius = 0.002;
                  s.bodies[0].origin[1] = 0.0087;
                  s.bodies[0].length = 0.008;
                  s.bodies.push_back(shell);
              }),
              "");
}

TEST(ValidateScene, BodiesAndMaterials) {
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies.clear(); }, "at least one body");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].material = "brass"; }, "body \"bar\" (body[0]).material: \"brass\"");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.materials[0].density = 0.0; }, "density");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.materials.push_back(s.materials[0]); }, "already used");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies.push_back(s.bodies[0]); }, "body \"bar\" (body[1]): the name is already used");
}

TEST(ValidateScene, ShapesAndSizes) {
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].shape = ShapeKind::Box; }, "a box is a 3D shape");
    EXPECT_MESSAGE_HAS(
        [](Scene& s) {
            s.geometry = GeometryKind::ThreeD;
            s.planes[0].axis = 2;
            s.bodies[0].shape = ShapeKind::Rectangle;
        },
        "a rectangle is a 2D shape");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].origin[0] = 0.001; }, "origin x must be 0");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].radius = -0.001; }, "body \"bar\" (body[0]).radius = -0.001");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].length = 0.0; }, ".length = 0");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].spacing = 0.0; }, ".spacing = 0");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].spacing = 0.002; }, "fewer than 2 nodes across its radius");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].spacing_z = 0.02; }, "fewer than 2 nodes across its extent");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].velocity[1] = std::numeric_limits<double>::quiet_NaN(); },
                       "velocity[1] must be finite");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.bodies[0].lattice_neighbours = 6; }, "lattice_neighbours = 6 is not 4 or 8");
    EXPECT_EQ(message_after([](Scene& s) { s.bodies[0].lattice_neighbours = 4; }), "");
    EXPECT_EQ(message_after([](Scene& s) { s.bodies[0].spacing = 0.003810 / 2; }), "");  // exactly 2 across
}

TEST(ValidateScene, Planes) {
    EXPECT_MESSAGE_HAS([](Scene& s) { s.planes[0].axis = 2; }, "plane \"anvil\" (plane[0]).axis = 2");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.planes[0].position = 0.001; }, "wrong side");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.planes[0].side = -1; }, "wrong side");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.planes[0].side = 0; }, "side = 0");
    EXPECT_MESSAGE_HAS(
        [](Scene& s) {
            s.planes[0].axis = 0;
            s.planes[0].position = 0.0;
        },
        "x > 0");
    // A confining wall around the bar, and the bar resting exactly on the anvil, are fine.
    EXPECT_EQ(message_after([](Scene& s) {
                  PlaneSpec wall;
                  wall.name = "wall";
                  wall.axis = 0;
                  wall.position = 0.00381;
                  wall.side = -1;
                  s.planes.push_back(wall);
              }),
              "");
}

TEST(ValidateScene, OptionRanges) {
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.influence_distance = 0.79; }, "solver.influence_distance = 0.79");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.influence_distance = 1.51; }, "[0.8, 1.5]");
    EXPECT_EQ(message_after([](Scene& s) { s.solver.influence_distance = 0.8; }), "");
    EXPECT_EQ(message_after([](Scene& s) { s.solver.influence_distance = 1.5; }), "");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.cfl = 0.0; }, "solver.cfl = 0 is outside (0, 1]");
    EXPECT_EQ(message_after([](Scene& s) { s.solver.cfl = 1.0; }), "");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.smoothing_coefficient = 1.0; }, "solver.smoothing_coefficient = 1");
    EXPECT_EQ(message_after([](Scene& s) { s.solver.smoothing_coefficient = 0.0; }), "");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.switch_plastic_strain = 0.0; }, "solver.switch_plastic_strain");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.viscosity_linear = -0.1; }, "solver.viscosity_linear");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.bond_viscosity_eps0 = 0.0; }, "solver.bond_viscosity_eps0");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.time_step_growth = 0.9; }, "solver.time_step_growth");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.solver.max_time_step = 0.0; }, "solver.max_time_step");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.stop.kinetic_energy_fraction = 1.0; }, "stop.kinetic_energy_fraction");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.output.history_every = 0; }, "output.history_every");
    EXPECT_MESSAGE_HAS([](Scene& s) { s.reference["x"] = std::numeric_limits<double>::infinity(); }, "reference.x");
}

TEST(ValidateScene, AnEndConditionIsRequired) {
    EXPECT_MESSAGE_HAS([](Scene& s) { s.stop = StopCriteria{}; }, "no end condition");
    EXPECT_EQ(message_after([](Scene& s) {
                  s.stop = StopCriteria{};
                  s.stop.max_steps = 10;
              }),
              "");
    EXPECT_EQ(message_after([](Scene& s) {
                  s.stop = StopCriteria{};
                  s.stop.kinetic_energy_fraction = 0.01;
              }),
              "");
}

}  // namespace
}  // namespace gpa
