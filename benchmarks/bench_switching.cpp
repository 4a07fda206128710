// What the search costs against the number of switched nodes (issue 22, item 2): a Taylor bar run
// with automatic connectivity beside the same bar all-variable, the neighbours and switching
// phases timed window by window while the switched nodes grow from none to most of the bar.
//
//   gpa_bench_switching [--scene FILE] [--refine F] [--threads N] [--windows K] [--until US] [--quick]
//
// Both runs take the scene as written (scenes/taylor-copper-190.toml by default) with every
// body's spacing divided by F, one with every body automatic, one with every body variable; they
// take turns a window at a time (so that the host's load falls on both alike), each window
// ending at the same simulated time, the scene's end time (or --until) divided into K equal windows. Per window and
// run: the variable nodes at its end (a share of the real nodes), the steps it took, and per step
// the neighbours phase (the per-step cut of the candidate lists, the removal of open pairs, and
// the searches, full or of some rows), the switching phase (the lattice-cell check and the
// switches) and the whole step; the full and row searches it made. If the search and the cut
// cost in proportion to the switched nodes, the automatic run's neighbours phase per step grows
// from the cut of the fixed rows alone towards the all-variable run's as the share does.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

#ifndef GPA_SOURCE_DIR
#define GPA_SOURCE_DIR "."
#endif

namespace {

using Clock = std::chrono::steady_clock;

// One run's position: cumulative phase seconds and counts, to take differences over a window.
struct Mark {
    std::size_t steps = 0;
    double neighbours = 0.0, switching = 0.0, wall = 0.0;
    std::size_t searches = 0, row_searches = 0;
};

struct Run {
    std::unique_ptr<gpa::Simulation> sim;
    double wall = 0.0;  // stepping seconds so far

    Mark mark() const {
        Mark m;
        m.steps = sim->steps();
        for (const auto& p : sim->phase_times()) {
            if (p.name == "neighbours") m.neighbours = p.seconds;
            if (p.name == "switching") m.switching = p.seconds;
        }
        m.wall = wall;
        m.searches = sim->totals().neighbour_searches;
        m.row_searches = sim->totals().row_searches;
        return m;
    }
    // Steps until the simulated time reaches `until` or the run ends.
    void advance(double until) {
        const auto t0 = Clock::now();
        while (!sim->finished() && sim->time() < until) sim->step();
        wall += std::chrono::duration<double>(Clock::now() - t0).count();
    }
};

gpa::Scene with_connectivity(gpa::Scene scene, gpa::ConnectivityMode mode, double refine) {
    scene.solver.connectivity = mode;
    for (auto& b : scene.bodies) {
        b.connectivity = mode;
        b.spacing /= refine;
        b.spacing_z /= refine;
    }
    return scene;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"gpa_bench_switching: the search's cost against the number of switched nodes, automatic beside all-variable"};
    std::string scene_file = std::string(GPA_SOURCE_DIR) + "/scenes/taylor-copper-190.toml";
    double refine = 2.0;
    int threads = 1;
    std::size_t windows = 8;
    double until_us = 0.0;
    bool quick = false;
    app.add_option("--scene", scene_file, "scene file (default: scenes/taylor-copper-190.toml)")->check(CLI::ExistingFile);
    app.add_option("--refine", refine, "every body's spacing divided by this (default 2)")->check(CLI::Range(0.1, 100.0));
    app.add_option("--threads", threads, "threads of both runs (default 1)")->check(CLI::Range(1, 1024));
    app.add_option("--windows", windows, "windows of equal simulated time (default 8)")->check(CLI::Range(1, 1000));
    app.add_option("--until", until_us, "simulated time the windows divide, us (default: the scene's end time)")
        ->check(CLI::PositiveNumber);
    app.add_flag("--quick", quick, "a short check: refine 1, 2 windows of the first tenth of the run");
    CLI11_PARSE(app, argc, argv);
    if (quick) {
        refine = 1.0;
        windows = 2;
    }
    gpa::Scene scene;
    try {
        scene = gpa::io::load_scene(scene_file);
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa_bench_switching: {}\n", e.what());
        return 2;
    }
    const double end = until_us > 0.0 ? until_us * 1e-6 : scene.stop.end_time;
    if (!(end > 0.0)) {
        fmt::print(stderr, "gpa_bench_switching: {}: the scene has no end time (stop.end_time): give --until\n", scene_file);
        return 2;
    }
    const double span = quick ? 0.1 * end : end;
    Run automatic, variable;
    automatic.sim = std::make_unique<gpa::Simulation>(with_connectivity(scene, gpa::ConnectivityMode::Automatic, refine), threads);
    variable.sim = std::make_unique<gpa::Simulation>(with_connectivity(scene, gpa::ConnectivityMode::Variable, refine), threads);
    const double real = static_cast<double>(automatic.sim->real_count());
    fmt::print("# gpa_bench_switching: {}, spacing / {}, {:.0f} nodes, {} thread(s), {} windows to {:.4g} us\n\n", scene_file, refine,
               real, threads, windows, span * 1e6);
    fmt::print("| window end (us) | switched | steps auto / var | neighbours auto / var (ms/step) | auto / var | switching auto "
               "(ms/step) | step auto / var (ms) | searches auto / var (full, rows) |\n");
    fmt::print("|---|---|---|---|---|---|---|---|\n");
    Mark a0 = automatic.mark(), v0 = variable.mark();
    Mark a_start = a0, v_start = v0;
    for (std::size_t w = 1; w <= windows; ++w) {
        const double until = span * static_cast<double>(w) / static_cast<double>(windows);
        automatic.advance(until);
        variable.advance(until);
        const Mark a1 = automatic.mark(), v1 = variable.mark();
        const double sa = static_cast<double>(std::max<std::size_t>(1, a1.steps - a0.steps));
        const double sv = static_cast<double>(std::max<std::size_t>(1, v1.steps - v0.steps));
        const double na = 1e3 * (a1.neighbours - a0.neighbours) / sa, nv = 1e3 * (v1.neighbours - v0.neighbours) / sv;
        const double switched = static_cast<double>(automatic.sim->totals().variable_nodes) / real;
        fmt::print("| {:.2f} | {:.1f} % | {} / {} | {:.3f} / {:.3f} | {:.2f} | {:.3f} | {:.3f} / {:.3f} | {}, {} / {}, {} |\n", until * 1e6,
                   100.0 * switched, a1.steps - a0.steps, v1.steps - v0.steps, na, nv, na / nv,
                   1e3 * (a1.switching - a0.switching) / sa, 1e3 * (a1.wall - a0.wall) / sa, 1e3 * (v1.wall - v0.wall) / sv,
                   a1.searches - a0.searches, a1.row_searches - a0.row_searches, v1.searches - v0.searches,
                   v1.row_searches - v0.row_searches);
        std::fflush(stdout);
        a0 = a1;
        v0 = v1;
        if (automatic.sim->finished() && variable.sim->finished()) break;
    }
    const Mark a1 = automatic.mark(), v1 = variable.mark();
    fmt::print("\nwhole: automatic {} steps, {:.2f} s ({:.2f} s neighbours, {:.2f} s switching); all-variable {} steps, {:.2f} s "
               "({:.2f} s neighbours)\n",
               a1.steps - a_start.steps, a1.wall - a_start.wall, a1.neighbours - a_start.neighbours, a1.switching - a_start.switching,
               v1.steps - v_start.steps, v1.wall - v_start.wall, v1.neighbours - v_start.neighbours);
    return 0;
}
