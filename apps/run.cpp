#include "run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <future>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"
#include "progress.hpp"

namespace gpa::app {

std::string_view default_scene_text();  // scenes/armco-cylinder-nodal.toml, embedded at build time

namespace {

namespace fs = std::filesystem;

Scene read_scene(const std::optional<fs::path>& file) {
    if (file) return io::load_scene(*file);
    return io::parse_scene(default_scene_text(), "built-in default scene (scenes/armco-cylinder-nodal.toml)");
}

// Snapshot times: every interval, or `count` spread over the end time; with neither known,
// the first and the last.
double snapshot_interval(const Scene& s) {
    if (s.output.snapshot_interval > 0.0) return s.output.snapshot_interval;
    if (s.output.snapshots > 1 && s.stop.end_time > 0.0) return s.stop.end_time / double(s.output.snapshots - 1);
    return 0.0;
}

// A copy of the real nodes and element bodies, written by a background task while the run goes on.
class SnapshotWriter {
public:
    explicit SnapshotWriter(fs::path folder) : series_(std::move(folder)) {}
    ~SnapshotWriter() {
        try {
            wait();
        } catch (...) {
        }
    }
    void write(const Simulation& sim) {
        wait();
        pending_ = std::async(std::launch::async, [this, snapshot = io::take_snapshot(sim)] {
            const auto t0 = std::chrono::steady_clock::now();
            series_.write(snapshot);
            seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        });
    }
    void wait() {
        if (pending_.valid()) pending_.get();
    }
    std::size_t count() const { return series_.count(); }
    double seconds() const { return seconds_; }

private:
    io::SnapshotSeries series_;
    std::future<void> pending_;
    double seconds_ = 0.0;
};

void print_report(const Simulation& sim) {
    const auto& t = sim.totals();
    fmt::print("  {} real nodes, {} steps, t = {:.4g} us ({})\n", t.real_nodes, t.step, t.time * 1e6, sim.stop_reason());
    if (t.elements > 0) fmt::print("  {} elements, {} element nodes\n", t.elements, t.element_nodes);
    if (!t.planes.empty()) {
        fmt::print("  final length {:.4g} mm, footprint diameter {:.4g} mm\n", t.length * 1e3, t.footprint_diameter * 1e3);
    }
    fmt::print("  plastic work {:.4g} J, viscous work {:.4g} J, boundary work {:.3g} J, energy error {:+.3g} %\n",
               t.plastic_work, t.viscous_work, t.boundary_work, 100.0 * t.energy_error);
    for (const auto& c : io::compare_with_reference(sim)) {
        fmt::print("  {}: {:.4g} against the reference {:.4g} ({:+.2f} %)\n", c.key, c.computed, c.reference,
                   100.0 * c.relative_error);
    }
}

}  // namespace

int run_scene(const RunOptions& options) {
    const Scene scene = read_scene(options.scene);
    const fs::path output = options.output.value_or(default_output_folder("runs", scene.name));
    const auto wall_start = std::chrono::steady_clock::now();
    Simulation sim(scene, options.threads);  // before the folder: an impossible scene leaves nothing behind
    io::RunFolder folder(output, options.overwrite);
    if (!options.quiet) {
        spdlog::info("{}: {} nodes, {} thread{}, output in {}", scene.name.empty() ? "scene" : scene.name, sim.real_count(),
                     sim.threads(), sim.threads() == 1 ? "" : "s", folder.partial().string());
    }
    io::HistoryWriter history(folder.partial() / "history.csv", sim.totals(), dimension_of(scene.geometry));
    SnapshotWriter snapshots(folder.partial());
    io::RunSummary summary;
    summary.scene_file = options.scene ? options.scene->string() : "(built-in default)";
    Progress progress(options.quiet);
    const double interval = snapshot_interval(scene);
    double next_snapshot = interval;
    history.write(sim.totals());
    snapshots.write(sim);
    try {
        while (!sim.finished()) {
            sim.step();
            const bool last = sim.finished();
            if (last || sim.steps() % std::max<std::size_t>(scene.output.history_every, 1) == 0) history.write(sim.totals());
            if (last || (interval > 0.0 && sim.time() >= next_snapshot * (1.0 - 1e-9))) {
                snapshots.write(sim);
                while (interval > 0.0 && next_snapshot <= sim.time() * (1.0 + 1e-9)) next_snapshot += interval;
            }
            progress.update(sim);
        }
        progress.finish(sim);
        snapshots.wait();
    } catch (const std::exception& e) {
        progress.finish(sim);
        try {
            snapshots.wait();
        } catch (...) {
        }
        summary.status = "failed";
        summary.message = e.what();
        summary.snapshots = snapshots.count();
        summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        try {
            history.write(sim.totals());
            io::write_summary(folder.partial() / "summary.json", sim, summary);
        } catch (...) {
        }
        fmt::print(stderr, "gpa: the run failed at t = {:.4g} us, step {}: {}\n", sim.time() * 1e6, sim.steps(), e.what());
        fmt::print(stderr, "gpa: what was written so far is in {}\n", folder.partial().string());
        return 3;
    }
    summary.message = sim.stop_reason();
    summary.snapshots = snapshots.count();
    summary.output_seconds = snapshots.seconds();
    summary.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    io::write_summary(folder.partial() / "summary.json", sim, summary);
    io::write_profile(folder.partial() / "profile.csv", sim);
    folder.commit();
    if (!options.quiet) {
        fmt::print("{}\n", scene.name.empty() ? "run finished" : scene.name);
        print_report(sim);
        fmt::print("  wall time {:.1f} s on {} thread{}\n", summary.wall_seconds, sim.threads(), sim.threads() == 1 ? "" : "s");
    }
    fmt::print("output: {} (open particles.pvd in ParaView; history.csv, summary.json)\n", folder.final_path().string());
    return 0;
}

fs::path default_output_folder(const std::string& root, const std::string& scene_name) {
    std::string slug;
    for (char c : scene_name) slug += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
    if (slug.empty()) slug = "scene";
    const std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
    return fs::path(root) / fmt::format("{}-{}", slug, stamp);
}

int check_scene(const fs::path& file) {
    const Scene scene = io::load_scene(file);
    Simulation sim(scene, 1);  // builds the nodes: every check of set-up runs
    fmt::print("{}: OK\n", file.string());
    fmt::print("  {} ({}), {} bod{}, {} real nodes, {} ghost nodes at the start\n", scene.name, name_of(scene.geometry),
               scene.bodies.size(), scene.bodies.size() == 1 ? "y" : "ies", sim.real_count(), sim.totals().ghost_nodes);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const auto block = body_lattice(scene, b);
        std::size_t count = 0;
        for (std::size_t i = 0; i < sim.real_count(); ++i) count += sim.nodes().body[i] == static_cast<int>(b);
        std::string elements;
        if (const ElementPart* e = sim.elements(); e && scene.bodies[b].discretisation == Discretisation::Elements) {
            count = static_cast<std::size_t>(std::count(e->mesh().nodes.body.begin(), e->mesh().nodes.body.end(), static_cast<int>(b)));
            elements = fmt::format(" ({} elements)", std::count(e->mesh().quads.body.begin(), e->mesh().quads.body.end(), static_cast<int>(b)));
        }
        fmt::print("  body \"{}\": {}, {} nodes{}, lattice spacing {:.4g} x {:.4g} mm\n", scene.bodies[b].name,
                   scene.bodies[b].material, count, elements, block.spacing[0] * 1e3, block.spacing[1] * 1e3);
    }
    fmt::print("  first time step {:.3g} ns; phases: {}\n", sim.next_time_step() * 1e9, fmt::join(sim.phases(), ", "));
    return 0;
}

int list_materials() {
    for (const auto& m : io::builtin_materials()) {
        fmt::print("{}\n  density {} kg/m^3, shear modulus {:.4g} GPa, specific heat {} J/(kg K), melt {} K\n", m.name,
                   m.density, m.shear_modulus / 1e9, m.specific_heat, m.melt_temperature);
        if (const auto* jc = std::get_if<materials::JohnsonCookStrength>(&m.strength)) {
            fmt::print("  Johnson-Cook A {:.4g} MPa, B {:.4g} MPa, n {}, C {}, m {}\n", jc->a / 1e6, jc->b / 1e6, jc->n, jc->c, jc->m);
        }
        fmt::print("  source: {}\n", m.source);
    }
    return 0;
}

}  // namespace gpa::app
