// Element bodies in scene files and outputs: the discretisation key and its errors, the .vtu of an
// element mesh read back, snapshots of both kinds in one .pvd, the profile of an element body,
// and the study variant that turns a scene's bodies into elements.

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

const std::string bar_scene = R"toml(
name = "element bar"
geometry = "axisymmetric"
[[material]]
name = "rubber"
density = 1000
shear_modulus = "1 MPa"
eos = { model = "linear", bulk_modulus = "10 MPa" }
strength = "elastic"
[[body]]
name = "bar"
shape = "cylinder"
material = "rubber"
radius = "2 mm"
length = "6 mm"
spacing = "1 mm"
velocity = [0, "-1 m/s"]
discretisation = "elements"
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
side = "above"
lift_off = false
[stop]
end_time = "1 us"
)toml";

std::string error_of(const std::string& text) {
    try {
        parse_scene(text, "scene.toml");
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SceneError";
    return {};
}

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
}

TEST(ElementScene, DiscretisationKeyReadsAndDefaultsToParticles) {
    EXPECT_EQ(parse_scene(bar_scene, "s.toml").bodies[0].discretisation, Discretisation::Elements);
    EXPECT_EQ(parse_scene(replaced(bar_scene, "discretisation = \"elements\"\n", ""), "s.toml").bodies[0].discretisation,
              Discretisation::Particles);
}

TEST(ElementScene, BadDiscretisationsFailNamingTheKey) {
    EXPECT_NE(error_of(replaced(bar_scene, "\"elements\"", "\"finite elements\"")).find("discretisation"), std::string::npos);
    const std::string in_3d = error_of(replaced(replaced(bar_scene, "\"axisymmetric\"", "\"3d\""), "velocity = [0, \"-1 m/s\"]",
                                                "velocity = [0, 0, \"-1 m/s\"]"));
    EXPECT_NE(in_3d.find("2D only"), std::string::npos) << in_3d;
    const std::string connectivity = error_of(replaced(bar_scene, "discretisation = \"elements\"\n",
                                                       "discretisation = \"elements\"\nconnectivity = \"fixed\"\n"));
    EXPECT_NE(connectivity.find("particle bodies only"), std::string::npos) << connectivity;
    // One kind per scene: a second body of particles is refused, naming both.
    const std::string mixed = error_of(bar_scene + R"toml(
[[body]]
name = "target"
shape = "cylinder"
material = "rubber"
origin = [0, "10 mm"]
radius = "2 mm"
length = "2 mm"
spacing = "1 mm"
)toml");
    EXPECT_NE(mixed.find("\"bar\""), std::string::npos) << mixed;
    EXPECT_NE(mixed.find("\"target\""), std::string::npos) << mixed;
    EXPECT_NE(mixed.find("one kind"), std::string::npos) << mixed;
}

// Reads the appended block of the DataArray called `name` of a VTK XML file as raw bytes.
std::string block(const std::string& file, const std::string& name) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    const auto tag = text.find("Name=\"" + name + "\"");
    EXPECT_NE(tag, std::string::npos) << name;
    const auto offset_at = text.find("offset=\"", tag) + 8;
    const std::uint64_t offset = std::stoull(text.substr(offset_at, text.find('"', offset_at) - offset_at));
    const auto data = text.find("<AppendedData encoding=\"raw\">");
    const auto start = text.find('_', data) + 1 + offset;
    std::uint64_t bytes = 0;
    std::memcpy(&bytes, text.data() + start, 8);
    return text.substr(start + 8, bytes);
}

template <class T>
std::vector<T> values(const std::string& raw) {
    std::vector<T> out(raw.size() / sizeof(T));
    std::memcpy(out.data(), raw.data(), raw.size());
    return out;
}

TEST(ElementOutputs, VtuHoldsTheTrianglesOfEveryQuadrilateralAndTheirFields) {
    const Scene scene = parse_scene(bar_scene, "s.toml");
    ElementMesh mesh = mesh_element_bodies(scene);
    for (std::size_t i = 0; i < mesh.points.size(); ++i) mesh.points.plastic_strain[i] = 0.001 * double(i);
    const fs::path dir = fs::temp_directory_path() / "gpa_element_outputs";
    fs::create_directories(dir);
    const std::string file = (dir / "mesh.vtu").string();
    write_vtu(file, mesh);
    std::ifstream in(file);
    std::string head;
    std::getline(in, head);
    std::getline(in, head);
    EXPECT_NE(head.find("UnstructuredGrid"), std::string::npos);
    const auto connectivity = values<std::int64_t>(block(file, "connectivity"));
    ASSERT_EQ(connectivity.size(), 3 * mesh.triangles());
    for (std::size_t t = 0; t < mesh.triangles(); ++t) {
        const auto& q = mesh.quads.nodes[t / 4];
        EXPECT_EQ(connectivity[3 * t], q[4]);
        EXPECT_EQ(connectivity[3 * t + 1], q[t % 4]);
        EXPECT_EQ(connectivity[3 * t + 2], q[(t % 4 + 1) % 4]);
    }
    const auto types = block(file, "types");
    EXPECT_EQ(types, std::string(mesh.triangles(), char{5}));
    const auto strain = values<double>(block(file, "plastic_strain"));
    ASSERT_EQ(strain.size(), mesh.triangles());
    EXPECT_EQ(strain.back(), mesh.points.plastic_strain.back());
    const auto mass = values<double>(block(file, "mass"));
    ASSERT_EQ(mass.size(), mesh.nodes.size());
    EXPECT_EQ(mass[3], mesh.nodes.mass[3]);
    // Node ids, as particle snapshots have them: an element node's index, which never changes.
    const auto ids = values<std::int64_t>(block(file, "id"));
    ASSERT_EQ(ids.size(), mesh.nodes.size());
    for (std::size_t i = 0; i < ids.size(); ++i) ASSERT_EQ(ids[i], static_cast<std::int64_t>(i));
}

TEST(ElementOutputs, SnapshotsOfElementBodiesJoinTheSeriesAndTheRunWritesTheirProfile) {
    const Scene scene = parse_scene(bar_scene, "s.toml");
    Simulation sim(scene, 1);
    while (!sim.finished()) sim.step();
    const fs::path dir = fs::temp_directory_path() / "gpa_element_series";
    fs::remove_all(dir);
    fs::create_directories(dir);
    SnapshotSeries series(dir);
    const auto names = series.write(take_snapshot(sim));
    ASSERT_EQ(names.size(), 1u);  // no particles: the .vtu alone
    EXPECT_EQ(names[0], "elements_00000.vtu");
    EXPECT_TRUE(fs::exists(dir / names[0]));
    std::ifstream pvd(dir / "particles.pvd");
    std::stringstream text;
    text << pvd.rdbuf();
    EXPECT_NE(text.str().find("file=\"elements_00000.vtu\""), std::string::npos);
    // A snapshot holding both kinds lists both as parts of one time step.
    Snapshot both = take_snapshot(sim);
    both.particles.resize(3);
    const auto two = series.write(both);
    ASSERT_EQ(two.size(), 2u);
    std::ifstream pvd2(dir / "particles.pvd");
    std::stringstream text2;
    text2 << pvd2.rdbuf();
    EXPECT_NE(text2.str().find("part=\"1\" file=\"elements_00001.vtu\""), std::string::npos) << text2.str();
    EXPECT_EQ(series.scheduled(), 2u);  // time steps
    EXPECT_EQ(series.count(), 3u);      // files in the .pvd

    // The profile of an element body: its boundary, from the face on the anvil (radius 2 mm, the
    // corner node) to the top (6 mm), ending at (top, 0).
    write_profile(dir / "profile.csv", sim);
    std::ifstream profile(dir / "profile.csv");
    std::string line;
    std::getline(profile, line);
    EXPECT_EQ(line, "height_m,radius_m");
    double h = 0, r = 0, first_r = -1, last_h = 0, last_r = -1;
    char comma;
    while (profile >> h >> comma >> r) {
        if (first_r < 0) first_r = r;
        last_h = h;
        last_r = r;
    }
    EXPECT_NEAR(first_r, 2e-3, 1e-5);  // 1 us of a 1 m/s impact moves nodes by ~1 um at most
    EXPECT_NEAR(last_h, sim.totals().length, 1e-12);
    EXPECT_EQ(last_r, 0.0);
}

TEST(ElementStudy, TheDiscretisationVariantTurnsEveryBodyIntoElements) {
    Scene scene = parse_scene(replaced(bar_scene, "discretisation = \"elements\"\n", "connectivity = \"fixed\"\n"), "s.toml");
    const Variant v = parse_variant("el:discretisation=elements");
    apply_variant(v, scene);
    EXPECT_EQ(scene.bodies[0].discretisation, Discretisation::Elements);
    EXPECT_FALSE(scene.bodies[0].connectivity.has_value());
    EXPECT_THROW(parse_variant("el:discretisation=fem"), InputError);
}

}  // namespace
}  // namespace gpa::io
