#include "run.hpp"

#include <algorithm>
#include <csignal>
#include <ctime>
#include <string_view>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/run_loop.hpp"
#include "gpa/io/scene_file.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace gpa::app {

std::string_view default_scene_text();  // scenes/armco-cylinder-nodal.toml, embedded at build time

namespace {

namespace fs = std::filesystem;

// The file the built-in default scene was embedded from: the files it names (its element
// reference) are found beside it, in the source tree the program was built from.
const fs::path default_scene_file{GPA_DEFAULT_SCENE_FILE};
constexpr const char* builtin_label = "(built-in default)";  // the summary's scene_file of the built-in scene

io::SceneSource read_source(const std::optional<fs::path>& file) {
    if (file) return io::SceneSource::from_file(*file);
    return {std::string(default_scene_text()), "built-in default scene (scenes/armco-cylinder-nodal.toml)", builtin_label,
            default_scene_file};
}

// What `gpa run` prints and returns once the run loop has returned: the report and where the
// outputs are; or why it stopped, and how to go on.
int report(const RunOptions& options, const io::RunLoop& run, const io::RunResult& result) {
    const Simulation& sim = run.simulation();
    switch (result.status) {
    case io::RunStatus::Finished:
        if (!options.quiet) {
            const Scene& scene = sim.scene();
            fmt::print("{}\n", scene.name.empty() ? "run finished" : scene.name);
            fmt::print("{}", io::run_report(sim));
            fmt::print("  wall time {:.1f} s on {} thread{}\n", result.wall_seconds, sim.threads(), sim.threads() == 1 ? "" : "s");
        }
        fmt::print("output: {} (open particles.pvd in ParaView; history.csv, summary.json)\n", result.folder.string());
        return 0;
    case io::RunStatus::Interrupted: {
        const char* name = result.stop_code == SIGTERM ? "SIGTERM" : "SIGINT";
        const std::string next = !result.problems.empty()
                                     ? fmt::format(", and saving it failed: {}", result.problems)
                                     : fmt::format("; resume it with: gpa run --resume {}", run.final_folder().string());
        fmt::print(stderr, "gpa: the run was stopped by {} after step {} at t = {:.4g} us{}\n", name, sim.steps(), sim.time() * 1e6, next);
        return 128 + result.stop_code;
    }
    case io::RunStatus::Failed:
        fmt::print(stderr, "gpa: the run failed: {}{}; what was written is in {}{}\n", result.message, result.problems,
                   result.folder.string(),
                   result.resumable ? fmt::format(" (gpa run --resume {} continues it from its last checkpoint)", run.final_folder().string())
                                    : "");
        return 3;
    }
    return 1;
}

// The program's side of a run: warnings through the log, progress on the terminal, SIGINT and
// SIGTERM as stop requests.
int run_in_loop(const RunOptions& options, io::RunLoop& run) {
    Progress progress(options.quiet);
    StopRequests signals;
    io::RunHooks hooks;
    hooks.progress = [&](const Simulation& sim, bool last) {
        if (last) progress.finish(sim);
        else progress.update(sim);
    };
    if (options.quiet) hooks.step_warning = [](const std::string&) {};
    hooks.stop_requested = [] {
        const int signo = StopRequests::requested();
        return io::StopRequest{signo, signo == SIGTERM ? "SIGTERM" : "SIGINT"};
    };
    const io::RunResult result = run.run(hooks);
    return report(options, run, result);
}

io::RunSettings settings_of(const RunOptions& options) {
    io::RunSettings settings;
    settings.overwrite = options.overwrite;
    settings.threads = options.threads;
    settings.memory = options.memory;
    // Set-up warnings whatever --quiet (a missing reference file, implausible values); those of
    // the steps (collapsed lattice cells) only without it (run_in_loop).
    settings.warning = [](const std::string& message) { spdlog::warn("{}", message); };
    return settings;
}

int fresh_run(const RunOptions& options) {
    io::SceneSource source = read_source(options.scene);
    io::RunSettings settings = settings_of(options);
    if (options.output) {
        settings.output = *options.output;
    } else {
        // The folder is named after the scene: its name is read first (the loop reads it again).
        settings.output = default_output_folder("runs", io::parse_scene(source.text, source.name).name);
    }
    io::RunLoop run(std::move(source), std::move(settings));
    const Simulation& sim = run.simulation();
    if (!options.quiet) {
        spdlog::info("{}: {} nodes, {} thread{}, output in {}", run.scene().name.empty() ? "scene" : run.scene().name, sim.real_count(),
                     sim.threads(), sim.threads() == 1 ? "" : "s", run.partial_folder().string());
    }
    return run_in_loop(options, run);
}

int resumed_run(const RunOptions& options) {
    if (options.output) throw io::OutputError("--resume continues a run in its own folder: give the folder to --resume, not -o");
    std::optional<io::SceneSource> given;
    if (options.scene) given = read_source(options.scene);
    auto run = io::RunLoop::resume(*options.resume, std::move(given), settings_of(options));
    const Simulation& sim = run->simulation();
    if (!options.quiet) {
        spdlog::info("{}: resuming at step {} (t = {:.4g} us), {} nodes, {} thread{}, output in {}", run->scene().name, sim.steps(),
                     sim.time() * 1e6, sim.real_count(), sim.threads(), sim.threads() == 1 ? "" : "s", run->partial_folder().string());
    }
    return run_in_loop(options, *run);
}

}  // namespace

int run_scene(const RunOptions& options) { return options.resume ? resumed_run(options) : fresh_run(options); }

fs::path default_output_folder(const std::string& root, const std::string& scene_name) {
    std::string slug;
    for (char c : scene_name) slug += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
    if (slug.empty()) slug = "scene";
    const std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
    return fs::path(root) / fmt::format("{}-{}", slug, stamp);
}

int check_scene(const fs::path& file, const MemoryLimit& memory) {
    std::string warning;
    const Scene scene = io::load_scene(file, &warning, memory);
    // Implausible values first: a unit slip in a size may make the set-up below refuse the scene
    // for its memory, and the user should see why.
    log_scene_warnings(scene, file.string());
    Simulation sim(scene, 1, memory);  // builds the nodes: every check of set-up runs
    // Each gauge placed as the run will place it (a gauge with no node to read is refused here).
    std::vector<Gauge> gauges;
    for (const auto& spec : scene.gauges) gauges.emplace_back(spec, scene, sim.nodes(), sim.real_count());
    fmt::print("{}: OK\n", file.string());
    fmt::print("  {} ({}), {} bod{}, {} real nodes, {} ghost nodes at the start\n", scene.name, name_of(scene.geometry),
               scene.bodies.size(), scene.bodies.size() == 1 ? "y" : "ies", sim.real_count(), sim.totals().ghost_nodes);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (const BodySpec& spec = scene.bodies[b]; spec.shape == ShapeKind::Nodes) {
            const NodeSetShape& set = *spec.node_set;
            double smallest = set.diameter(0), largest = smallest;
            for (std::size_t k = 0; k < set.size(); ++k) {
                smallest = std::min(smallest, set.diameter(k));
                largest = std::max(largest, set.diameter(k));
            }
            fmt::print("  body \"{}\": {}, {} imported nodes (from {}), diameters {:.4g} to {:.4g} mm, median {:.4g} mm\n",
                       spec.name, spec.material, set.size(), spec.surface_file, smallest * 1e3, largest * 1e3,
                       set.typical_diameter() * 1e3);
            continue;
        }
        std::size_t count = 0;
        for (std::size_t i = 0; i < sim.real_count(); ++i) count += sim.nodes().body[i] == static_cast<int>(b);
        if (const BodySpec& spec = scene.bodies[b];
            spec.discretisation == Discretisation::Particles && dimension_of(scene.geometry) == 3 && cell_fill(spec, scene.geometry) == CellFill::Rings) {
            fmt::print("  body \"{}\": {}, {} nodes in rings about its axis, spacing {:.4g} mm\n", spec.name, spec.material, count,
                       spec.spacing * 1e3);
            continue;
        }
        const auto block = body_lattice(scene, b);
        std::string elements;
        if (const ElementPart* e = sim.elements(); e && scene.bodies[b].discretisation == Discretisation::Elements) {
            count = static_cast<std::size_t>(std::count(e->mesh().nodes.body.begin(), e->mesh().nodes.body.end(), static_cast<int>(b)));
            elements = fmt::format(" ({} elements)", std::count(e->mesh().quads.body.begin(), e->mesh().quads.body.end(), static_cast<int>(b)));
        }
        // Every axis's spacing: x, z in 2D; x, y, z in 3D.
        std::vector<std::string> spacing;
        for (int c = 0; c < dimension_of(scene.geometry); ++c) spacing.push_back(fmt::format("{:.4g}", block.spacing[c] * 1e3));
        const bool trimmed = elements.empty() && block.trim;
        fmt::print("  body \"{}\": {}, {} nodes{}, lattice spacing {} mm{}\n", scene.bodies[b].name, scene.bodies[b].material, count,
                   elements, fmt::join(spacing, " x "), trimmed ? ", cells trimmed to the surface" : "");
    }
    // A material derived with `base`: what it changes, constant by constant.
    for (const auto& material : scene.materials) {
        if (material.base.empty()) continue;
        const materials::Material* base = nullptr;
        for (const auto& other : scene.materials) {
            if (&other != &material && other.name == material.base) base = &other;
        }
        if (!base) base = io::find_builtin_material(material.base);
        if (!base) continue;  // (the reader found it; a scene made in code may name anything)
        const auto changes = io::material_changes(material, *base);
        fmt::print("  material \"{}\": base \"{}\"{}{}\n", material.name, base->name,
                   changes.empty() ? " unchanged" : ", with ", fmt::join(changes, ", "));
    }
    for (std::size_t k = 0; k < scene.prescribed_velocities.size(); ++k) {
        const auto& r = scene.prescribed_velocities[k];
        std::string held;
        const int dim = dimension_of(scene.geometry);
        for (int c = 0; c < dim; ++c) {
            if (r.velocity[c]) held += fmt::format("{}{} = {:g} m/s", held.empty() ? "" : ", ", axis_letter(c, dim), *r.velocity[c]);
        }
        fmt::print("  prescribed velocity \"{}\": {} nodes of body \"{}\" at {}{}\n", r.name, sim.totals().regions[k].nodes, r.body, held,
                   r.ramp > 0.0 ? fmt::format(" after a {:.4g} us ramp", r.ramp * 1e6) : std::string());
    }
    // The gauges and their nodes.
    for (const Gauge& gauge : gauges) {
        const GaugeSpec& spec = gauge.spec();
        const auto& ids = gauge.node_ids();
        const std::string listed = ids.size() <= 8 ? fmt::format("{}", fmt::join(ids, ", "))
                                                   : fmt::format("{}, ... {}", fmt::join(ids.begin(), ids.begin() + 4, ", "), ids.back());
        fmt::print("  gauge \"{}\": {} node{} (id{} {}), {} columns in {}\n", spec.name, ids.size(), ids.size() == 1 ? "" : "s",
                   ids.size() == 1 ? "" : "s", listed, gauge.columns().size() + 2, io::GaugeWriter::file_name(spec.name));
    }
    fmt::print("  first time step {:.3g} ns; phases: {}\n", sim.next_time_step() * 1e9, fmt::join(sim.phases(), ", "));
    if (!warning.empty()) fmt::print("  warning: {}\n", warning);
    return 0;
}

namespace {

std::string eos_summary(const materials::EquationOfState& eos) {
    if (const auto* linear = std::get_if<materials::LinearEos>(&eos)) {
        return fmt::format("linear EOS K {:.4g} GPa{}", linear->bulk_modulus / 1e9, linear->logarithmic ? " (logarithmic)" : "");
    }
    if (const auto* poly = std::get_if<materials::PolynomialEos>(&eos)) {
        return fmt::format("polynomial EOS K1 {:.4g} GPa, Gamma0 {}", poly->k1 / 1e9, poly->gruneisen);
    }
    if (const auto* mg = std::get_if<materials::MieGruneisenEos>(&eos)) {
        return fmt::format("Mie-Grueneisen EOS c0 {} m/s, s {}, Gamma0 {}", mg->sound_speed, mg->slope, mg->gruneisen);
    }
    return "an equation of state";
}

std::string failure_summary(const materials::Failure& f) {
    std::string out;
    if (f.johnson_cook) {
        out = fmt::format("Johnson-Cook fracture D1-D5 {}, {}, {}, {}, {}", f.johnson_cook->d1, f.johnson_cook->d2, f.johnson_cook->d3,
                          f.johnson_cook->d4, f.johnson_cook->d5);
    }
    if (f.spall_pressure) out += fmt::format("{}spall at {:.4g} GPa", out.empty() ? "" : "; ", *f.spall_pressure / 1e9);
    return out.empty() ? "no failure model" : out;
}

}  // namespace

void log_scene_warnings(const Scene& scene, std::string_view label) {
    for (const std::string& odd : scene_warnings(scene)) spdlog::warn("{}: {}", label, odd);
}

int list_materials(const std::vector<std::string>& names) {
    if (!names.empty()) {
        // Every name is checked before anything is printed.
        std::vector<const materials::Material*> chosen;
        for (const auto& name : names) chosen.push_back(&io::builtin_material(name));
        for (std::size_t k = 0; k < chosen.size(); ++k) {
            fmt::print("{}# {}: built-in material (materials/data/library.toml). A scene uses it by name, derives from it\n"
                       "# with base = \"{}\" and changes only what differs, or copies this table and edits it.\n{}",
                       k > 0 ? "\n" : "", chosen[k]->name, chosen[k]->name, io::material_as_toml(*chosen[k]));
        }
        return 0;
    }
    for (const auto& m : io::builtin_materials()) {
        fmt::print("{}\n  density {} kg/m^3, shear modulus {:.4g} GPa, specific heat {} J/(kg K), melt {} K\n", m.name,
                   m.density, m.shear_modulus / 1e9, m.specific_heat, m.melt_temperature);
        if (const auto* jc = std::get_if<materials::JohnsonCookStrength>(&m.strength)) {
            fmt::print("  Johnson-Cook A {:.4g} MPa, B {:.4g} MPa, n {}, C {}, m {}\n", jc->a / 1e6, jc->b / 1e6, jc->n, jc->c, jc->m);
        }
        fmt::print("  {}; {}\n", eos_summary(m.eos), failure_summary(m.failure));
        fmt::print("  source: {}\n", m.source);
    }
    fmt::print("\nEvery constant of one, as a table a scene can use: gpa materials \"NAME\"\n");
    return 0;
}

}  // namespace gpa::app
