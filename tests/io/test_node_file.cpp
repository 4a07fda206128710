// Node files (io/node_file.hpp; shape "nodes"): a body's nodes written out as a CSV table and as a
// gpa snapshot come back as the same nodes, to the bit (CSV) and to round-off (a snapshot's mass
// over density), in 2D axisymmetric and in 3D; malformed tables are refused naming the file, the
// line and the column; the scene reader takes the file beside the scene and refuses the keys of
// lattices; a resumed run refuses a node file that changed.

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/node_file.hpp"
#include "gpa/io/run_loop.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/vtk.hpp"
#include "support/scenes.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

fs::path node_scratch_folder() {
    const fs::path p = fs::temp_directory_path() / "gpa_test_node_file";
    fs::create_directories(p);
    return p;
}

// Body 0's nodes of a freshly set-up run, as a CSV table in millimetres: x, (y,) z and the
// node's volume (3D) or cross-section (2D, the ring's volume over 2 pi x in axisymmetric
// geometry), every number to 17 digits; with an id column first, which the reader ignores.
std::string csv_of(const Simulation& sim) {
    const NodeStore& n = sim.nodes();
    const int dim = n.dim();
    std::string out = dim == 3 ? "id, x, y, z, volume\n" : "# a comment line\nid,\"X\",Z,Area\n";
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (n.body[i] != 0) continue;
        out += fmt::format("{}", n.id[i]);
        for (int c = 0; c < dim; ++c) out += fmt::format(",{:.17g}", n.initial_position[c][i] * 1e3);
        const double v = n.initial_volume[i];
        const double size = n.geometry() == GeometryKind::Axisymmetric ? v / (2.0 * std::numbers::pi * n.initial_position[0][i]) : v;
        out += fmt::format(",{:.17g}\n", size * (dim == 3 ? 1e9 : 1e6));
    }
    return out;
}

// Positions and sizes, in metres, the way csv_of wrote them.
void expect_same_nodes(const Simulation& sim, const NodeSet& set, double relative) {
    const NodeStore& n = sim.nodes();
    const int dim = n.dim();
    std::size_t k = 0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (n.body[i] != 0) continue;
        ASSERT_LT(k, set.positions.size());
        for (int c = 0; c < dim; ++c) {
            EXPECT_NEAR(set.positions[k][c], n.initial_position[c][i], 1e-15 * std::abs(n.initial_position[c][i])) << k;
        }
        const double v = n.initial_volume[i];
        const double size = n.geometry() == GeometryKind::Axisymmetric ? v / (2.0 * std::numbers::pi * n.initial_position[0][i]) : v;
        EXPECT_NEAR(set.sizes[k], size, relative * size) << k;
        ++k;
    }
    EXPECT_EQ(k, set.positions.size());
}

TEST(NodeFile, ABodysNodesWrittenAsCsvComeBackTheSame) {
    for (const GeometryKind g : {GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        const Scene scene = g == GeometryKind::ThreeD ? testing::pulled_elastic_bar(g, 2e-3, 6e-3, 3, 0.0, 0.0, 0.3)
                                                      : testing::armco_cylinder(6, 1e-6);
        const Simulation sim(scene, 1);
        const NodeSet set = parse_node_csv(csv_of(sim), "nodes.csv", 1e-3, g);
        // 17 digits of a number in millimetres, read back and scaled: within an ulp or two.
        expect_same_nodes(sim, set, 4e-16);
        EXPECT_EQ(set.origins.at(0), g == GeometryKind::ThreeD ? "line 2" : "line 3");
    }
}

TEST(NodeFile, ABodysNodesInAGpaSnapshotComeBackTheSame) {
    for (const GeometryKind g : {GeometryKind::Axisymmetric, GeometryKind::PlaneStrain, GeometryKind::ThreeD}) {
        const Scene scene = g == GeometryKind::ThreeD ? testing::pulled_elastic_bar(g, 2e-3, 6e-3, 3, 0.0, 0.0, 0.3)
                            : g == GeometryKind::PlaneStrain ? testing::pulled_elastic_bar(g, 2e-3, 6e-3, 4, 0.0, 0.0, 0.3)
                                                             : testing::armco_cylinder(6, 1e-6);
        const Simulation sim(scene, 1);
        const fs::path file = node_scratch_folder() / "snapshot.vtp";
        write_vtp(file, sim.nodes(), sim.real_count(),
                  SnapshotFormat{{SnapshotField::Mass, SnapshotField::Density}, SnapshotPrecision::Float64});
        const NodeSet set = read_node_file(file, 1.0, g);
        // volume = mass / (mass / volume): two roundings, and a third for the ring's 2 pi x.
        expect_same_nodes(sim, set, 1e-15);
        EXPECT_EQ(set.origins.at(3), "point 3");
    }
}

std::string csv_refusal(const std::string& text, GeometryKind g = GeometryKind::ThreeD) {
    try {
        (void)parse_node_csv(text, "part.csv", 1e-3, g);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

TEST(NodeFile, MalformedTablesAreRefusedNamingTheLineAndTheColumn) {
    const std::string header = "x,y,z,volume\n";
    EXPECT_EQ(csv_refusal(header + "0,0,0,1\n1,0,0,1\n"), "");
    EXPECT_EQ(csv_refusal("\xEF\xBB\xBF" + header + "\r\n0, 0, 0, 1\r\n+1,0,0,1e0\r\n"), "");
    EXPECT_NE(csv_refusal("x,y,volume\n0,0,1\n").find("part.csv:1: the header names no column \"z\""), std::string::npos)
        << csv_refusal("x,y,volume\n0,0,1\n");
    EXPECT_NE(csv_refusal("x,z,area\n0,0,1\n").find("a 3D scene's nodes need the columns x, y, z, volume"), std::string::npos);
    EXPECT_NE(csv_refusal("x,y,z,volume\n0,0,1\n", GeometryKind::PlaneStrain).find("no column \"area\""), std::string::npos);
    EXPECT_NE(csv_refusal("x,y,z,x,volume\n").find("names column \"x\" twice"), std::string::npos);
    EXPECT_NE(csv_refusal(header + "0,0,0,1\n\n1,0,zero,1\n").find("part.csv:4: column \"z\": \"zero\" is not a number"),
              std::string::npos)
        << csv_refusal(header + "0,0,0,1\n\n1,0,zero,1\n");
    EXPECT_NE(csv_refusal(header + "0,0,0,1,7\n").find("part.csv:2: 5 fields, but the header has 4 columns"), std::string::npos);
    EXPECT_NE(csv_refusal(header + "0,0,0,\n").find("column \"volume\": \"\" is not a number"), std::string::npos);
    EXPECT_NE(csv_refusal(header + "0,0,0,1\n0,0,0,1\n").find("line 2 and line 3 are 0 m apart"), std::string::npos)
        << csv_refusal(header + "0,0,0,1\n0,0,0,1\n");
    EXPECT_NE(csv_refusal(header + "0,0,0,-1\n").find("line 2: its volume is -1e-09"), std::string::npos)
        << csv_refusal(header + "0,0,0,-1\n");
    EXPECT_NE(csv_refusal(header + "0,0,nan,1\n").find("line 2: its z is not a finite number"), std::string::npos);
    EXPECT_NE(csv_refusal("x,z,area\n0,1,1\n", GeometryKind::Axisymmetric).find("line 2: at x = 0 m"), std::string::npos);
    EXPECT_NE(csv_refusal(header).find("holds no node"), std::string::npos);
    // The file's bytes quoted in a message are made printable: it stays one line (found by the fuzz
    // target: a header name with carriage returns inside).
    const std::string quoted = csv_refusal("x,y\r\r1,z,volume\n") + csv_refusal(header + "0,0,0,1\r\r2\n");
    EXPECT_EQ(quoted.find('\r'), std::string::npos) << quoted;
    EXPECT_NE(quoted.find("names x, y\\r\\r1, z, volume"), std::string::npos) << quoted;
    EXPECT_NE(quoted.find("\"1\\r\\r2\" is not a number"), std::string::npos) << quoted;
    EXPECT_NE(csv_refusal("# only a comment\n").find("holds no header line"), std::string::npos);
    constexpr char with_zero[] = "x,y,z,volume\n0,0\0,0,1\n";  // a zero byte inside: the array's size less its terminator
    EXPECT_NE(csv_refusal(std::string(with_zero, sizeof with_zero - 1)).find("part.csv:2: holds a zero byte"), std::string::npos);
    try {
        (void)read_node_file(node_scratch_folder() / "nodes.txt", 1e-3, GeometryKind::ThreeD);
        ADD_FAILURE() << "a .txt node file was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("a CSV table (.csv) or a VTK XML point file (.vtp, .vtu)"), std::string::npos) << e.what();
    }
    // A VTK file without sizes.
    const Simulation sim(testing::armco_cylinder(4, 1e-6), 1);
    const fs::path vtp = node_scratch_folder() / "velocity_only.vtp";
    write_vtp(vtp, sim.nodes(), sim.real_count(), SnapshotFormat{{SnapshotField::Velocity}, SnapshotPrecision::Float64});
    try {
        (void)read_node_file(vtp, 1.0, GeometryKind::Axisymmetric);
        ADD_FAILURE() << "a VTK file without sizes was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("no point array \"area\""), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("\"velocity\""), std::string::npos) << e.what();
    }
}

std::string nodes_scene(const std::string& keys) {
    return fmt::format(R"(
name = "imported nodes on a plate"
geometry = "3d"
[[body]]
name = "plate"
shape = "box"
material = "OFHC copper"
origin = [0, 0, 0]
size = ["4 mm", "4 mm", "2 mm"]
spacing = "0.5 mm"
[[body]]
name = "part"
material = "OFHC copper"
velocity = [0, 0, "-100 m/s"]
{}
[stop]
max_steps = 6
)", keys);
}

// A 4 x 4 x 4 block of 0.5 mm nodes, in millimetres, its lowest nodes 0.25 mm above z = 0.
std::string block_csv() {
    std::string out = "x,y,z,volume\n";
    for (int k = 0; k < 4; ++k) {
        for (int j = 0; j < 4; ++j) {
            for (int i = 0; i < 4; ++i) out += fmt::format("{},{},{},0.125\n", 0.25 + 0.5 * i, 0.25 + 0.5 * j, 0.25 + 0.5 * k);
        }
    }
    return out;
}

TEST(NodeFile, TheSceneReaderTakesTheFileBesideTheSceneAndRefusesTheKeysOfLattices) {
    const fs::path folder = node_scratch_folder() / "scene";
    fs::create_directories(folder / "parts");
    std::ofstream(folder / "parts" / "block.csv") << block_csv();
    const fs::path file = folder / "scene.toml";
    std::ofstream(file) << nodes_scene("shape = \"nodes\"\nfile = \"parts/block.csv\"\nunit = \"mm\"\norigin = [0, 0, \"2 mm\"]");
    const Scene scene = load_scene(file);
    ASSERT_TRUE(scene.bodies[1].node_set);
    EXPECT_EQ(scene.bodies[1].node_set->size(), 64u);
    EXPECT_DOUBLE_EQ(nominal_spacing(scene.bodies[1]), 0.5e-3);
    Simulation sim(scene, 2);
    while (!sim.finished()) sim.step();
    // The block strikes the plate it touches: the plate's nodes move down, momentum and energy are
    // kept to round-off.
    double plate_momentum = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (sim.nodes().body[i] == 0) plate_momentum += sim.nodes().mass[i] * sim.nodes().velocity[2][i];
    }
    const double initial = -64 * 8960.0 * 0.125e-9 * 100.0;
    EXPECT_LT(plate_momentum, 1e-3 * initial);
    EXPECT_NEAR(sim.totals().momentum[2], initial, 1e-12 * std::abs(initial));
    EXPECT_LT(std::abs(sim.totals().energy_error), 1e-9);

    const auto expect = [&](const std::string& keys, const std::string& words) {
        const std::string message = testing::scene_file_refusal(nodes_scene(keys), file);
        EXPECT_NE(message.find(words), std::string::npos) << keys << "\n -> " << message;
    };
    const std::string ok = "shape = \"nodes\"\nfile = \"parts/block.csv\"\nunit = \"mm\"\n";
    expect(ok + "origin = [0, 0, \"1 mm\"]", "overlaps");
    expect(ok + "origin = [0, 0, \"2 mm\"]\nspacing = \"0.5 mm\"", "does not apply to imported nodes");
    expect(ok + "origin = [0, 0, \"2 mm\"]\nlattice_neighbours = 26", "does not apply to imported nodes");
    expect(ok + "origin = [0, 0, \"2 mm\"]\nradius = \"1 mm\"", "does not apply to imported nodes");
    expect(ok + "origin = [0, 0, \"2 mm\"]\nconnectivity = \"fixed\"", "variable connectivity only");
    expect("shape = \"nodes\"\nfile = \"parts/none.csv\"\nunit = \"mm\"", "body[1] \"part\".file: ");
    expect("shape = \"nodes\"\nfile = \"parts/none.csv\"\nunit = \"mm\"", "none.csv: no such node file");
    expect("shape = \"nodes\"\nunit = \"mm\"", "the CSV or VTK file of the nodes");
    expect("shape = \"nodes\"\nfile = \"parts/block.csv\"", "unit");
}

TEST(NodeFile, AFileWhoseNodesWouldNotFitTheMemoryLimitIsRefusedBeforeTheyAreRead) {
    const fs::path folder = node_scratch_folder() / "memory";
    fs::create_directories(folder);
    std::ofstream(folder / "block.csv") << block_csv();
    std::ofstream(folder / "scene.toml") << nodes_scene("shape = \"nodes\"\nfile = \"block.csv\"\nunit = \"mm\"\norigin = [0, 0, \"2 mm\"]");
    // 65 lines: at most 65 nodes, each some 300 B to read and 1.7 kB to run (limits.hpp).
    const double per_node = bytes_to_import_node + bytes_per_node_besides_lists(3) + list_entries_per_node(3) * bytes_per_list_entry;
    const auto limit = [](double bytes) { return MemoryLimit{static_cast<std::uint64_t>(bytes), "--max-memory (the test)"}; };
    const double bytes = static_cast<double>(fs::file_size(folder / "block.csv"));
    try {
        (void)load_scene(folder / "scene.toml", nullptr, limit(bytes + 60 * per_node));
        ADD_FAILURE() << "a node file beyond the memory limit was read";
    } catch (const LimitError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("body[1] \"part\".file: "), std::string::npos) << m;
        EXPECT_NE(m.find("block.csv: its 65 lines (a node each, at most) need an estimated"), std::string::npos) << m;
        EXPECT_NE(m.find("--max-memory (the test)"), std::string::npos) << m;
    }
    EXPECT_NO_THROW((void)load_scene(folder / "scene.toml", nullptr, limit(bytes + 66 * per_node)));
}

TEST(NodeFile, AResumedRunRefusesANodeFileThatChangedSinceItStarted) {
    const fs::path folder = node_scratch_folder() / "resume";
    fs::remove_all(folder);
    fs::create_directories(folder);
    std::ofstream(folder / "block.csv") << block_csv();
    std::ofstream(folder / "scene.toml") << nodes_scene("shape = \"nodes\"\nfile = \"block.csv\"\nunit = \"mm\"\norigin = [0, 0, \"2 mm\"]");
    const fs::path output = folder / "run";
    {
        RunSettings settings;
        settings.output = output;
        settings.threads = 1;
        RunLoop run(SceneSource::from_file(folder / "scene.toml"), settings);
        RunHooks hooks;
        hooks.stop_requested = [&] { return run.simulation().steps() == 2 ? StopRequest{1, "the test"} : StopRequest{}; };
        ASSERT_EQ(run.run(hooks).status, RunStatus::Interrupted);
    }
    std::string moved = block_csv();
    moved.replace(moved.find("0.125"), 5, "0.126");  // one node's volume
    std::ofstream(folder / "block.csv") << moved;
    EXPECT_THROW((void)RunLoop::resume(output, std::nullopt, RunSettings{}), CheckpointError);
    std::ofstream(folder / "block.csv") << block_csv();
    EXPECT_EQ(RunLoop::resume(output, std::nullopt, RunSettings{})->run().status, RunStatus::Finished);
    fs::remove_all(folder);
}

}  // namespace
}  // namespace gpa::io
