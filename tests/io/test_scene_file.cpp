// Scene files parse to the Scene they describe: values in SI, defaults from scene.hpp, library
// and scene-defined materials, derived materials, references; and no input crashes the reader.

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include <gtest/gtest.h>

#include "gpa/engine/solver_options.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa::io {
namespace {

namespace m = gpa::materials;

const std::string test_dir = GPA_IO_TEST_DIR;

std::string error_of(std::string_view text, const std::string& file = "scene.toml") {
    try {
        parse_scene(text, file);
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SceneError";
    return {};
}

// A small valid scene; tests add or replace lines.
const std::string minimal_head = R"toml(
geometry = "plane-strain"
[stop]
end_time = "10 us"
)toml";

const std::string elastic_material = R"toml(
[[material]]
name = "rubber"
density = 1000
shear_modulus = "1 MPa"
eos = { model = "linear", bulk_modulus = "10 MPa" }
strength = "elastic"
)toml";

TEST(SceneFile, TaylorImpactParsesToTheExpectedScene) {
    const Scene s = load_scene(test_dir + "/good_scenes/taylor_copper.toml");
    EXPECT_EQ(s.name, "taylor-copper-190");
    EXPECT_EQ(s.geometry, GeometryKind::Axisymmetric);

    ASSERT_EQ(s.bodies.size(), 1u);
    const BodySpec& bar = s.bodies[0];
    EXPECT_EQ(bar.name, "bar");
    EXPECT_EQ(bar.shape, ShapeKind::Cylinder);
    EXPECT_EQ(bar.material, "OFHC copper");
    EXPECT_EQ(bar.origin, (std::array<double, 3>{0, 0, 0}));
    EXPECT_EQ(bar.radius, 0.00381);
    EXPECT_EQ(bar.length, 0.0254);
    EXPECT_EQ(bar.spacing, 0.000254);
    EXPECT_EQ(bar.spacing_z, 0.0);
    EXPECT_EQ(bar.velocity, (std::array<double, 3>{0, -190.0, 0}));
    EXPECT_FALSE(bar.connectivity.has_value());
    EXPECT_EQ(bar.lattice_neighbours, 0);

    ASSERT_EQ(s.planes.size(), 1u);
    const PlaneSpec& anvil = s.planes[0];
    EXPECT_EQ(anvil.name, "anvil");
    EXPECT_EQ(anvil.kind, PlaneKind::Rigid);
    EXPECT_EQ(anvil.axis, 1);
    EXPECT_EQ(anvil.position, 0.0);
    EXPECT_EQ(anvil.side, 1);
    EXPECT_FALSE(anvil.lift_off);

    EXPECT_EQ(s.solver.connectivity, ConnectivityMode::Variable);
    EXPECT_EQ(s.solver.viscosity, ViscosityKind::Nodal);
    EXPECT_EQ(s.solver.viscosity_linear, 0.2);
    EXPECT_EQ(s.solver.viscosity_quadratic, 4.0);
    EXPECT_EQ(s.solver.influence_distance, 1.0);
    EXPECT_EQ(s.stop.end_time, 150e-6);
    EXPECT_EQ(s.stop.kinetic_energy_fraction, 0.01);
    EXPECT_EQ(s.stop.max_steps, 0u);
    EXPECT_EQ(s.output.snapshots, 30u);

    // Only the library material the bar uses is copied into the scene.
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_EQ(s.materials[0].name, "OFHC copper");
    EXPECT_EQ(s.materials[0].density, 8960.0);

    EXPECT_EQ(s.reference.at("final_length"), 0.01621);
    EXPECT_EQ(s.reference.at("footprint_diameter"), 0.01356);
    EXPECT_NE(s.reference_source.find("Johnson and Cook"), std::string::npos);
}

TEST(SceneFile, AbsentOptionsTakeTheDefaultsOfSceneHpp) {
    const Scene s = parse_scene(minimal_head + elastic_material + R"toml(
[[body]]
shape = "rectangle"
material = "rubber"
size = ["10 mm", "20 mm"]
spacing = "1 mm"
)toml",
                                "dir/minimal.toml");
    EXPECT_EQ(s.name, "minimal");  // from the file name
    EXPECT_EQ(s.description, "");
    EXPECT_EQ(s.bodies[0].name, "body0");
    EXPECT_EQ(s.bodies[0].size, (std::array<double, 3>{0.01, 0.02, 0}));

    const SolverOptions d;
    EXPECT_EQ(s.solver.connectivity, d.connectivity);
    EXPECT_EQ(s.solver.switch_plastic_strain, d.switch_plastic_strain);
    EXPECT_EQ(s.solver.influence_distance, d.influence_distance);
    EXPECT_EQ(s.solver.weight, d.weight);
    EXPECT_EQ(s.solver.viscosity, d.viscosity);
    EXPECT_EQ(s.solver.viscosity_linear, d.viscosity_linear);
    EXPECT_EQ(s.solver.viscosity_quadratic, d.viscosity_quadratic);
    EXPECT_EQ(s.solver.bond_viscosity_eps0, d.bond_viscosity_eps0);
    EXPECT_EQ(s.solver.smoothing, d.smoothing);
    EXPECT_EQ(s.solver.smoothing_coefficient, d.smoothing_coefficient);
    EXPECT_EQ(s.solver.cfl, d.cfl);
    EXPECT_EQ(s.solver.alpha_limit, d.alpha_limit);
    EXPECT_EQ(s.solver.max_time_step, d.max_time_step);
    EXPECT_EQ(s.solver.time_step_growth, d.time_step_growth);
    EXPECT_EQ(s.solver.failure, d.failure);
    EXPECT_EQ(s.solver.scatter, d.scatter);
    EXPECT_EQ(s.solver.reorder_interval, d.reorder_interval);
    const OutputOptions o;
    EXPECT_EQ(s.output.snapshots, o.snapshots);
    EXPECT_EQ(s.output.snapshot_interval, o.snapshot_interval);
    EXPECT_EQ(s.output.history_every, o.history_every);
    EXPECT_EQ(s.stop.kinetic_energy_fraction, 0.0);
    EXPECT_EQ(s.stop.max_steps, 0u);
}

TEST(SceneFile, EveryOptionIsRead) {
    const Scene s = parse_scene(R"toml(
geometry = "3d"
[[material]]
name = "steel"
base = "4340 steel"
[[body]]
name = "block"
shape = "box"
material = "steel"
origin = ["-5 mm", "-5 mm", 0]
size = ["10 mm", "10 mm", "4 mm"]
spacing = "0.5 mm"
velocity = ["1 m/s", 0, "-0.5 km/s"]
initial_stress = { xx = "-10 MPa", xy = "2 MPa" }
connectivity = "automatic"
lattice_neighbours = 18
[[plane]]
kind = "symmetry"
axis = "x"
position = "-5 mm"
[[plane]]
kind = "rigid"
axis = "z"
position = "4 mm"
side = -1
[solver]
connectivity = "fixed"
switch_plastic_strain = 0.2
influence_distance = 1.2
weight = "sph-nsf"
viscosity = "bond"
viscosity_linear = 0.1
viscosity_quadratic = 2
bond_viscosity_eps0 = 0.02
smoothing = "tension"
smoothing_coefficient = 0.1
cfl = 0.4
alpha_limit = 2.5
max_time_step = "0.1 us"
time_step_growth = 1.05
failure = true
scatter = "cells"
reorder_interval = 50
[stop]
end_time = "20 us"
kinetic_energy_fraction = 0.05
max_steps = 1e6
[output]
snapshots = 0
snapshot_interval = "1 us"
history_every = 5
)toml",
                                "options.toml");
    const BodySpec& b = s.bodies[0];
    EXPECT_EQ(b.origin, (std::array<double, 3>{-0.005, -0.005, 0}));
    EXPECT_EQ(b.size, (std::array<double, 3>{0.01, 0.01, 0.004}));
    EXPECT_EQ(b.velocity, (std::array<double, 3>{1.0, 0.0, -500.0}));
    EXPECT_EQ(b.initial_stress, (std::array<double, 6>{-10e6, 0, 0, 0, 0, 2e6}));
    EXPECT_EQ(b.connectivity, ConnectivityMode::Automatic);
    EXPECT_EQ(b.lattice_neighbours, 18);
    ASSERT_EQ(s.planes.size(), 2u);
    EXPECT_EQ(s.planes[0].name, "plane0");
    EXPECT_EQ(s.planes[0].kind, PlaneKind::Symmetry);
    EXPECT_EQ(s.planes[0].axis, 0);
    EXPECT_EQ(s.planes[0].position, -0.005);
    EXPECT_EQ(s.planes[1].axis, 2);
    EXPECT_EQ(s.planes[1].side, -1);
    EXPECT_TRUE(s.planes[1].lift_off);

    EXPECT_EQ(s.solver.connectivity, ConnectivityMode::Fixed);
    EXPECT_EQ(s.solver.switch_plastic_strain, 0.2);
    EXPECT_EQ(s.solver.influence_distance, 1.2);
    EXPECT_EQ(s.solver.weight, WeightKind::SphNsf);
    EXPECT_EQ(s.solver.viscosity, ViscosityKind::Bond);
    EXPECT_EQ(s.solver.viscosity_linear, 0.1);
    EXPECT_EQ(s.solver.viscosity_quadratic, 2.0);
    EXPECT_EQ(s.solver.bond_viscosity_eps0, 0.02);
    EXPECT_EQ(s.solver.smoothing, SmoothingMode::Tension);
    EXPECT_EQ(s.solver.smoothing_coefficient, 0.1);
    EXPECT_EQ(s.solver.cfl, 0.4);
    EXPECT_EQ(s.solver.alpha_limit, 2.5);
    EXPECT_EQ(s.solver.max_time_step, 1e-7);
    EXPECT_EQ(s.solver.time_step_growth, 1.05);
    EXPECT_TRUE(s.solver.failure);
    EXPECT_EQ(s.solver.scatter, ScatterScheme::Cells);
    EXPECT_EQ(s.solver.reorder_interval, 50u);
    EXPECT_EQ(s.stop.end_time, 20e-6);
    EXPECT_EQ(s.stop.kinetic_energy_fraction, 0.05);
    EXPECT_EQ(s.stop.max_steps, 1000000u);
    EXPECT_EQ(s.output.snapshots, 0u);
    EXPECT_EQ(s.output.snapshot_interval, 1e-6);
    EXPECT_EQ(s.output.history_every, 5u);
}

TEST(SceneFile, InitialStressAsAnArrayInNodeStoreOrder) {
    const Scene s = parse_scene(minimal_head + elastic_material + R"toml(
[[body]]
shape = "rectangle"
material = "rubber"
size = [0.01, 0.01]
spacing = 0.001
initial_stress = ["-1 MPa", "-2 MPa", 0, "-3 MPa"]
)toml",
                                "stress.toml");
    EXPECT_EQ(s.bodies[0].initial_stress, (std::array<double, 6>{-1e6, -2e6, 0, -3e6, 0, 0}));
}

TEST(SceneFile, SceneDefinedMaterialHasEveryField) {
    const Scene s = parse_scene(minimal_head + R"toml(
[[material]]
name = "soft metal"
source = "made up for a test"
density = "2.7 g/cc"
shear_modulus = "26 GPa"
specific_heat = "900 J/(kg K)"
taylor_quinney = 1.0
room_temperature = "300 K"
melt_temperature = "900 K"
[material.eos]
model = "polynomial"
k1 = "70 GPa"
k2 = "100 GPa"
k3 = "-5 GPa"
gruneisen = 2.0
[material.strength]
model = "von-mises"
yield_stress = "300 MPa"
[material.failure]
spall_pressure = "1.2 GPa"
[material.failure.johnson_cook]
d1 = 0.1
d2 = 0.2
d3 = -1.5
d4 = 0.01
d5 = 0.0
min_failure_strain = 0.05
[[body]]
shape = "cylinder"
material = "Soft Metal"
radius = "5 mm"
length = "10 mm"
spacing = "1 mm"
spacing_z = "0.5 mm"
)toml",
                                "own.toml");
    ASSERT_EQ(s.materials.size(), 1u);
    const m::Material& mat = s.materials[0];
    EXPECT_EQ(s.bodies[0].material, "soft metal");  // letter case of the definition
    EXPECT_EQ(s.bodies[0].spacing_z, 0.0005);
    EXPECT_EQ(mat.source, "made up for a test");
    EXPECT_EQ(mat.density, 2700.0);
    EXPECT_EQ(mat.shear_modulus, 26e9);
    EXPECT_EQ(mat.specific_heat, 900.0);
    EXPECT_EQ(mat.taylor_quinney, 1.0);
    EXPECT_EQ(mat.room_temperature, 300.0);
    EXPECT_EQ(mat.melt_temperature, 900.0);
    const auto& eos = std::get<m::PolynomialEos>(mat.eos);
    EXPECT_EQ(eos.k1, 70e9);
    EXPECT_EQ(eos.k2, 100e9);
    EXPECT_EQ(eos.k3, -5e9);
    EXPECT_EQ(eos.gruneisen, 2.0);
    EXPECT_EQ(std::get<m::VonMisesStrength>(mat.strength).yield_stress, 300e6);
    ASSERT_TRUE(mat.failure.spall_pressure.has_value());
    EXPECT_EQ(*mat.failure.spall_pressure, 1.2e9);
    ASSERT_TRUE(mat.failure.johnson_cook.has_value());
    EXPECT_EQ(mat.failure.johnson_cook->d3, -1.5);
    EXPECT_EQ(mat.failure.johnson_cook->reference_strain_rate, 1.0);
    EXPECT_EQ(mat.failure.johnson_cook->min_failure_strain, 0.05);
}

TEST(SceneFile, DerivedMaterialKeepsWhatItDoesNotOverride) {
    const Scene s = parse_scene(minimal_head + R"toml(
[[material]]
name = "hard steel"
base = "4340 steel"
density = "7.85 g/cc"
strength = { a = "950 MPa" }                 # no model: change the base's Johnson-Cook constants
eos = { sound_speed = "4600 m/s" }
failure = { spall_pressure = "3 GPa" }
[[material]]
name = "plastic copper"
base = "OFHC copper"
strength = { model = "von-mises", yield_stress = "200 MPa" }   # another model: its constants
failure = "none"
[[body]]
shape = "rectangle"
material = "hard steel"
size = ["4 mm", "4 mm"]
spacing = "1 mm"
[[body]]
shape = "rectangle"
material = "plastic copper"
origin = [0, "5 mm"]
size = ["4 mm", "4 mm"]
spacing = "1 mm"
)toml",
                                "derived.toml");
    const m::Material& base = builtin_material("4340 steel");
    const m::Material& hard = s.materials[0];
    EXPECT_EQ(hard.name, "hard steel");
    EXPECT_EQ(hard.density, 7850.0);
    EXPECT_EQ(hard.shear_modulus, base.shear_modulus);
    EXPECT_EQ(hard.melt_temperature, base.melt_temperature);
    const auto& jc = std::get<m::JohnsonCookStrength>(hard.strength);
    const auto& base_jc = std::get<m::JohnsonCookStrength>(base.strength);
    EXPECT_EQ(jc.a, 950e6);
    EXPECT_EQ(jc.b, base_jc.b);
    EXPECT_EQ(jc.n, base_jc.n);
    EXPECT_EQ(jc.m, base_jc.m);
    const auto& mg = std::get<m::MieGruneisenEos>(hard.eos);
    EXPECT_EQ(mg.sound_speed, 4600.0);
    EXPECT_EQ(mg.slope, std::get<m::MieGruneisenEos>(base.eos).slope);
    EXPECT_EQ(*hard.failure.spall_pressure, 3e9);
    ASSERT_TRUE(hard.failure.johnson_cook.has_value());  // kept from the base
    EXPECT_EQ(hard.failure.johnson_cook->d1, base.failure.johnson_cook->d1);
    EXPECT_NE(hard.source.find("4340 steel"), std::string::npos) << hard.source;
    EXPECT_NE(hard.source.find("density"), std::string::npos) << hard.source;

    const m::Material& copper = s.materials[1];
    EXPECT_EQ(std::get<m::VonMisesStrength>(copper.strength).yield_stress, 200e6);
    EXPECT_FALSE(copper.failure.johnson_cook.has_value());
    EXPECT_EQ(copper.density, 8960.0);
    // Neither library material is in the scene: the bodies use the derived ones.
    EXPECT_EQ(s.materials.size(), 2u);
}

TEST(SceneFile, LibraryNamesIgnoreLetterCase) {
    const Scene s = parse_scene(minimal_head + R"toml(
[[body]]
shape = "rectangle"
material = "armco IRON"
size = ["4 mm", "4 mm"]
spacing = "1 mm"
[[body]]
shape = "rectangle"
material = "Armco iron"
origin = [0, "5 mm"]
size = ["4 mm", "4 mm"]
spacing = "1 mm"
)toml",
                                "case.toml");
    EXPECT_EQ(s.bodies[0].material, "Armco iron");
    EXPECT_EQ(s.bodies[1].material, "Armco iron");
    EXPECT_EQ(s.materials.size(), 1u);
}

TEST(SceneFile, MessagesAreOneLineWithFileLineAndKey) {
    const std::string body = minimal_head + elastic_material + R"toml(
[[body]]
name = "bar"
shape = "cylinder"
material = "rubber"
raduis = "3 mm"
length = "10 mm"
spacing = "1 mm"
)toml";
    EXPECT_EQ(error_of(body, "bar.toml"), "bar.toml:17: body \"bar\" (body[0]).raduis: unknown key; did you mean \"radius\"?");

    const std::string negative = minimal_head + elastic_material + R"toml(
[[body]]
name = "bar"
shape = "cylinder"
material = "rubber"
radius = "-3 mm"
length = "10 mm"
spacing = "1 mm"
)toml";
    EXPECT_EQ(error_of(negative, "bar.toml"), "bar.toml:17: body \"bar\" (body[0]).radius: \"-3 mm\" must be a positive length");

    const std::string cfl = minimal_head + elastic_material + R"toml(
[[body]]
shape = "rectangle"
material = "rubber"
size = [0.01, 0.01]
spacing = 0.001
[solver]
cfl = 1.5
)toml";
    EXPECT_EQ(error_of(cfl, "cfl.toml"), "cfl.toml: solver.cfl = 1.5 is outside (0, 1]");
}

// A quote inside a bare value (2", 1.", -', a date or time followed by a quote) does not open a
// string for toml++, which tests the characters after it against its Unicode tables (where
// toml++ 3.3.0 reaches __builtin_unreachable for some of them): the guard reads the quote as
// toml++ does and refuses the non-ASCII character itself, in a value, an array and an inline table.
TEST(SceneFile, NonAsciiAfterAQuoteInABareValueIsRefusedBeforeTomlReadsIt) {
    for (const std::string value : {"2\"\xCF\xBB\"", "2.\"\xCF\xBB\"", "-'\xCF\xBB'", "+\"\"\"\xCF\xBB\"\"\"", "1e5\"\xC2\xA0\"",
                                    "1979-05-27'\xCF\xBB'", "07:32:00\"\xCF\xBB\"", "[1.\"\xCF\xBB\"]", "{ a = 2\"\xCF\xBB\" }"}) {
        const std::string m = error_of(minimal_head + "name = " + value + "\n");
        EXPECT_NE(m.find("a non-ASCII character outside a quoted string"), std::string::npos) << value << ": " << m;
    }
}

// Non-ASCII text where TOML allows it still reads: strings, quoted keys (dotted too), comments.
TEST(SceneFile, NonAsciiInStringsQuotedKeysAndCommentsReads) {
    const Scene s = parse_scene(R"toml(name = 'café ϻ'  # été
description = """bar é
   """
)toml" + minimal_head + elastic_material + R"toml(
[[body]]
name = "bär"
shape = "rectangle"
material = "rubber"
origin = [0, 0]
size = [0.01, 0.01]
spacing = 0.001
[reference]
source = "Müller (2020)"
"elements" = "e.toml"
)toml", "scene.toml");
    EXPECT_EQ(s.name, "café ϻ");
    EXPECT_EQ(s.bodies.at(0).name, "bär");
    EXPECT_EQ(s.reference_source, "Müller (2020)");
    // A quoted part of a dotted key reads as a key (the scene, which has no body, is refused by
    // the reader, not by the guard or as a syntax error).
    const std::string m = error_of(minimal_head + "[reference]\na.\"ü\" = 1\n");
    EXPECT_EQ(m.find("non-ASCII"), std::string::npos) << m;
    EXPECT_EQ(m.find("syntax error"), std::string::npos) << m;
}

TEST(SceneFile, QuotedTextCannotBreakTheMessageLine) {
    const std::string m = error_of(minimal_head + "[[body]]\nname = \"two\\nlines\"\nshape = \"cube\"\n");
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_NE(m.find("two\\nlines"), std::string::npos) << m;
}

// The examples of docs/scene-format.md read as they claim: whole scenes as scenes, [[material]]
// examples as a material library.
TEST(SceneFile, PrescribedVelocitiesReadTheirRegionVelocityAndRamp) {
    const std::string text = R"toml(
geometry = "axisymmetric"
[[body]]
name = "bar"
shape = "cylinder"
material = "4340 steel"
radius = "2 mm"
length = "20 mm"
spacing = "0.25 mm"
[[prescribed_velocity]]
name = "grip"
body = "bar"
region = { above = { z = "19 mm" }, within_radius = "1.5 mm" }
velocity = { z = "2 m/s" }
ramp = "5 us"
[[prescribed_velocity]]
body = "bar"
region = { box = { min = [0, 0], max = ["2 mm", "1 mm"] }, beyond_radius = "0.5 mm" }
velocity = [0, 0]
[stop]
end_time = "10 us"
)toml";
    const Scene s = parse_scene(text, "grip.toml");
    ASSERT_EQ(s.prescribed_velocities.size(), 2u);
    const auto& grip = s.prescribed_velocities[0];
    EXPECT_EQ(grip.name, "grip");
    EXPECT_EQ(grip.body, "bar");
    EXPECT_EQ(grip.lower[1], 0.019);
    EXPECT_EQ(grip.upper[1], INFINITY);
    EXPECT_EQ(grip.lower[0], -INFINITY);
    EXPECT_EQ(grip.radius_min, 0.0);
    EXPECT_EQ(grip.radius_max, 0.0015);
    EXPECT_FALSE(grip.velocity[0].has_value());
    EXPECT_EQ(grip.velocity[1], 2.0);
    EXPECT_FALSE(grip.velocity[2].has_value());
    EXPECT_EQ(grip.ramp, 5e-6);
    const auto& clamp = s.prescribed_velocities[1];
    EXPECT_EQ(clamp.name, "velocity1");
    EXPECT_EQ(clamp.lower, (std::array<double, 3>{0.0, 0.0, -INFINITY}));
    EXPECT_EQ(clamp.upper, (std::array<double, 3>{0.002, 0.001, INFINITY}));
    EXPECT_EQ(clamp.radius_min, 0.0005);
    EXPECT_EQ(clamp.velocity[0], 0.0);
    EXPECT_EQ(clamp.velocity[1], 0.0);
    EXPECT_EQ(clamp.ramp, 0.0);
}

TEST(SceneFile, DocumentationExamplesParse) {
    std::ifstream in(GPA_SCENE_FORMAT_DOC);
    ASSERT_TRUE(in) << GPA_SCENE_FORMAT_DOC;
    std::string line, block;
    bool inside = false;
    int scenes = 0, libraries = 0;
    while (std::getline(in, line)) {
        if (!inside && line == "```toml") {
            inside = true;
            block.clear();
        } else if (inside && line == "```") {
            inside = false;
            if (block.find("\ngeometry = ") != std::string::npos) {
                EXPECT_NO_THROW(parse_scene(block, "doc-example.toml")) << block;
                ++scenes;
            } else if (block.rfind("[[material]]", 0) == 0) {
                EXPECT_NO_THROW(parse_material_library(block, "doc-example.toml")) << block;
                ++libraries;
            }
        } else if (inside) {
            block += line + "\n";
        }
    }
    EXPECT_GE(scenes, 1);
    EXPECT_GE(libraries, 2);
}

// The project's own scenes (scenes/*.toml) all read.
TEST(SceneFile, APresetSetsItsKeysAndTheKeysBesideItOverrideIt) {
    const std::string body = R"toml(
[[body]]
shape = "rectangle"
material = "rubber"
size = ["4 mm", "4 mm"]
spacing = "1 mm"
)toml";
    const Scene taylor = parse_scene(minimal_head + elastic_material + body + "[solver]\npreset = \"taylor-bar\"\n", "scene.toml");
    EXPECT_EQ(taylor.solver.weight, WeightKind::SphNsf);
    EXPECT_EQ(taylor.solver.influence_distance, 1.3);
    EXPECT_EQ(taylor.solver.normalisation, Normalisation::PerDirection);
    // A key beside the preset wins, before or after it in the table.
    for (const std::string solver : {"[solver]\ninfluence_distance = 1.2\npreset = \"taylor-bar\"\n",
                                     "[solver]\npreset = \"taylor-bar\"\ninfluence_distance = 1.2\n"}) {
        const Scene s = parse_scene(minimal_head + elastic_material + body + solver, "scene.toml");
        EXPECT_EQ(s.solver.influence_distance, 1.2);
        EXPECT_EQ(s.solver.weight, WeightKind::SphNsf);
    }
    // "paper" is today's defaults, named.
    const Scene paper = parse_scene(minimal_head + elastic_material + body + "[solver]\npreset = \"paper\"\n", "scene.toml");
    const SolverOptions defaults;
    EXPECT_EQ(paper.solver.weight, defaults.weight);
    EXPECT_EQ(paper.solver.influence_distance, defaults.influence_distance);
    EXPECT_EQ(paper.solver.normalisation, defaults.normalisation);
    // Every preset names rows of the table with values they accept.
    for (const SolverPreset& p : solver_presets()) {
        SolverOptions o;
        apply_solver_preset(p, o);
        for (const SolverOption& option : solver_option_table()) EXPECT_FALSE(option_error(option, o).has_value()) << p.name;
    }
    // An unknown name: the line, the key, the presets and the nearest.
    const std::string text = minimal_head + elastic_material + body + "[solver]\npreset = \"tailor-bar\"\n";
    EXPECT_EQ(error_of(text), "scene.toml:19: solver.preset: \"tailor-bar\" is not one of \"paper\" or \"taylor-bar\" (did you "
                              "mean \"taylor-bar\"?)");
}

TEST(SceneFile, ProjectScenesParse) {
    const std::filesystem::path dir = GPA_SCENES_DIR;
    if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "no " << dir;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".toml") continue;
        EXPECT_NO_THROW(load_scene(entry.path())) << entry.path();
    }
}

TEST(SceneFile, MissingFileIsASceneError) {
    try {
        load_scene(test_dir + "/no/such/scene.toml");
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("no/such/scene.toml"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
    }
    EXPECT_THROW(load_scene(test_dir + "/good_scenes"), SceneError);
}

// No prefix of a good scene, and no single damaged byte, crashes the reader or escapes as
// anything but SceneError.
TEST(SceneFile, DamagedScenesFailCleanly) {
    const std::string path = test_dir + "/good_scenes/taylor_copper.toml";
    std::string text;
    {
        std::FILE* f = std::fopen(path.c_str(), "rb");
        ASSERT_NE(f, nullptr);
        char buffer[4096];
        std::size_t n = 0;
        while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
        std::fclose(f);
    }
    const auto try_parse = [](const std::string& t, std::size_t where) {
        try {
            parse_scene(t, "damaged.toml");
        } catch (const SceneError& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.find('\n'), std::string::npos) << m;
            EXPECT_EQ(m.rfind("damaged.toml", 0), 0u) << m;
        } catch (const std::exception& e) {
            ADD_FAILURE() << "at " << where << ": not a SceneError: " << e.what();
        }
    };
    for (std::size_t cut = 0; cut <= text.size(); ++cut) try_parse(text.substr(0, cut), cut);
    for (std::size_t i = 0; i < text.size(); i += 3) {
        for (const char replacement : {'\0', '"', '=', '[', '\xff', '9', '-'}) {
            std::string damaged = text;
            damaged[i] = replacement;
            try_parse(damaged, i);
        }
    }
}

}  // namespace
}  // namespace gpa::io
