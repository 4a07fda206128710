// The snapshot's arrays: `[output] fields` and `precision` read from scene files (and refused when
// wrong), files holding the chosen fields in their order with their types, Float32 values the
// nearest floats of the node data, and a set of files with every field, written with the values
// they must hold, for an independent VTK reader (tests/io/vtk_round_trip.py, run by ctest as
// io_vtk_round_trip).
//
// When the environment variable GPA_VTK_ROUND_TRIP_DIR names a folder, the last test writes its
// files and expected.txt there; otherwise into a temporary folder it removes.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/engine/snapshot_fields.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/snapshot_reader.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

// A small elastic-plastic bar 20 steps into its impact: every field is non-zero somewhere.
const std::string bar_2d = R"toml(
name = "bar"
geometry = "axisymmetric"
[[body]]
name = "bar"
shape = "cylinder"
material = "OFHC copper"
radius = "1 mm"
length = "3 mm"
spacing = "0.25 mm"
velocity = [0, "-200 m/s"]
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
[stop]
max_steps = 20
)toml";

const std::string bar_3d = R"toml(
name = "block"
geometry = "3d"
[[body]]
name = "block"
shape = "box"
material = "OFHC copper"
origin = [0, 0, 0]
size = ["1 mm", "0.75 mm", "1.25 mm"]
spacing = "0.25 mm"
velocity = ["20 m/s", "-30 m/s", "-200 m/s"]
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
[stop]
max_steps = 20
)toml";

const std::string element_bar = R"toml(
name = "element bar"
geometry = "axisymmetric"
[[body]]
name = "bar"
shape = "cylinder"
material = "OFHC copper"
radius = "1 mm"
length = "3 mm"
spacing = "0.5 mm"
velocity = [0, "-200 m/s"]
discretisation = "elements"
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
[stop]
max_steps = 20
)toml";

std::string with_output(const std::string& scene, const std::string& output) { return scene + "[output]\n" + output + "\n"; }

std::string scene_error(const std::string& text) {
    try {
        parse_scene(text, "s.toml");
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SceneError for " << text;
    return {};
}

Snapshot run_briefly(const std::string& text) {
    Simulation sim(parse_scene(text, "s.toml"), 1);
    while (!sim.finished()) sim.step();
    return take_snapshot(sim);
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

fs::path scratch(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("gpa_snapshot_fields_{}", name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

TEST(SnapshotFieldsScene, FieldsAndPrecisionAreRead) {
    const Scene plain = parse_scene(bar_2d, "s.toml");
    EXPECT_EQ(plain.output.snapshot_format.fields, default_snapshot_fields());
    EXPECT_EQ(plain.output.snapshot_format.precision, SnapshotPrecision::Float64);
    const Scene chosen = parse_scene(with_output(bar_2d, "fields = [\"stress\", \"velocity\", \"failed\"]\nprecision = \"float32\""), "s.toml");
    EXPECT_EQ(chosen.output.snapshot_format.fields,
              (std::vector<SnapshotField>{SnapshotField::Stress, SnapshotField::Velocity, SnapshotField::Failed}));
    EXPECT_EQ(chosen.output.snapshot_format.precision, SnapshotPrecision::Float32);
    EXPECT_EQ(parse_scene(with_output(bar_2d, "fields = [\"all\"]"), "s.toml").output.snapshot_format.fields, all_snapshot_fields());
    EXPECT_TRUE(parse_scene(with_output(bar_2d, "fields = []"), "s.toml").output.snapshot_format.fields.empty());
    // The default leaves out the initial position (position less displacement) and the plastic work.
    const auto d = default_snapshot_fields();
    EXPECT_EQ(std::count(d.begin(), d.end(), SnapshotField::InitialPosition), 0);
    EXPECT_EQ(std::count(d.begin(), d.end(), SnapshotField::PlasticWork), 0);
    EXPECT_EQ(d.size() + 2, all_snapshot_fields().size());
    for (const SnapshotField f : all_snapshot_fields()) {
        SnapshotField back{};
        ASSERT_TRUE(snapshot_field_of(name_of(f), back)) << name_of(f);
        EXPECT_EQ(back, f);
    }
}

TEST(SnapshotFieldsScene, BadFieldsAndPrecisionsNameTheKeyAndWhatIsAllowed) {
    const std::string unknown = scene_error(with_output(bar_2d, "fields = [\"velocity\", \"stresss\"]"));
    EXPECT_NE(unknown.find("output.fields"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("\"stresss\" is not a snapshot field"), std::string::npos) << unknown;
    EXPECT_NE(unknown.find("\"von_mises_stress\""), std::string::npos) << unknown;  // the list of fields
    const std::string twice = scene_error(with_output(bar_2d, "fields = [\"velocity\", \"pressure\", \"velocity\"]"));
    EXPECT_NE(twice.find("\"velocity\" is named twice"), std::string::npos) << twice;
    const std::string all_and_one = scene_error(with_output(bar_2d, "fields = [\"all\", \"damage\"]"));
    EXPECT_NE(all_and_one.find("\"damage\" is named twice"), std::string::npos) << all_and_one;
    const std::string not_list = scene_error(with_output(bar_2d, "fields = \"velocity\""));
    EXPECT_NE(not_list.find("expected a list of field names"), std::string::npos) << not_list;
    const std::string number = scene_error(with_output(bar_2d, "fields = [3]"));
    EXPECT_NE(number.find("is not a snapshot field"), std::string::npos) << number;
    const std::string precision = scene_error(with_output(bar_2d, "precision = \"half\""));
    EXPECT_NE(precision.find("output.precision"), std::string::npos) << precision;
    EXPECT_NE(precision.find("float32"), std::string::npos) << precision;
    // A library caller gets the same check from validate_scene().
    Scene scene = parse_scene(bar_2d, "s.toml");
    scene.output.snapshot_format.fields = {SnapshotField::Mass, SnapshotField::Mass};
    try {
        validate_scene(scene);
        ADD_FAILURE() << "a field named twice was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'mass' twice"), std::string::npos) << e.what();
    }
}

TEST(SnapshotFiles, HoldTheChosenFieldsInTheirOrderWithIntegerFlagsAndIndices) {
    const Snapshot snapshot = run_briefly(bar_2d);
    const fs::path dir = scratch("chosen");
    SnapshotSeries series(dir, "particles",
                          {{SnapshotField::Material, SnapshotField::Stress, SnapshotField::Failed, SnapshotField::Body}, SnapshotPrecision::Float64});
    const auto names = series.write(snapshot);
    ASSERT_EQ(names.size(), 1u);
    const VtkFile file(dir / names[0]);
    std::vector<std::string> arrays;
    for (const auto& a : file.arrays()) arrays.push_back(a.name);
    EXPECT_EQ(arrays, (std::vector<std::string>{"material", "stress", "failed", "body", "id"}));
    const std::string text = read_text(dir / names[0]);
    EXPECT_NE(text.find("type=\"Int32\" Name=\"material\""), std::string::npos);
    EXPECT_NE(text.find("type=\"UInt8\" Name=\"failed\""), std::string::npos);
    EXPECT_NE(text.find("type=\"Int32\" Name=\"body\""), std::string::npos);
    EXPECT_NE(text.find("type=\"Float64\" Name=\"stress\" NumberOfComponents=\"6\""), std::string::npos);
    // Positions and ids alone.
    SnapshotSeries bare(scratch("bare"), "particles", {{}, SnapshotPrecision::Float64});
    const VtkFile minimal(fs::temp_directory_path() / "gpa_snapshot_fields_bare" / bare.write(snapshot).at(0));
    ASSERT_EQ(minimal.arrays().size(), 1u);
    EXPECT_EQ(minimal.arrays()[0].name, "id");
    EXPECT_EQ(minimal.points().size(), 3 * snapshot.particles.size());
    // Float32 saves 4 bytes on each float of the file: 36 a node with every field (five vectors, the
    // six-component stress, twelve scalars and the position), and nothing on the integer arrays; the
    // headers differ only in the offsets' digits (under 100 bytes here).
    SnapshotSeries wide(scratch("wide"), "particles", {all_snapshot_fields(), SnapshotPrecision::Float64});
    SnapshotSeries narrow(scratch("narrow"), "particles", {all_snapshot_fields(), SnapshotPrecision::Float32});
    const auto wide_bytes = fs::file_size(fs::temp_directory_path() / "gpa_snapshot_fields_wide" / wide.write(snapshot).at(0));
    const auto narrow_bytes = fs::file_size(fs::temp_directory_path() / "gpa_snapshot_fields_narrow" / narrow.write(snapshot).at(0));
    EXPECT_NEAR(double(wide_bytes - narrow_bytes), 4.0 * 36.0 * double(snapshot.particles.size()), 100.0)
        << narrow_bytes << " against " << wide_bytes;
    for (const char* d : {"chosen", "bare", "wide", "narrow"}) fs::remove_all(fs::temp_directory_path() / fmt::format("gpa_snapshot_fields_{}", d));
}

// --- every field, with the values it must hold ---------------------------------------------------

// One array as the files must hold it: where, its VTK type, components and values (tuple-major).
struct Expected {
    std::string location;  // "point" or "cell"
    std::string name;      // "" for the Points array
    std::string type;
    int components = 1;
    std::vector<double> values;
};

// The arrays a particle snapshot with every field holds, written out from the node store with the
// format's rules (docs/outputs.md): 2D vectors as (x, z, 0); the Cauchy stress s - P I as XX, YY,
// ZZ, XY, YZ, XZ with X = x, Y = z (2D) and Z out of plane; damage at most 1.
std::vector<Expected> expected_particles(const NodeStore& n, bool float32) {
    const std::string f = float32 ? "Float32" : "Float64";
    const std::size_t count = n.size();
    const int dim = n.dim();
    std::vector<Expected> out;
    const auto vec = [&](const std::string& name, auto&& value) {
        Expected e{"point", name, f, 3, {}};
        for (std::size_t i = 0; i < count; ++i) {
            for (int c = 0; c < 3; ++c) e.values.push_back(c < dim ? value(c, i) : 0.0);
        }
        out.push_back(e);
    };
    const auto one = [&](const std::string& name, const std::string& type, auto&& value) {
        Expected e{"point", name, type, 1, {}};
        for (std::size_t i = 0; i < count; ++i) e.values.push_back(value(i));
        out.push_back(e);
    };
    const auto s = [&](int c, std::size_t i) { return n.deviatoric_stress[c][i]; };
    vec("velocity", [&](int c, std::size_t i) { return n.velocity[c][i]; });
    vec("force", [&](int c, std::size_t i) { return n.force[c][i]; });
    vec("alpha", [&](int c, std::size_t i) { return n.alpha[c][i]; });
    one("pressure", f, [&](std::size_t i) { return n.pressure[i]; });
    one("viscous_pressure", f, [&](std::size_t i) { return n.viscous_pressure[i]; });
    one("von_mises_stress", f, [&](std::size_t i) {
        const double ss = dim == 2 ? s(0, i) * s(0, i) + s(1, i) * s(1, i) + s(3, i) * s(3, i) + 2 * s(2, i) * s(2, i)
                                   : s(0, i) * s(0, i) + s(1, i) * s(1, i) + s(2, i) * s(2, i) +
                                         2 * (s(3, i) * s(3, i) + s(4, i) * s(4, i) + s(5, i) * s(5, i));
        return std::sqrt(1.5 * ss);
    });
    Expected stress{"point", "stress", f, 6, {}};
    for (std::size_t i = 0; i < count; ++i) {
        const double p = n.pressure[i];
        if (dim == 2) {
            stress.values.insert(stress.values.end(), {s(0, i) - p, s(1, i) - p, s(3, i) - p, s(2, i), 0.0, 0.0});
        } else {
            stress.values.insert(stress.values.end(), {s(0, i) - p, s(1, i) - p, s(2, i) - p, s(5, i), s(3, i), s(4, i)});
        }
    }
    out.push_back(stress);
    one("plastic_strain", f, [&](std::size_t i) { return n.plastic_strain[i]; });
    one("plastic_work", f, [&](std::size_t i) { return n.plastic_work[i]; });
    one("temperature", f, [&](std::size_t i) { return n.temperature[i]; });
    one("damage", f, [&](std::size_t i) { return std::min(n.damage[i], 1.0); });
    one("failed", "UInt8", [&](std::size_t i) { return n.failed[i] ? 1.0 : 0.0; });
    one("volumetric_strain", f, [&](std::size_t i) { return n.volumetric_strain[i]; });
    one("density", f, [&](std::size_t i) { return n.mass[i] / n.volume[i]; });
    one("internal_energy", f, [&](std::size_t i) { return n.internal_energy[i]; });
    vec("displacement", [&](int c, std::size_t i) { return n.position[c][i] - n.initial_position[c][i]; });
    vec("initial_position", [&](int c, std::size_t i) { return n.initial_position[c][i]; });
    one("diameter", f, [&](std::size_t i) { return n.diameter[i]; });
    one("mass", f, [&](std::size_t i) { return n.mass[i]; });
    one("connectivity", "UInt8", [&](std::size_t i) { return n.connectivity[i] == Connectivity::Variable ? 1.0 : 0.0; });
    one("body", "Int32", [&](std::size_t i) { return double(n.body[i]); });
    one("material", "Int32", [&](std::size_t i) { return double(n.material[i]); });
    one("prescribed_velocity", "UInt8", [&](std::size_t i) { return double(n.velocity_region[i]); });
    one("id", "Int64", [&](std::size_t i) { return double(n.id[i]); });
    vec("", [&](int c, std::size_t i) { return n.position[c][i]; });
    return out;
}

// The same for an element body: node fields at the points, material point fields at the triangles.
std::vector<Expected> expected_elements(const ElementMesh& mesh, bool float32) {
    const std::string f = float32 ? "Float32" : "Float64";
    const ElementNodes& n = mesh.nodes;
    const ElementPoints& p = mesh.points;
    std::vector<Expected> out;
    const auto node_vec = [&](const std::string& name, const std::array<std::vector<double>, 2>& v) {
        Expected e{"point", name, f, 3, {}};
        for (std::size_t i = 0; i < n.size(); ++i) e.values.insert(e.values.end(), {v[0][i], v[1][i], 0.0});
        out.push_back(e);
    };
    const auto cell = [&](const std::string& name, const std::string& type, auto&& value) {
        Expected e{"cell", name, type, 1, {}};
        for (std::size_t i = 0; i < p.size(); ++i) e.values.push_back(value(i));
        out.push_back(e);
    };
    const auto s = [&](int c, std::size_t i) { return p.deviatoric_stress[c][i]; };
    node_vec("velocity", n.velocity);
    node_vec("force", n.force);
    out.push_back({"point", "mass", f, 1, n.mass});
    Expected body{"point", "body", "Int32", 1, {}};
    for (const auto b : n.body) body.values.push_back(b);
    out.push_back(body);
    cell("pressure", f, [&](std::size_t i) { return p.pressure[i]; });
    cell("viscous_pressure", f, [&](std::size_t i) { return p.viscous_pressure[i]; });
    cell("von_mises_stress", f, [&](std::size_t i) {
        return std::sqrt(1.5 * (s(0, i) * s(0, i) + s(1, i) * s(1, i) + s(3, i) * s(3, i) + 2 * s(2, i) * s(2, i)));
    });
    Expected stress{"cell", "stress", f, 6, {}};
    for (std::size_t i = 0; i < p.size(); ++i) {
        stress.values.insert(stress.values.end(), {s(0, i) - p.pressure[i], s(1, i) - p.pressure[i], s(3, i) - p.pressure[i], s(2, i), 0.0, 0.0});
    }
    out.push_back(stress);
    cell("plastic_strain", f, [&](std::size_t i) { return p.plastic_strain[i]; });
    cell("plastic_work", f, [&](std::size_t i) { return p.plastic_work[i]; });
    cell("temperature", f, [&](std::size_t i) { return p.temperature[i]; });
    cell("damage", f, [&](std::size_t i) { return std::min(p.damage[i], 1.0); });
    cell("failed", "UInt8", [&](std::size_t i) { return p.failed[i] ? 1.0 : 0.0; });
    cell("density", f, [&](std::size_t i) { return p.density[i]; });
    cell("internal_energy", f, [&](std::size_t i) { return p.internal_energy[i]; });
    cell("material", "Int32", [&](std::size_t i) { return double(mesh.quads.material[i / 4]); });
    Expected contact{"point", "contact", "UInt8", 1, {}};
    for (const auto c : n.contact) contact.values.push_back(c);
    out.push_back(contact);
    Expected ids{"point", "id", "Int64", 1, {}};
    for (std::size_t i = 0; i < n.size(); ++i) ids.values.push_back(double(i));
    out.push_back(ids);
    cell("element", "Int64", [&](std::size_t i) { return double(i / 4); });
    node_vec("", n.position);
    return out;
}

double as_written(double v, const std::string& type) { return type == "Float32" ? double(static_cast<float>(v)) : v; }

// Checks a file with gpa's own reader against the expected arrays (the values, the names and
// their order); returns the expected arrays as text for the independent reader.
std::string check_and_describe(const fs::path& file, const std::vector<Expected>& expected) {
    const VtkFile vtk(file);
    std::string text = fmt::format("file {}\n", file.filename().string());
    std::size_t named = 0;
    for (const Expected& e : expected) {
        const DataLocation where = e.location == "cell" ? DataLocation::Cell : DataLocation::Point;
        const std::vector<double> got = e.name.empty() ? vtk.points() : vtk.values(e.name, where);
        EXPECT_EQ(got.size(), e.values.size()) << file << " " << e.name;
        for (std::size_t k = 0; k < std::min(got.size(), e.values.size()); ++k) {
            if (got[k] != as_written(e.values[k], e.type)) {
                ADD_FAILURE() << file << " " << e.name << " value " << k << ": " << got[k] << " against " << e.values[k];
                break;
            }
        }
        if (!e.name.empty()) ++named;
        text += fmt::format("array {} {} {} {} {}\n", e.location, e.name.empty() ? "-" : e.name, e.type, e.components,
                            e.values.size() / static_cast<std::size_t>(e.components));
        for (const double v : e.values) text += fmt::format("{:.17g}\n", v);
    }
    EXPECT_EQ(vtk.arrays().size(), named) << file << ": arrays besides those expected";
    return text;
}

TEST(SnapshotFiles, EveryFieldHoldsItsNodeValuesInBothPrecisions) {
    const char* env = std::getenv("GPA_VTK_ROUND_TRIP_DIR");
    const fs::path dir = env && *env ? fs::path(env) : scratch("round_trip");
    fs::create_directories(dir);
    std::string description;
    Snapshot flat = run_briefly(bar_2d);
    Snapshot solid = run_briefly(bar_3d);
    Snapshot elements = run_briefly(element_bar);
    // Make every value of the flags and the clamp occur: a failed node with damage past 1, a
    // fixed one, and a second body index.
    for (Snapshot* s : {&flat, &solid}) {
        NodeStore& n = s->particles;
        ASSERT_GT(n.size(), 3u);
        n.damage[1] = 1.4;
        n.failed[1] = 1;
        n.connectivity[2] = Connectivity::Fixed;
        n.body[3] = 1;
        n.material[3] = 2;
        n.velocity_region[3] = 1;
        EXPECT_GT(*std::max_element(n.plastic_strain.begin(), n.plastic_strain.end()), 0.0);
    }
    // Every stress component distinct and non-zero at node 0, so that two swapped components
    // cannot pass (the stored order is not the written one).
    for (Snapshot* snap : {&flat, &solid}) {
        NodeStore& n = snap->particles;
        for (int c = 0; c < stress_components(n.dim()); ++c) n.deviatoric_stress[c][0] = (c + 1) * 1.25e6;
        n.pressure[0] = 0.5e6;
    }
    ASSERT_TRUE(elements.elements.has_value());
    // A failed element cell with damage past 1, and distinct stress components there too.
    elements.elements->points.failed[5] = 1;
    elements.elements->points.damage[5] = 1.3;
    for (int c = 0; c < 4; ++c) elements.elements->points.deviatoric_stress[c][0] = (c + 1) * 1.25e6;
    EXPECT_GT(*std::max_element(elements.elements->points.plastic_strain.begin(), elements.elements->points.plastic_strain.end()), 0.0);
    for (const bool float32 : {false, true}) {
        const std::string width = float32 ? "float32" : "float64";
        const SnapshotFormat format{all_snapshot_fields(), float32 ? SnapshotPrecision::Float32 : SnapshotPrecision::Float64};
        const fs::path p2 = dir / fmt::format("particles_2d_{}.vtp", width), p3 = dir / fmt::format("particles_3d_{}.vtp", width);
        const fs::path e2 = dir / fmt::format("elements_2d_{}.vtu", width);
        write_vtp(p2, flat.particles, flat.particles.size(), format);
        write_vtp(p3, solid.particles, solid.particles.size(), format);
        write_vtu(e2, *elements.elements, format);
        description += check_and_describe(p2, expected_particles(flat.particles, float32));
        description += check_and_describe(p3, expected_particles(solid.particles, float32));
        description += check_and_describe(e2, expected_elements(*elements.elements, float32));
    }
    std::ofstream(dir / "expected.txt") << description;
    if (!(env && *env)) fs::remove_all(dir);
}

}  // namespace
}  // namespace gpa::io
