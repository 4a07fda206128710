#include "study.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <ctime>
#include <exception>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/resource.h>
#include <unistd.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "gpa/engine/errors.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"
#include "progress.hpp"
#include "run.hpp"

namespace gpa::app {

namespace {

namespace fs = std::filesystem;

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// The process's memory as Linux reports it in /proc/self/status ("VmHWM:   1640 kB"), in bytes;
// NaN where there is no such file or field.
double status_bytes(const std::string& field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(field + ":", 0) != 0) continue;
        std::istringstream words(line.substr(field.size() + 1));
        double kb = nan;
        if (words >> kb) return kb * 1024.0;
    }
    return nan;
}

// The peak resident memory of each case. On Linux, writing 5 to /proc/self/clear_refs sets the
// high-water mark VmHWM back to the present resident size, so VmHWM after a case is that case's
// peak. Without it (another system, or a kernel that refuses), getrusage's maxrss is the peak
// since the process started, which a larger earlier case can have set.
class MemoryGauge {
public:
    MemoryGauge() { resettable_ = reset_high_water_mark() && std::isfinite(status_bytes("VmHWM")); }

    // Before a case: give freed heap back to the system, so that what is resident is what the
    // program holds, and restart the high-water mark from there.
    void start_case() {
#if defined(__GLIBC__)
        ::malloc_trim(0);
#endif
        if (resettable_) resettable_ = reset_high_water_mark();
        baseline_ = status_bytes("VmRSS");
    }

    double peak() const {
        if (resettable_) return status_bytes("VmHWM");
        rusage usage{};
        if (::getrusage(RUSAGE_SELF, &usage) != 0) return nan;
        return double(usage.ru_maxrss) * 1024.0;  // kB on Linux
    }

    // The case's own share: its peak above what was resident before it (only meaningful with a
    // resettable high-water mark).
    double case_bytes() const { return resettable_ ? peak() - baseline_ : nan; }

    std::string note() const {
        return resettable_
                   ? "peak MB is the process's resident high-water mark (VmHWM) during the case, reset before it through "
                     "/proc/self/clear_refs; B/node is that peak less the resident size before the case, per node"
                   : "/proc/self/clear_refs could not be written: peak MB is getrusage's maxrss, the process's peak since "
                     "it started (a larger earlier case may have set it), and B/node is not measured";
    }

private:
    static bool reset_high_water_mark() {
        std::ofstream out("/proc/self/clear_refs");
        if (!out) return false;
        out << "5";
        out.flush();
        return static_cast<bool>(out);
    }
    bool resettable_ = false;
    double baseline_ = nan;
};

// One planned run.
struct Plan {
    std::size_t variant = 0;
    double refinement = 1.0;
    int threads = 1;
    std::string series;
    Scene scene;
    double cell_size = 0.0;
};

std::string thread_word(int n) { return n == 1 ? "thread" : "threads"; }

// A case's one-line result for the progress output.
std::string case_line(const io::StudyCase& c) {
    if (!c.finished) return fmt::format("failed after {} steps ({:.3g} s): {}", c.steps, c.wall_seconds, c.message);
    std::string s = fmt::format("{:.3g} s, {:.3g} M node-steps/s, peak {:.0f} MB", c.wall_seconds, c.node_steps_per_second / 1e6,
                                c.peak_bytes / 1048576.0);
    for (const auto& [key, value] : c.metrics) {
        const auto* m = io::find_study_metric(key);
        if (!m || value == 0.0) continue;
        s += fmt::format("; {} {:.5g} {}", key, value * m->display_scale, m->display_unit);
    }
    return s;
}

void print_summary(const io::StudyReport& report, const io::StudyAnalysis& analysis) {
    fmt::print("{}: {} cases\n", report.scene_name.empty() ? report.scene_file : report.scene_name, report.cases.size());
    for (const auto& key : analysis.metrics) {
        const auto* m = io::find_study_metric(key);
        if (!m->analysed) continue;
        const auto ref = report.reference.find(key);
        fmt::print("  {}{}:\n", key,
                   ref != report.reference.end()
                       ? fmt::format(" (the scene's answer {:.5g} {})", ref->second * m->display_scale, m->display_unit)
                       : "");
        for (const auto& series : analysis.series) {
            const auto& x = analysis.extrapolations.at({series, key});
            if (x.status == io::ConvergenceStatus::Converging) {
                fmt::print("    {}: extrapolated {:.5g} {}, observed order {}{}{}\n", series, x.extrapolated * m->display_scale,
                           m->display_unit, std::isfinite(x.order) ? fmt::format("{:.2f}", x.order) : "> 64",
                           ref != report.reference.end()
                               ? fmt::format(", {:+.2f} % from the answer", 100.0 * io::relative_error(x.extrapolated, ref->second))
                               : "",
                           x.slow ? " (converging slowly: a rough guess)" : "");
            } else {
                fmt::print("    {}: {}\n", series, io::describe(x.status));
            }
        }
    }
}

}  // namespace

int run_study(const StudyOptions& options) {
    // Everything that can be refused is checked before the output folder exists.
    std::string reference_warning;
    const Scene scene = io::load_scene(options.scene, &reference_warning);
    if (!reference_warning.empty()) spdlog::warn("{}", reference_warning);
    log_scene_warnings(scene, options.scene.string());
    const std::vector<double> factors = io::parse_refinements(options.refine);
    const std::vector<std::string> chosen_metrics = options.metrics.empty() ? std::vector<std::string>{} : io::parse_metric_list(options.metrics);
    const std::vector<int> thread_counts = io::parse_thread_counts(options.threads);
    std::vector<io::Variant> variants;
    for (const auto& text : options.variants) variants.push_back(io::parse_variant(text));
    if (variants.empty()) variants.push_back(io::Variant{"scene", {}, {}});
    for (std::size_t a = 0; a < variants.size(); ++a) {
        for (std::size_t b = 0; b < a; ++b) {
            if (variants[a].name == variants[b].name) {
                throw InputError(fmt::format("--variant: the name '{}' is given twice", variants[a].name));
            }
        }
    }

    std::vector<std::vector<Plan>> by_variant(variants.size());
    std::vector<std::string> series_names;
    for (std::size_t v = 0; v < variants.size(); ++v) {
        Scene base = scene;
        io::apply_variant(variants[v], base);
        std::vector<int> threads = variants[v].threads ? std::vector<int>{*variants[v].threads} : thread_counts;
        for (int& t : threads) t = t == 0 ? hardware_threads() : t;
        std::vector<double> cells;
        for (double f : factors) {
            Scene s;
            double cell = 0.0;
            try {
                s = io::refined(base, f);
                validate_scene(s);
                cell = io::lattice_cell_size(s);
            } catch (const InputError& e) {
                throw InputError(fmt::format("--refine {:g} (variant {}): {}", f, variants[v].name, e.what()));
            }
            if (!cells.empty() && !(cell < cells.back() * (1.0 - 1e-9))) {
                throw InputError(fmt::format("--refine: the factors {:g} and {:g} give the same lattice ({:.4g} mm cells); "
                                             "choose factors further apart",
                                             factors[cells.size() - 1], f, cell * 1e3));
            }
            cells.push_back(cell);
            for (int t : threads) {
                Plan p;
                p.variant = v;
                p.refinement = f;
                p.threads = t;
                p.series = threads.size() > 1 ? fmt::format("{}-{}t", variants[v].name, t) : variants[v].name;
                p.scene = s;
                p.cell_size = cell;
                if (f == factors.front() && std::find(series_names.begin(), series_names.end(), p.series) != series_names.end()) {
                    throw InputError(fmt::format("--variant: two series are called '{}'; rename a variant", p.series));
                }
                if (f == factors.front()) series_names.push_back(p.series);
                by_variant[v].push_back(std::move(p));
            }
        }
        // The coarsest lattice of each variant is set up once, so that a scene the engine cannot
        // start (a fixed body apart from a plane, ...) is refused before anything is written.
        try {
            Simulation check(by_variant[v].front().scene, 1, options.memory);
        } catch (const InputError& e) {
            throw InputError(variants.size() > 1 || !options.variants.empty()
                                 ? fmt::format("--variant {}: {}", variants[v].name, e.what())
                                 : std::string(e.what()));
        }
    }
    // Coarse to fine, every variant at each resolution: the cheap cases report first.
    std::vector<Plan> plans;
    for (double f : factors) {
        for (auto& list : by_variant) {
            for (auto& p : list) {
                if (p.refinement == f) plans.push_back(std::move(p));
            }
        }
    }

    if (options.reference) {
        if (series_names.size() != 1) {
            throw InputError(fmt::format("--reference: the study has {} series; a reference is written from one (one variant, "
                                         "one thread count)",
                                         series_names.size()));
        }
        if (factors.size() < 3) throw InputError("--reference: a reference needs three or more resolutions (--refine)");
        const fs::path parent = options.reference->parent_path();
        if (!parent.empty() && !fs::is_directory(parent)) {
            throw InputError(fmt::format("--reference {}: the folder {} does not exist", options.reference->string(), parent.string()));
        }
    }
    const fs::path output = options.output.value_or(default_output_folder("studies", scene.name));
    io::RunFolder folder(output, options.overwrite);
    io::StudyReport report;
    report.scene_name = scene.name;
    report.scene_file = options.scene.string();
    report.scene_description = scene.description;
    report.refinements = factors;
    report.variants = variants;
    report.chosen_metrics = chosen_metrics;
    report.reference = scene.reference;
    report.reference_source = scene.reference_source;
    // A reference that is not there was a warning above: the study is not compared with it.
    if (!scene.element_reference.empty() && reference_warning.empty()) {
        report.element_reference = io::read_element_reference(scene.element_reference);
    }
    MemoryGauge memory;
    report.memory_note = memory.note();
    if (!options.quiet) {
        fmt::print(stderr, "study of {}: {} cases ({} resolution{}, {} series), output in {}\n",
                   scene.name.empty() ? options.scene.string() : scene.name, plans.size(), factors.size(),
                   factors.size() == 1 ? "" : "s", series_names.size(), folder.partial().string());
        if (factors.size() < 3) fmt::print(stderr, "note: fewer than three resolutions: no orders, no extrapolation\n");
        if (scene.stop.max_steps > 0) {
            fmt::print(stderr, "note: the scene stops after max_steps = {}: finer cases then end at an earlier time, and "
                               "their errors mean little\n",
                       scene.stop.max_steps);
        }
    }

    std::size_t failures = 0;
    for (std::size_t k = 0; k < plans.size(); ++k) {
        const Plan& p = plans[k];
        io::StudyCase c;
        c.variant = variants[p.variant].name;
        c.series = p.series;
        c.refinement = p.refinement;
        c.cell_size = p.cell_size;
        c.threads = p.threads;
        if (!options.quiet) {
            fmt::print(stderr, "[{}/{}] {}, refinement {:g} (cell {:.4g} mm), {} {}\n", k + 1, plans.size(), p.series, p.refinement,
                       p.cell_size * 1e3, p.threads, thread_word(p.threads));
        }
        memory.start_case();
        std::unique_ptr<Simulation> sim;
        const auto start = std::chrono::steady_clock::now();
        try {
            sim = std::make_unique<Simulation>(p.scene, p.threads, options.memory);
            io::RunProbe probe(*sim);
            c.nodes = sim->real_count() + sim->totals().element_nodes;
            c.threads = sim->threads();
            Progress progress(options.quiet || ::isatty(::fileno(stderr)) == 0);  // in place on a terminal, else silent
            const auto loop_start = std::chrono::steady_clock::now();
            try {
                while (!sim->finished()) {
                    sim->step();
                    probe.observe(*sim);
                    progress.update(*sim);
                }
            } catch (...) {
                c.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
                progress.finish(*sim);
                throw;
            }
            c.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_start).count();
            progress.finish(*sim);
            c.finished = true;
            c.message = sim->stop_reason();
            sim->measure_bodies();  // the local peaks (and the bodies' pieces) of the final state
            c.metrics = probe.metrics(*sim);
            c.outline = io::final_outline(*sim);
        } catch (const std::exception& e) {
            c.finished = false;
            c.message = e.what();
            if (c.wall_seconds == 0.0) c.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            ++failures;
        }
        if (sim) {
            c.steps = sim->steps();
            c.simulated_time = sim->time();
            c.mean_time_step = c.steps > 0 ? c.simulated_time / double(c.steps) : nan;
            c.node_steps_per_second = c.wall_seconds > 0.0 ? sim->node_steps() / c.wall_seconds : nan;
        }
        c.peak_bytes = memory.peak();
        c.case_bytes = memory.case_bytes();
        sim.reset();
        report.cases.push_back(c);
        if (!options.quiet) fmt::print(stderr, "  {}\n", case_line(c));
        // The tables so far, so that an interrupted study leaves what it had measured.
        const auto analysis = io::analyse_study(report);
        io::write_study_csv(folder.partial() / "study.csv", report, analysis);
        io::write_study_markdown(folder.partial() / "study.md", report, analysis);
    }

    const auto analysis = io::analyse_study(report);
    const auto plots = io::write_study_plots(folder.partial(), report, analysis);
    folder.commit();
    if (options.reference) {
        // The finest finished case's outline goes with the reference.
        const io::StudyCase* finest = nullptr;
        for (const auto& c : report.cases) {
            if (c.finished && (!finest || c.cell_size < finest->cell_size)) finest = &c;
        }
        // A reference holds every metric the runs produced, whatever --metrics chose to show.
        io::StudyReport whole = report;
        whole.chosen_metrics.clear();
        auto ref = io::reference_from_study(whole, io::analyse_study(whole), series_names.front(),
                                            finest ? finest->outline : decltype(finest->outline){});
        ref.peak_radius = scene.output.peak_radius;
        io::write_element_reference(*options.reference, ref);
        fmt::print("element reference: {} ({} metrics{})\n", options.reference->string(), ref.values.size(),
                   ref.missing.empty() ? "" : fmt::format(", {} without a reference", ref.missing.size()));
    }
    // A metric asked for that no run produced (a crater without a target, a contact time of a
    // body that never left its plane), or that is shown but not analysed: say so.
    for (const auto& key : report.chosen_metrics) {
        if (std::find(analysis.metrics.begin(), analysis.metrics.end(), key) == analysis.metrics.end()) {
            fmt::print(stderr, "note: --metrics {}: no run produced it (docs/study.md says when each metric applies)\n", key);
        } else if (!io::find_study_metric(key)->analysed) {
            fmt::print(stderr, "note: --metrics {}: shown in the tables, not analysed (it is no converging quantity)\n", key);
        }
    }
    if (!options.quiet) print_summary(report, analysis);
    std::string files = "study.md, study.csv";
    for (const auto& p : plots) files += fmt::format(", {}", p.filename().string());
    fmt::print("output: {} ({})\n", folder.final_path().string(), files);
    if (failures > 0) {
        fmt::print(stderr, "gpa: {} of {} cases failed; see {}\n", failures, plans.size(),
                   (folder.final_path() / "study.md").string());
        return 3;
    }
    return 0;
}

}  // namespace gpa::app
