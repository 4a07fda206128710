// Whole-step throughput of the engine on a Taylor bar in plastic flow, phase by phase, on 1 and
// N threads; the peak resident memory per node of a run that searches, reorders and writes a
// snapshot; and a triad memory bandwidth measured in the same process.
//
//   gpa_bench_steps [--case NAME]... [--nodes 1e4,1e5,1e6] [--threads 1,2] [--steps K]
//                   [--warmup W] [--repeat R] [--memory] [--bandwidth] [--quick]
//
// Cases (all the OFHC copper bar of scenes/taylor-copper-190.toml, 25.4 mm x 7.62 mm at 190 m/s
// onto a rigid anvil, Johnson-Cook, nodal viscosity, spacing scaled to the node count):
//   2d-variable  axisymmetric, variable connectivity (the scene as it is)
//   2d-fixed     axisymmetric, fixed connectivity (the default stencil: at the scene's a = 1.3,
//                the box of 8 and every lattice node within 2 a d0, 20 neighbours)
//   3d-variable  3D, the whole bar, variable connectivity
//   3d-fixed     3D, fixed connectivity (the default stencil: 80 neighbours inside at a = 1.3)
//
// Each size and thread count gets its own Simulation, all started from the same state; after W
// warm-up steps (the impact face is then in plastic flow) the simulations take turns to run K
// steps, R times, and the medians of those R rounds are reported. Node-steps per second = real
// nodes x steps / wall time of whole steps (output excluded); pair-steps per second the same with
// the neighbour-list entries (ghost rows included) in place of the nodes.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "bench_util.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"

#ifndef GPA_SOURCE_DIR
#define GPA_SOURCE_DIR "."
#endif

namespace {

using Clock = std::chrono::steady_clock;
using gpa::bench::median;
using gpa::bench::parse_list;


// The bar of scenes/taylor-copper-190.toml in the geometry and connectivity of `name`, with a
// spacing that gives about `nodes` nodes.
double skin_option = -1.0;  // --skin: SolverOptions::neighbour_skin (< 0: the default)
bool hourglass_all = false;  // --hourglass-all: the hourglass damping on every node

gpa::Scene make_case(const std::string& name, double nodes) {
    gpa::Scene scene = gpa::io::load_scene(std::filesystem::path(GPA_SOURCE_DIR) / "scenes/taylor-copper-190.toml");
    auto& bar = scene.bodies.at(0);
    const bool three_d = name.rfind("3d", 0) == 0;
    const double radius = bar.radius, length = bar.length;
    if (three_d) {
        scene.geometry = gpa::GeometryKind::ThreeD;
        bar.origin = {0, 0, 0};
        bar.velocity = {0, 0, bar.velocity[1]};
        for (auto& p : scene.planes) p.axis = 2;
        bar.spacing = std::cbrt(M_PI * radius * radius * length / nodes);
        // The cells whose centres lie inside, as the benchmark has always filled its bar: the fill
        // is set-up, not the step, and A/B runs against older commits compare the same nodes.
        bar.fill = gpa::CellFill::Centres;
    } else {
        bar.spacing = std::sqrt(radius * length / nodes);
    }
    bar.spacing_z = 0.0;
    scene.solver.connectivity = name.find("fixed") != std::string::npos ? gpa::ConnectivityMode::Fixed
                                                                         : gpa::ConnectivityMode::Variable;
    if (skin_option >= 0.0) scene.solver.neighbour_skin = skin_option;
    // The hourglass damping on the lattice regime, as the benchmark has always run it (3D runs damp
    // every node by default since 2026-12-05), so that A/B runs against older commits time the same
    // work; --hourglass-all times the damping on every node.
    scene.solver.hourglass_nodes = hourglass_all ? gpa::HourglassNodes::All : gpa::HourglassNodes::Lattice;
    scene.stop = {};
    scene.stop.max_steps = 1u << 30;
    return scene;
}

struct Round {
    double step_seconds = 0.0;
    std::map<std::string, double> phases;
    std::size_t searches = 0;
    std::size_t row_searches = 0;  // searches of some rows alone (NeighbourLists::search_rows)
};

struct Runner {
    std::unique_ptr<gpa::Simulation> sim;
    std::vector<Round> rounds;
    int threads = 1;

    Round run(std::size_t steps) {
        Round r;
        const auto before = sim->phase_times();
        const std::size_t searches = sim->totals().neighbour_searches, row_searches = sim->totals().row_searches;
        const auto t0 = Clock::now();
        for (std::size_t k = 0; k < steps; ++k) sim->step();
        r.step_seconds = std::chrono::duration<double>(Clock::now() - t0).count() / static_cast<double>(steps);
        const auto after = sim->phase_times();
        for (std::size_t p = 0; p < after.size(); ++p) {
            r.phases[after[p].name] = (after[p].seconds - before[p].seconds) / static_cast<double>(steps);
        }
        r.searches = sim->totals().neighbour_searches - searches;
        r.row_searches = sim->totals().row_searches - row_searches;
        return r;
    }
};

// Peak resident memory since the last reset, bytes (Linux: VmHWM; reset by clear_refs).
bool reset_peak_memory() {
    std::ofstream f("/proc/self/clear_refs");
    if (!f) return false;
    f << "5";
    return static_cast<bool>(f);
}

double resident_memory_bytes() {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line)) {
        if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) * 1024.0;
    }
    return 0.0;
}

double peak_memory_bytes() {
    std::ifstream f("/proc/self/status");
    std::string line;
    while (std::getline(f, line)) {
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) * 1024.0;
    }
    return 0.0;
}

// STREAM-style triad a = b + s c over arrays much larger than the caches; bytes counted as
// 3 x 8 per element (as STREAM does; write-allocate traffic would add a fourth).
double triad_bandwidth(int threads, std::size_t n) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
    std::vector<double> a(n), b(n), c(n);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16), [&](const auto& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            a[i] = 0.0;
            b[i] = 1.0;
            c[i] = 2.0;
        }
    });
    std::vector<double> rates;
    for (int rep = 0; rep < 7; ++rep) {
        const auto t0 = Clock::now();
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16), [&](const auto& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) a[i] = b[i] + 3.0 * c[i];
        });
        rates.push_back(24.0 * static_cast<double>(n) / std::chrono::duration<double>(Clock::now() - t0).count());
    }
    if (a[n / 2] != 7.0) std::abort();  // keeps the loop honest
    return median(rates);
}


}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"gpa_bench_steps: whole-step throughput, per phase, on a Taylor bar in plastic flow"};
    std::vector<std::string> cases;
    std::string nodes_text = "1e4,1e5", threads_text = "1,2";
    std::size_t steps = 20, warmup = 20, repeat = 3;
    bool memory = false, bandwidth = false, quick = false;
    app.add_option("--case", cases, "2d-variable, 2d-fixed, 3d-variable, 3d-fixed (default: all)")
        ->check(CLI::IsMember({"2d-variable", "2d-fixed", "3d-variable", "3d-fixed"}));
    app.add_option("--nodes", nodes_text, "comma-separated node counts (about)");
    app.add_option("--threads", threads_text, "comma-separated thread counts");
    app.add_option("--steps", steps, "steps per round")->check(CLI::Range(1, 1000000));
    app.add_option("--warmup", warmup, "steps before the first round")->check(CLI::Range(0, 1000000));
    app.add_option("--repeat", repeat, "rounds (medians are reported)")->check(CLI::Range(1, 1000));
    app.add_option("--skin", skin_option, "neighbour skin, a fraction of the interaction radius (default: the solver's)")
        ->check(CLI::Range(0.0, 1.0));
    app.add_flag("--hourglass-all", hourglass_all, "the hourglass damping on every node (solver.hourglass_nodes = \"all\")");
    app.add_flag("--memory", memory, "peak resident memory per node of a run with a search, a reorder and a snapshot");
    app.add_flag("--bandwidth", bandwidth, "triad memory bandwidth on each thread count");
    app.add_flag("--quick", quick, "CI: 2d-variable at 1e5 nodes, 1 and 2 threads, 10 steps x 3");
    CLI11_PARSE(app, argc, argv);
    if (quick) {
        cases = {"2d-variable"};
        nodes_text = "1e5";
        threads_text = "1,2";
        steps = 10;
        warmup = 10;
    }
    if (cases.empty()) cases = {"2d-variable", "2d-fixed", "3d-variable", "3d-fixed"};
    std::vector<double> sizes, thread_list;
    try {
        sizes = parse_list(nodes_text);
        thread_list = parse_list(threads_text);
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa_bench_steps: --nodes/--threads: {}\n", e.what());
        return 2;
    }

    fmt::print("# gpa_bench_steps: {} steps x {} rounds after {} warm-up steps; medians\n\n", steps, repeat, warmup);
    if (bandwidth) {
        for (double t : thread_list) {
            fmt::print("triad bandwidth, {} thread(s): {:.2f} GB/s (3 x 2^25 doubles)\n", t,
                       triad_bandwidth(static_cast<int>(t), std::size_t{1} << 25) / 1e9);
        }
        fmt::print("\n");
    }
    for (const auto& name : cases) {
        for (double size : sizes) {
            std::vector<Runner> runners;
            for (double t : thread_list) {
                Runner r;
                r.threads = static_cast<int>(t);
                r.sim = std::make_unique<gpa::Simulation>(make_case(name, size), r.threads);
                for (std::size_t k = 0; k < warmup; ++k) r.sim->step();
                runners.push_back(std::move(r));
            }
            for (std::size_t rep = 0; rep < repeat; ++rep) {
                for (auto& r : runners) r.rounds.push_back(r.run(steps));
            }
            const auto& first = *runners.front().sim;
            const double real = static_cast<double>(first.real_count());
            const double per_node = static_cast<double>(first.totals().pairs) / real;
            fmt::print("## {} with {:.0f} nodes ({:.0f} ghosts, {:.2f} neighbours per node incl. ghost pairs)\n\n", name, real,
                       static_cast<double>(first.totals().ghost_nodes), per_node);
            // Phase table: one column per thread count.
            std::string header = "| phase (ms/step) |", rule = "|---|";
            for (const auto& r : runners) {
                header += fmt::format(" {} thr |", r.threads);
                rule += "---|";
            }
            fmt::print("{}\n{}\n", header, rule);
            for (const auto& phase : first.phases()) {
                std::string row = fmt::format("| {} |", phase);
                for (const auto& r : runners) {
                    std::vector<double> v;
                    for (const auto& round : r.rounds) v.push_back(round.phases.at(phase));
                    row += fmt::format(" {:.3f} |", 1e3 * median(v));
                }
                fmt::print("{}\n", row);
            }
            std::vector<double> base_times;
            std::string whole = "| whole step |", rate = "| node-steps/s |", pair_rate = "| pair-steps/s |", speedup = "| speed-up |",
                        searched = "| searches/round |", rows_searched = "| row searches/round |";
            for (const auto& r : runners) {
                std::vector<double> v;
                std::size_t searches = 0, row_searches = 0;
                for (const auto& round : r.rounds) {
                    v.push_back(round.step_seconds);
                    searches += round.searches;
                    row_searches += round.row_searches;
                }
                const double t = median(v);
                if (base_times.empty()) base_times.push_back(t);
                whole += fmt::format(" {:.3f} |", 1e3 * t);
                rate += fmt::format(" {:.3g} M |", real / t / 1e6);
                // Pairs visited per second: the list entries of real and ghost rows, once per step.
                pair_rate += fmt::format(" {:.3g} M |", static_cast<double>(r.sim->totals().pairs) / t / 1e6);
                speedup += fmt::format(" {:.2f}x |", base_times.front() / t);
                searched += fmt::format(" {:.1f} of {} |", static_cast<double>(searches) / static_cast<double>(r.rounds.size()), steps);
                rows_searched += fmt::format(" {:.1f} |", static_cast<double>(row_searches) / static_cast<double>(r.rounds.size()));
            }
            fmt::print("{}\n{}\n{}\n{}\n{}\n{}\n\n", whole, rate, pair_rate, speedup, searched, rows_searched);
            std::fflush(stdout);
        }
    }
    if (memory) {
        namespace fs = std::filesystem;
        for (const auto& name : cases) {
            for (double size : sizes) {
                const bool reset = reset_peak_memory();
                auto scene = make_case(name, size);
                scene.solver.reorder_interval = 10;
                double real = 0.0, searches = 0.0;
                {
                    gpa::Simulation sim(scene, static_cast<int>(thread_list.back()));
                    const double after_setup = peak_memory_bytes();
                    for (int k = 0; k < 25; ++k) sim.step();  // two reorders, and searches
                    fmt::print("memory {}: peak {:.0f} B/node after set-up, {:.0f} after 25 steps, resident now {:.0f}\n", name,
                               after_setup / static_cast<double>(sim.real_count()),
                               peak_memory_bytes() / static_cast<double>(sim.real_count()),
                               resident_memory_bytes() / static_cast<double>(sim.real_count()));
                    // What the arrays hold now, by array, largest first (Simulation::memory_use).
                    auto use = sim.memory_use();
                    std::sort(use.begin(), use.end(), [](const auto& a, const auto& b) { return a.bytes > b.bytes; });
                    double total = 0.0;
                    for (const auto& row : use) total += static_cast<double>(row.bytes);
                    const double per = 1.0 / static_cast<double>(sim.real_count());
                    fmt::print("memory {} by array (B/node): ", name);
                    for (const auto& row : use) {
                        if (row.bytes > 0) fmt::print("{} {:.1f}; ", row.array, static_cast<double>(row.bytes) * per);
                    }
                    fmt::print("total {:.0f}\n", total * per);
                    const fs::path dir = fs::temp_directory_path() / fmt::format("gpa_bench_steps_{}", ::getpid());
                    fs::create_directories(dir);
                    gpa::io::SnapshotSeries series(dir);
                    series.write(sim.nodes(), sim.real_count(), sim.time());
                    fs::remove_all(dir);
                    real = static_cast<double>(sim.real_count());
                    searches = static_cast<double>(sim.totals().neighbour_searches);
                }
                const double peak = peak_memory_bytes();
                fmt::print("memory {} {:.0f} nodes: peak resident {:.1f} MB = {:.0f} bytes per node ({} searches, 2 reorders, "
                           "1 snapshot{})\n",
                           name, real, peak / 1e6, peak / real, searches,
                           reset ? "" : "; peak not reset: includes earlier cases");
            }
        }
    }
    return 0;
}
