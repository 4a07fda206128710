// The element solver's cost against GPA's, in one process: the OFHC copper bar of
// scenes/taylor-copper-190.toml (25.4 mm x 7.62 mm at 190 m/s onto a rigid anvil, Johnson-Cook,
// nodal viscosity) at the same spacing as GPA particles (variable connectivity, the scene as it
// is) and as elements (one quadrilateral per lattice cell: as many elements as particle nodes,
// four material points and about two nodes each).
//
//   gpa_bench_elements [--cells 1e4,1e5] [--threads 1,2] [--steps K] [--warmup W] [--repeat R] [--quick]
//
// Every size, kind and thread count gets its own Simulation from the same scene; after W warm-up
// steps (the impact face in plastic flow) they take turns to run K steps, R times, and the
// medians of the rounds are reported: microseconds per element-step (quadrilateral x step) and
// per GPA node-step, per phase and whole steps, and their ratio.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "gpa/engine/elements.hpp"
#include "bench_util.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

#ifndef GPA_SOURCE_DIR
#define GPA_SOURCE_DIR "."
#endif

namespace {

using Clock = std::chrono::steady_clock;
using gpa::bench::median;
using gpa::bench::parse_list;


gpa::Scene make_case(bool elements, double cells) {
    gpa::Scene scene = gpa::io::load_scene(std::filesystem::path(GPA_SOURCE_DIR) / "scenes/taylor-copper-190.toml");
    auto& bar = scene.bodies.at(0);
    bar.spacing = std::sqrt(bar.radius * bar.length / cells);
    if (elements) bar.discretisation = gpa::Discretisation::Elements;
    scene.stop = {};
    scene.stop.max_steps = 1u << 30;
    return scene;
}

struct Runner {
    std::string kind;
    int threads = 1;
    std::unique_ptr<gpa::Simulation> sim;
    std::vector<double> step_seconds;
    std::map<std::string, std::vector<double>> phases;

    double units() const {  // element-steps or node-steps per step
        return kind == "elements" ? static_cast<double>(sim->totals().elements) : static_cast<double>(sim->real_count());
    }
    void run(std::size_t steps) {
        const auto before = sim->phase_times();
        const auto t0 = Clock::now();
        for (std::size_t k = 0; k < steps; ++k) sim->step();
        step_seconds.push_back(std::chrono::duration<double>(Clock::now() - t0).count() / static_cast<double>(steps));
        const auto after = sim->phase_times();
        for (std::size_t p = 0; p < after.size(); ++p) {
            phases[after[p].name].push_back((after[p].seconds - before[p].seconds) / static_cast<double>(steps));
        }
    }
};


}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"gpa_bench_elements: element-steps against GPA node-steps on a Taylor bar in plastic flow"};
    std::string cells_text = "1e4,1e5", threads_text = "1,2";
    std::size_t steps = 20, warmup = 30, repeat = 5;
    bool quick = false;
    app.add_option("--cells", cells_text, "lattice cells of the bar (particle nodes = elements), comma-separated");
    app.add_option("--threads", threads_text, "comma-separated thread counts");
    app.add_option("--steps", steps, "steps per round")->check(CLI::Range(1, 1000000));
    app.add_option("--warmup", warmup, "steps before the first round")->check(CLI::Range(0, 1000000));
    app.add_option("--repeat", repeat, "rounds (medians are reported)")->check(CLI::Range(1, 1000));
    app.add_flag("--quick", quick, "1e4 cells, 1 and 2 threads, 10 steps x 3");
    CLI11_PARSE(app, argc, argv);
    if (quick) {
        cells_text = "1e4";
        steps = 10;
        warmup = 10;
        repeat = 3;
    }
    std::vector<double> sizes, thread_list;
    try {
        sizes = parse_list(cells_text);
        thread_list = parse_list(threads_text);
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa_bench_elements: --cells/--threads: {}\n", e.what());
        return 2;
    }
    fmt::print("# gpa_bench_elements: {} steps x {} rounds after {} warm-up steps; medians\n\n", steps, repeat, warmup);
    for (double size : sizes) {
        std::vector<Runner> runners;
        for (const char* kind : {"particles", "elements"}) {
            for (double t : thread_list) {
                Runner r;
                r.kind = kind;
                r.threads = static_cast<int>(t);
                r.sim = std::make_unique<gpa::Simulation>(make_case(r.kind == "elements", size), r.threads);
                for (std::size_t k = 0; k < warmup; ++k) r.sim->step();
                runners.push_back(std::move(r));
            }
        }
        for (std::size_t rep = 0; rep < repeat; ++rep) {
            for (auto& r : runners) r.run(steps);
        }
        const auto& particles = *runners.front().sim;
        const auto& elements = *runners.back().sim;
        fmt::print("## the copper bar at {:.4g} mm: {} particle nodes; {} elements ({} nodes, {} material points)\n\n",
                   1e3 * particles.scene().bodies[0].spacing, particles.real_count(), elements.totals().elements,
                   elements.totals().element_nodes, 4 * elements.totals().elements);
        for (const char* kind : {"particles", "elements"}) {
            std::string header = fmt::format("| {} phase (ms/step) |", kind), rule = "|---|";
            std::vector<const Runner*> mine;
            for (const auto& r : runners) {
                if (r.kind == kind) mine.push_back(&r);
            }
            for (const Runner* r : mine) {
                header += fmt::format(" {} thr |", r->threads);
                rule += "---|";
            }
            fmt::print("{}\n{}\n", header, rule);
            for (const auto& phase : mine.front()->sim->phases()) {
                std::string row = fmt::format("| {} |", phase);
                for (const Runner* r : mine) row += fmt::format(" {:.3f} |", 1e3 * median(r->phases.at(phase)));
                fmt::print("{}\n", row);
            }
            std::string whole = "| whole step |", per = fmt::format("| us per {} |", std::string(kind) == "elements" ? "element-step" : "node-step"),
                        speedup = "| speed-up |";
            const double base = median(mine.front()->step_seconds);
            for (const Runner* r : mine) {
                const double t = median(r->step_seconds);
                whole += fmt::format(" {:.3f} |", 1e3 * t);
                per += fmt::format(" {:.3f} |", 1e6 * t / r->units());
                speedup += fmt::format(" {:.2f}x |", base / t);
            }
            fmt::print("{}\n{}\n{}\n\n", whole, per, speedup);
        }
        std::string ratio = "| element-step / node-step |", rule = "|---|", head = "| ratio |";
        for (std::size_t k = 0; k < thread_list.size(); ++k) {
            const Runner& p = runners[k];
            const Runner& e = runners[thread_list.size() + k];
            const double pe = median(e.step_seconds) / e.units(), pp = median(p.step_seconds) / p.units();
            head += fmt::format(" {} thr |", p.threads);
            rule += "---|";
            ratio += fmt::format(" {:.2f} |", pe / pp);
        }
        fmt::print("{}\n{}\n{}\n\n", head, rule, ratio);
        std::fflush(stdout);
    }
    return 0;
}
