// Writes a scene's element reference (io/reference.hpp) from finished `gpa run` folders of its
// element runs instead of running the study again: each folder's summary.json (final length,
// footprint, plastic work, steps, time), its last snapshot (the local peaks of measure.hpp over the
// triangles, with the scene's peak_radius) and its profile.csv (the outline). The rule that turns
// the series into a reference and the file it writes are those of `gpa study --reference`.
//
//   gpa_reference_from_runs SCENE OUT.toml VARIANT FACTOR:RUN_DIR FACTOR:RUN_DIR FACTOR:RUN_DIR...
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <regex>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpa/engine/measure.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/snapshot_reader.hpp"
#include "gpa/io/study.hpp"

using namespace gpa;
namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    if (!in) throw std::runtime_error("cannot read " + p.string());
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

double json_value(const std::string& text, const std::string& key) {
    const std::regex re("\"" + key + "\": ([-+0-9.eE]+)");
    std::smatch m;
    if (!std::regex_search(text, m, re)) throw std::runtime_error("summary.json has no " + key);
    return std::stod(m[1]);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 6) {
        std::fprintf(stderr, "gpa_reference_from_runs SCENE OUT.toml VARIANT FACTOR:RUN_DIR FACTOR:RUN_DIR FACTOR:RUN_DIR...\n");
        return 2;
    }
    try {
        const Scene scene = io::load_scene(argv[1]);
        io::StudyReport report;
        report.scene_name = scene.name;
        report.scene_file = argv[1];
        io::Variant v = io::parse_variant(argv[3]);
        report.variants.push_back(v);
        for (int k = 4; k < argc; ++k) {
            const std::string arg = argv[k];
            const auto colon = arg.find(':');
            const double factor = std::stod(arg.substr(0, colon));
            const fs::path dir = arg.substr(colon + 1);
            Scene s = scene;
            io::apply_variant(v, s);
            s = io::refined(s, factor);
            io::StudyCase c;
            c.variant = v.name;
            c.series = v.name;
            c.refinement = factor;
            c.cell_size = io::lattice_cell_size(s);
            const std::string summary = slurp(dir / "summary.json");
            c.finished = summary.find("\"status\": \"finished\"") != std::string::npos;
            c.metrics["final_length"] = json_value(summary, "length_m");
            c.metrics["footprint_diameter"] = json_value(summary, "footprint_diameter_m");
            c.metrics["plastic_work"] = json_value(summary, "plastic_work_J");
            c.steps = static_cast<std::size_t>(json_value(summary, "steps"));
            c.wall_seconds = json_value(summary, "step_seconds");
            // The local peaks of the last snapshot's triangles.
            const auto index = io::read_pvd(io::find_pvd(dir));
            const io::VtkFile file(index.snapshots.back().files.front());
            const auto points = file.points();
            const auto cells = file.cells();
            const auto strain = file.values("plastic_strain", io::DataLocation::Cell);
            const auto heat = file.values("temperature", io::DataLocation::Cell);
            std::vector<measure::FieldPoint> centroids;
            std::vector<double> centroid_strain, centroid_heat;
            for (std::size_t t = 0; t < file.cell_count(); ++t) {
                const std::int64_t begin = t ? cells.offsets[t - 1] : 0;
                if (cells.offsets[t] - begin != 3) continue;
                std::array<std::array<double, 2>, 3> x{};
                for (int a = 0; a < 3; ++a) {
                    const auto p = static_cast<std::size_t>(cells.connectivity[static_cast<std::size_t>(begin + a)]);
                    x[a] = {points[3 * p], points[3 * p + 1]};
                }
                measure::FieldPoint f;
                f.position = {(x[0][0] + x[1][0] + x[2][0]) / 3, (x[0][1] + x[1][1] + x[2][1]) / 3, 0};
                f.weight = 0.5 * std::abs((x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[1][1] - x[0][1]) * (x[2][0] - x[0][0]));
                centroids.push_back(f);
                centroid_strain.push_back(strain[t]);
                centroid_heat.push_back(heat[t]);
            }
            const std::array<std::span<const double>, 2> fields{centroid_strain, centroid_heat};
            const auto peaks = measure::local_peaks(centroids, fields, scene.output.peak_radius, 2);
            c.metrics["peak_plastic_strain"] = peaks[0].value;
            c.metrics["peak_temperature"] = peaks[1].value;
            std::ifstream prof(dir / "profile.csv");
            std::string line;
            std::getline(prof, line);
            while (std::getline(prof, line)) {
                const auto comma = line.find(',');
                c.outline.emplace_back(std::stod(line.substr(0, comma)), std::stod(line.substr(comma + 1)));
            }
            fmt::print("{:g}: cell {:.4g} mm, L {:.5f} mm, D {:.5f} mm, PW {:.4f} J, peak strain {:.4f}, peak T {:.1f} K, {} steps, {:.0f} s\n",
                       factor, c.cell_size * 1e3, c.metrics["final_length"] * 1e3, c.metrics["footprint_diameter"] * 1e3,
                       c.metrics["plastic_work"], c.metrics["peak_plastic_strain"], c.metrics["peak_temperature"], c.steps,
                       c.wall_seconds);
            report.cases.push_back(c);
        }
        report.refinements.clear();
        for (const auto& c : report.cases) report.refinements.push_back(c.refinement);
        const auto analysis = io::analyse_study(report);
        const io::StudyCase* finest = &report.cases.front();
        for (const auto& c : report.cases) {
            if (c.cell_size < finest->cell_size) finest = &c;
        }
        auto ref = io::reference_from_study(report, analysis, v.name, finest->outline);
        // The commit of the program that made the runs (GPA_RUNS_COMMIT), not this tool's.
        if (const char* c = std::getenv("GPA_RUNS_COMMIT")) ref.commit = c;
        ref.written_by = "gpa_reference_from_runs from the gpa run folders of its cases (tools/reference_from_runs.cpp)";
        ref.peak_radius = scene.output.peak_radius;
        io::write_element_reference(argv[2], ref);
        for (const auto& [key, x] : ref.values) {
            fmt::print("  {}: {:.6g} ({}, {}, order {:.2f}, uncertainty {:.3g})\n", key, x.value, x.kind, x.status, x.order, x.uncertainty);
        }
        for (const auto& [key, why] : ref.missing) fmt::print("  {}: no reference: {}\n", key, why);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gpa_reference_from_runs: %s\n", e.what());
        return 1;
    }
    return 0;
}
