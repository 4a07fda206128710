// What a run leaves on disk when things go wrong: one run per folder (the lock), whole lines and
// no temporary files when the disk fills (simulated with a file-size limit, RLIMIT_FSIZE: writes
// past it fail with EFBIG as on a full disk), marked snapshots in the .pvd; and the scene reader's
// guards (a size limit however the file is opened, non-ASCII text only where TOML allows it).

#include <algorithm>
#include <cmath>
#include <numeric>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/folder_lock.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/snapshot_reader.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / fmt::format("gpa_run_outputs_{}_{}", ::getpid(), name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string read_all(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

bool has_tmp_files(const fs::path& dir) {
    for (const auto& e : fs::recursive_directory_iterator(dir)) {
        if (e.path().extension() == ".tmp") return true;
    }
    return false;
}

// Files of this process may grow to `bytes` only while it lives (SIGXFSZ ignored, so that the
// write fails with EFBIG instead of ending the process).
class FileSizeLimit {
public:
    explicit FileSizeLimit(rlim_t bytes) {
        previous_signal_ = std::signal(SIGXFSZ, SIG_IGN);
        ::getrlimit(RLIMIT_FSIZE, &previous_);
        rlimit limit = previous_;
        limit.rlim_cur = bytes;
        ::setrlimit(RLIMIT_FSIZE, &limit);
    }
    ~FileSizeLimit() {
        ::setrlimit(RLIMIT_FSIZE, &previous_);
        std::signal(SIGXFSZ, previous_signal_);
    }

private:
    rlimit previous_{};
    void (*previous_signal_)(int) = nullptr;
};

const char* tiny_scene = R"(
name = "tiny"
geometry = "axisymmetric"
[[material]]
name = "elastic steel"
density = "7800 kg/m^3"
shear_modulus = "80 GPa"
eos = { model = "linear", bulk_modulus = "160 GPa" }
strength = "elastic"
[[body]]
name = "bar"
shape = "cylinder"
material = "elastic steel"
radius = "1 mm"
length = "4 mm"
spacing = "0.25 mm"
velocity = [0, "-50 m/s"]
[[plane]]
name = "anvil"
kind = "rigid"
axis = "z"
position = 0
[stop]
max_steps = 20
)";

TEST(FolderLock, ASecondRunOnTheSameFolderIsRefusedAtOnce) {
    const fs::path dir = scratch("lock");
    const fs::path folder = dir / "run";
    {
        FolderLock first(folder);
        EXPECT_EQ(first.file(), dir / "run.lock");
        EXPECT_EQ(read_all(first.file()), fmt::format("{}\n", ::getpid()));
        try {
            FolderLock second(folder / "");  // "run/" is the same folder
            ADD_FAILURE() << "two locks on one folder";
        } catch (const OutputError& e) {
            const std::string m = e.what();
            EXPECT_NE(m.find("in use by another gpa run"), std::string::npos) << m;
            EXPECT_NE(m.find(fmt::format("process {}", ::getpid())), std::string::npos) << m;
            EXPECT_NE(m.find("run.lock"), std::string::npos) << m;
        }
        // A RunFolder takes the same lock before it touches anything.
        fs::create_directories(dir / "run.partial");
        std::ofstream(dir / "run.partial" / "history.csv") << "the first run's rows\n";
        EXPECT_THROW(RunFolder(folder, false), OutputError);
        EXPECT_EQ(read_all(dir / "run.partial" / "history.csv"), "the first run's rows\n");
    }
    EXPECT_FALSE(fs::exists(dir / "run.lock")) << "the lock file goes with its run";
    // A lock file left by a run that died (kill -9) holds no lock: the next run takes it over.
    std::ofstream(dir / "run.lock") << "999999999\n";
    EXPECT_NO_THROW(FolderLock again(folder));
    fs::remove_all(dir);
}

// history.csv's columns belong to the scene (issue 24, item 4): the specimen's length and
// footprint only where a rigid plane measures them, extensive quantities per metre of thickness in
// plane strain, the energy error in per cent as the console prints it, a unit on every column of a
// dimensional quantity.
TEST(Summary, PlaneStrainKeysOfExtensiveQuantitiesArePerMetre) {
    std::string slab = tiny_scene;
    slab.replace(slab.find("axisymmetric"), 12, "plane-strain");
    const fs::path dir = scratch("summary_per_metre");
    for (const bool plane_strain : {false, true}) {
        Simulation sim(parse_scene(plane_strain ? slab : tiny_scene, "s.toml"), 1);
        sim.step();
        sim.measure_bodies();  // the local peaks below
        write_summary(dir / "summary.json", sim, RunSummary{});
        const std::string text = read_all(dir / "summary.json");
        for (const char* key : {"mass_kg", "kinetic_energy_J", "plastic_work_J", "kinetic_J", "reaction_N", "momentum_kg_m_s"}) {
            EXPECT_EQ(text.find(fmt::format("\"{}\":", key)) != std::string::npos, !plane_strain) << key << "\n" << text;
            EXPECT_EQ(text.find(fmt::format("\"{}_per_m\":", key)) != std::string::npos, plane_strain) << key;
        }
        // Intensive quantities keep their units.
        EXPECT_NE(text.find("\"time_s\":"), std::string::npos);
        EXPECT_NE(text.find("\"length_m\":"), std::string::npos);
        // The searches the run made (the set-up's and any since), beside its timings.
        EXPECT_NE(text.find(fmt::format("\"neighbour_searches\": {}", sim.totals().neighbour_searches)), std::string::npos) << text;
        EXPECT_NE(text.find(fmt::format("\"row_searches\": {}", sim.totals().row_searches)), std::string::npos) << text;
        EXPECT_NE(text.find(fmt::format("\"rows_searched\": {}", sim.totals().rows_searched)), std::string::npos) << text;
        EXPECT_GE(sim.totals().neighbour_searches, 1u);
        // The local peaks say over how many points they were taken and how many had no
        // neighbourhood (measure.hpp, LocalPeak::alone): none in a body at rest on its lattice.
        EXPECT_NE(text.find(fmt::format("\"points\": {}, \"points_alone\": 0", sim.real_count())), std::string::npos)
            << text;
    }
    fs::remove_all(dir);
}

TEST(HistoryColumns, BelongToTheSceneAndCarryTheirUnits) {
    const auto header_and_row = [](const std::string& text) {
        const Scene scene = parse_scene(text, "columns.toml");
        Simulation sim(scene, 1);
        for (int k = 0; k < 5; ++k) sim.step();
        const fs::path dir = scratch("columns");
        {
            HistoryWriter history(dir / "history.csv", sim.totals(), HistoryLayout::of(scene));
            history.write(sim.totals());
        }
        std::istringstream in(read_all(dir / "history.csv"));
        std::string header, row;
        std::getline(in, header);
        std::getline(in, row);
        fs::remove_all(dir);
        std::vector<std::string> names, values;
        std::string cell;
        for (std::stringstream h(header); std::getline(h, cell, ',');) names.push_back(cell);
        for (std::stringstream r(row); std::getline(r, cell, ',');) values.push_back(cell);
        return std::make_tuple(names, values, sim.totals().energy_error);
    };
    const auto has = [](const std::vector<std::string>& names, const std::string& name) {
        return std::find(names.begin(), names.end(), name) != names.end();
    };
    // The tiny bar on its anvil: a specimen, axisymmetric (ring totals, no per-metre suffix).
    const auto [names, values, error] = header_and_row(tiny_scene);
    ASSERT_EQ(names.size(), values.size());
    for (const char* column : {"length_m", "footprint_diameter_m", "base_height_m", "face_plastic_strain_roughness",
                               "kinetic_energy_J", "momentum_z_kg_m_s", "anvil_reaction_N", "total_energy_error_percent"}) {
        EXPECT_TRUE(has(names, column)) << column;
    }
    // Clang before 16 cannot capture a structured binding in a lambda (a C++20 rule): pass them in.
    const auto value_of = [](const std::vector<std::string>& header, const std::vector<std::string>& row,
                             const std::string& name) {
        return std::stod(row[static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin())]);
    };
    EXPECT_NE(error, 0.0);
    // Written with 7 significant digits: within half a unit of the last.
    EXPECT_NEAR(value_of(names, values, "total_energy_error_percent"), 100.0 * error, 5e-7 * std::abs(100.0 * error));
    // Without a rigid plane: no specimen columns. In plane strain: per metre of thickness.
    std::string free_slab = tiny_scene;
    free_slab.replace(free_slab.find("axisymmetric"), 12, "plane-strain");
    free_slab.erase(free_slab.find("[[plane]]"), free_slab.find("[stop]") - free_slab.find("[[plane]]"));
    const auto [slab_names, slab_values, slab_error] = header_and_row(free_slab);
    for (const char* column : {"length_m", "footprint_diameter_m", "base_height_m", "face_plastic_strain_roughness"}) {
        EXPECT_FALSE(has(slab_names, column)) << column;
    }
    for (const char* column : {"kinetic_energy_J_per_m", "plastic_work_J_per_m", "momentum_x_kg_m_s_per_m", "hourglass_work_J_per_m"}) {
        EXPECT_TRUE(has(slab_names, column)) << column;
    }
    EXPECT_FALSE(has(slab_names, "kinetic_energy_J"));
    EXPECT_EQ(slab_names.size(), slab_values.size());
    // A plane-strain slab on its anvil: the specimen columns again, the plane's per metre.
    std::string slab_on_anvil = tiny_scene;
    slab_on_anvil.replace(slab_on_anvil.find("axisymmetric"), 12, "plane-strain");
    const auto [anvil_names, anvil_values, anvil_error] = header_and_row(slab_on_anvil);
    for (const char* column : {"length_m", "footprint_diameter_m", "anvil_reaction_N_per_m", "anvil_impulse_N_s_per_m"}) {
        EXPECT_TRUE(has(anvil_names, column)) << column;
    }
    EXPECT_FALSE(has(anvil_names, "anvil_reaction_N"));
}

TEST(DiskFull, HistoryKeepsWholeLines) {
    const fs::path dir = scratch("history");
    const Scene scene = parse_scene(tiny_scene, "tiny.toml");
    Simulation sim(scene, 1);
    const fs::path file = dir / "history.csv";
    std::string message;
    {
        HistoryWriter history(file, sim.totals(), HistoryLayout::of(scene));
        const FileSizeLimit limit(3000);  // the header and a few rows
        try {
            for (int k = 0; k < 100; ++k) history.write(sim.totals());
        } catch (const OutputError& e) {
            message = e.what();
        }
    }
    EXPECT_NE(message.find("history.csv"), std::string::npos) << message;
    const std::string text = read_all(file);
    ASSERT_FALSE(text.empty());
    EXPECT_LE(text.size(), 3000u);
    EXPECT_EQ(text.back(), '\n') << "the file ends with a whole line";
    // Every line has the header's number of columns.
    std::istringstream lines(text);
    std::string header, line;
    std::getline(lines, header);
    const auto columns = std::count(header.begin(), header.end(), ',');
    int rows = 0;
    while (std::getline(lines, line)) {
        EXPECT_EQ(std::count(line.begin(), line.end(), ','), columns) << line;
        ++rows;
    }
    EXPECT_GT(rows, 0);
    fs::remove_all(dir);
}

TEST(DiskFull, AFileWrittenAtomicallyIsTheOldOneOrTheNewOneAndLeavesNoTemporaryFile) {
    const fs::path dir = scratch("atomic");
    const fs::path file = dir / "summary.json";
    write_text_file(file, "old\n");
    {
        const FileSizeLimit limit(1000);
        EXPECT_THROW(write_text_file(file, std::string(5000, 'x')), OutputError);
    }
    EXPECT_EQ(read_all(file), "old\n");
    EXPECT_FALSE(has_tmp_files(dir));
    // A body that throws leaves no temporary file either.
    EXPECT_THROW(write_file_atomically(file, [](std::ofstream&) { throw OutputError("the body failed"); }), OutputError);
    EXPECT_FALSE(has_tmp_files(dir));
    EXPECT_EQ(read_all(file), "old\n");
    fs::remove_all(dir);
}

TEST(DiskFull, ASnapshotThatDoesNotFitLeavesTheSeriesAsItWas) {
    const fs::path dir = scratch("snapshots");
    const Scene scene = parse_scene(tiny_scene, "tiny.toml");
    Simulation sim(scene, 1);
    SnapshotSeries series(dir);
    series.write(sim.nodes(), sim.real_count(), 0.0);
    const std::string pvd = read_all(dir / "particles.pvd");
    {
        const FileSizeLimit limit(4000);  // a snapshot of 64 nodes is about 14 kB
        EXPECT_THROW(series.write(sim.nodes(), sim.real_count(), 1e-6), OutputError);
    }
    EXPECT_EQ(read_all(dir / "particles.pvd"), pvd);
    EXPECT_FALSE(fs::exists(dir / "particles_00001.vtp"));
    EXPECT_FALSE(has_tmp_files(dir));
    fs::remove_all(dir);
}

TEST(Snapshots, OnesOutsideTheScheduleAreMarkedInThePvd) {
    const fs::path dir = scratch("marked");
    const Scene scene = parse_scene(tiny_scene, "tiny.toml");
    Simulation sim(scene, 1);
    SnapshotSeries series(dir);
    series.write(sim.nodes(), sim.real_count(), 0.0);
    Snapshot snapshot = take_snapshot(sim);
    snapshot.time = 2e-8;
    EXPECT_EQ(series.write_marked(snapshot, "failed_step0000003", "failed step 3"),
              std::vector<std::string>{"particles_failed_step0000003.vtp"});
    series.write(sim.nodes(), sim.real_count(), 3e-8);
    const std::string pvd = read_all(dir / "particles.pvd");
    EXPECT_NE(pvd.find(R"(part="0" file="particles_failed_step0000003.vtp" name="failed step 3")"), std::string::npos) << pvd;
    EXPECT_NE(pvd.find(R"(file="particles_00001.vtp"/>)"), std::string::npos) << "the schedule's numbering goes on: " << pvd;
    EXPECT_EQ(series.scheduled(), 2u);
    EXPECT_EQ(series.count(), 3u);
    fs::remove_all(dir);
}

// Node ids (NodeStore::id, issue 24): a run that reorders its nodes every 5 steps writes, in every
// snapshot, the id of each node; read back by id, every node is there in every snapshot, moves
// between two snapshots no further than the fastest node could (so it is the same material point),
// starts where the lattice put it, and ends where the engine has the node of that id.
TEST(Snapshots, EveryNodeCanBeFollowedByItsIdThroughAReorderingRun) {
    const fs::path dir = scratch("ids");
    std::string text = tiny_scene;
    text.replace(text.find("max_steps = 20"), 14, "max_steps = 60\n[solver]\nreorder_interval = 5");
    const Scene scene = parse_scene(text, "tiny.toml");
    Simulation sim(scene, 2);
    const std::size_t n = sim.real_count();
    std::vector<std::array<double, 2>> start(n);
    for (std::size_t i = 0; i < n; ++i) start[sim.nodes().id[i]] = {sim.nodes().position[0][i], sim.nodes().position[1][i]};
    SnapshotSeries series(dir);
    std::vector<double> times{sim.time()};
    series.write(sim.nodes(), n, sim.time());
    double fastest = 0.0;
    for (int k = 0; k < 6; ++k) {
        for (int s2 = 0; s2 < 10; ++s2) {
            sim.step();
            for (std::size_t i = 0; i < n; ++i) fastest = std::max(fastest, std::hypot(sim.nodes().velocity[0][i], sim.nodes().velocity[1][i]));
        }
        series.write(sim.nodes(), n, sim.time());
        times.push_back(sim.time());
    }
    const SnapshotIndex index = read_pvd(dir / "particles.pvd");
    ASSERT_EQ(index.snapshots.size(), times.size());
    std::vector<std::array<double, 2>> previous;
    bool reordered = false;
    for (std::size_t k = 0; k < index.snapshots.size(); ++k) {
        const VtkFile file(index.snapshots[k].files.at(0));
        const std::vector<double> ids = file.values("id", DataLocation::Point);
        const std::vector<double> points = file.points();
        ASSERT_EQ(ids.size(), n);
        std::vector<std::array<double, 2>> by_id(n, {NAN, NAN});
        for (std::size_t i = 0; i < n; ++i) {
            const auto id = static_cast<std::size_t>(ids[i]);
            ASSERT_LT(id, n);
            ASSERT_TRUE(std::isnan(by_id[id][0])) << "id " << id << " twice in snapshot " << k;
            by_id[id] = {points[3 * i], points[3 * i + 1]};
            reordered |= id != i;
        }
        if (k == 0) {
            for (std::size_t id = 0; id < n; ++id) {
                EXPECT_EQ(by_id[id][0], start[id][0]);
                EXPECT_EQ(by_id[id][1], start[id][1]);
            }
        } else {
            // No node moves further than the fastest speed over the interval (1 % for the leapfrog's
            // half-step velocities).
            const double reach = 1.01 * fastest * (times[k] - times[k - 1]);
            for (std::size_t id = 0; id < n; ++id) {
                ASSERT_LE(std::hypot(by_id[id][0] - previous[id][0], by_id[id][1] - previous[id][1]), reach) << "id " << id;
            }
        }
        previous = by_id;
    }
    EXPECT_TRUE(reordered) << "the run reordered its nodes: the test follows them";
    for (std::size_t i = 0; i < n; ++i) {
        EXPECT_EQ(previous[sim.nodes().id[i]][0], sim.nodes().position[0][i]);
        EXPECT_EQ(previous[sim.nodes().id[i]][1], sim.nodes().position[1][i]);
    }
    fs::remove_all(dir);
}

TEST(SceneText, IsReadWithASizeLimitHoweverTheFileIsOpened) {
    // A device that never ends (and reports no size).
    try {
        read_scene_text("/dev/zero");
        ADD_FAILURE() << "/dev/zero was read";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("too large for a scene file"), std::string::npos) << e.what();
    }
    EXPECT_THROW(load_scene("/dev/zero"), SceneError);
}

TEST(SceneText, NonAsciiTextIsAcceptedWhereTomlAllowsIt) {
    // U+03FB (bytes CF BB) reaches undefined behaviour in toml++ 3.3.0 outside strings; inside
    // strings, comments and quoted keys it is ordinary text.
    const std::string text = std::string("\xEF\xBB\xBF") +  // a byte-order mark
                             "# a comment with \xCF\xBB in it\n"
                             "description = \"\xCF\xBB basic\"\n" +
                             tiny_scene +
                             "[reference]\n"
                             "source = '''multi-line \xCF\xBB\nliteral'''\n"
                             "\"\xCF\xBB quoted key\" = 1.0\n";
    Scene s;
    ASSERT_NO_THROW(s = parse_scene(text, "unicode.toml"));
    EXPECT_EQ(s.description, "\xCF\xBB basic");
    EXPECT_EQ(s.reference.at("\xCF\xBB quoted key"), 1.0);
    const std::string multi = std::string("description = \"\"\"line one \xCF\xBB\nline \\\"two\\\" \"\"\"\n") + tiny_scene;
    ASSERT_NO_THROW(s = parse_scene(multi, "multi.toml"));
    EXPECT_EQ(s.description, "line one \xCF\xBB\nline \"two\" ");
}

TEST(SceneText, NonAsciiTextOutsideStringsIsRefusedWithItsLine) {
    for (const auto& [text, line] : std::vector<std::pair<std::string, int>>{
             {std::string(tiny_scene) + "\xCF\xBB\n", 25},
             {"\xCF\xBB = 1\n", 1},
             {"a = 1 \xCF\xBB\n", 1},
             {"a = [1, \xC2\xA0 2]\n", 1},
             {"s = \"x\"\xCF\xBB\n", 1},
             {"s = 'x' # c\n\xCF\xBB\n", 2},
         }) {
        try {
            parse_scene(text, "bad.toml");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const SceneError& e) {
            const std::string m = e.what();
            EXPECT_EQ(m.rfind(fmt::format("bad.toml:{}:", line), 0), 0u) << m;
            EXPECT_NE(m.find("non-ASCII character outside a quoted string"), std::string::npos) << m;
        }
    }
}

}  // namespace
}  // namespace gpa::io
