// gpa: high-velocity impact simulation with the Generalized Particle Algorithm.
//   gpa run [SCENE] [-o DIR] [--threads N] [--overwrite] [--quiet] [--max-memory SIZE]
//   gpa run --resume DIR [--threads N] [--quiet] [--max-memory SIZE]
//   gpa study SCENE [-o DIR] [--refine 1,1.5,2] [--variant NAME:key=value,...]... [--threads 1,2] [--metrics a,b]
//             [--overwrite] [-q]
//             [--reference FILE]
//   gpa check SCENE [--max-memory SIZE]
//   gpa render RUN_DIR [--field NAME[:x|y|z|xx|...]] [-o PNG] [--snapshot N|last | --time T] [--size WxH | --width W]
//              [--range MIN:MAX] [--mirror | --no-mirror] [--view +y] [--region R | --frame run] [--no-failed-marks]
//              [--geometry G] [--list] [-q]
//   gpa materials
//   gpa demo [--threads N] [-o DIR]
//   gpa --version
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "demo.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/engine/version.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/study.hpp"
#include "render.hpp"
#include "run.hpp"
#include "study.hpp"

namespace {

const std::vector<std::string> commands{"run", "study", "check", "render", "materials", "demo"};

// A whole number of threads, 0 (all hardware threads) to 4096; the message names the value.
std::string check_threads(const std::string& text) {
    std::size_t end = 0;
    long value = -1;
    try {
        value = std::stol(text, &end);
    } catch (const std::exception&) {
        end = 0;
    }
    if (end != text.size() || text.empty() || value < 0 || value > 4096) {
        return fmt::format("'{}' is not a thread count: a whole number from 0 (all hardware threads) to 4096", text);
    }
    return {};
}

// A folder name, not an option that lost its value (`-o -q`).
std::string check_folder(const std::string& text) {
    if (text.empty()) return "the folder name is empty";
    if (text[0] == '-') {
        return fmt::format("'{}' is an option, not a folder name (for a folder of that name write ./{})", text, text);
    }
    return {};
}

// "16G", "512M", "1.5GiB", "2000000000": bytes (K, M, G, T with or without iB, powers of 1024).
std::string parse_memory(const std::string& text, std::uint64_t& bytes) {
    std::size_t end = 0;
    double value = -1.0;
    try {
        value = std::stod(text, &end);
    } catch (const std::exception&) {
        end = 0;
    }
    std::string unit = end > 0 ? text.substr(end) : std::string();
    if (!unit.empty() && unit.front() == ' ') unit.erase(0, 1);
    double scale = 0.0;
    for (const auto& [names, s] : std::vector<std::pair<std::vector<std::string>, double>>{
             {{"", "B"}, 1.0}, {{"K", "k", "KiB", "kiB", "KB", "kB"}, 1024.0}, {{"M", "MiB", "MB"}, 1048576.0},
             {{"G", "GiB", "GB"}, 1073741824.0}, {{"T", "TiB", "TB"}, 1099511627776.0}}) {
        for (const auto& n : names) {
            if (unit == n) scale = s;
        }
    }
    const double total = value * scale;
    if (end == 0 || scale == 0.0 || !(total >= 1.0) || !std::isfinite(total) || total > 1.8e19) {
        return fmt::format("'{}' is not a memory size: a positive number with K, M, G or T (powers of 1024), e.g. 16G", text);
    }
    bytes = static_cast<std::uint64_t>(total);
    return {};
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"gpa: high-velocity impact simulation with the Generalized Particle Algorithm "
                 "(Johnson, Beissel and Stryk 2000)"};
    app.require_subcommand(1);
    app.set_version_flag("--version", gpa::build_id(), "print the version, the commit and the build, and exit");

    const auto threads_check = CLI::Validator(check_threads, "THREADS");
    const auto folder_check = CLI::Validator(check_folder, "DIR");
    std::string memory_text;
    const auto memory_check = CLI::Validator(
        [](const std::string& text) {
            std::uint64_t ignored = 0;
            return parse_memory(text, ignored);
        },
        "SIZE");
    const std::string memory_help =
        "memory limit, e.g. 16G or 512M (default: the machine's physical memory): a scene whose nodes or neighbour "
        "lists would need more is refused";

    gpa::app::RunOptions run_options;
    std::string scene, output, resume;
    auto* run = app.add_subcommand("run", "run a scene (without one: the paper's Armco-iron cylinder impact)");
    run->add_option("scene", scene, "scene file (TOML, see docs/scene-format.md)");
    run->add_option("-o,--output", output, "output folder (default: runs/<scene>-<date>-<time>)")->check(folder_check);
    run->add_option("--resume", resume,
                    "continue the interrupted or failed run in this output folder from its last checkpoint")
        ->check(folder_check);
    run->add_option("--threads", run_options.threads, "threads (0 = all hardware threads)")->check(threads_check);
    run->add_flag("--overwrite", run_options.overwrite, "replace an existing output folder when the run ends");
    run->add_flag("-q,--quiet", run_options.quiet, "no progress and no report, only where the output went");
    run->add_option("--max-memory", memory_text, memory_help)->check(memory_check);

    gpa::app::StudyOptions study_options;
    std::string study_scene, study_output;
    auto* study = app.add_subcommand("study", "run a scene over resolutions and method variants: wall time, memory, "
                                              "metrics, discretisation and reference errors (docs/study.md)");
    study->add_option("scene", study_scene, "scene file (TOML)")->required();
    study->add_option("-o,--output", study_output, "output folder (default: studies/<scene>-<date>-<time>)")->check(folder_check);
    study->add_option("--refine", study_options.refine,
                      "refinement factors: every body's spacing is divided by each (default 1,1.5,2)");
    study->add_option("--variant", study_options.variants,
                      "a method variant, NAME or NAME:key=value,...; repeat for more (default: the scene as written). Keys: " +
                          gpa::io::variant_keys_help())
        ->expected(1)
        ->take_all();
    study->add_option("--threads", study_options.threads, "thread counts, e.g. 1,2 (0 = all hardware threads; default 0)");
    study->add_option("--metrics", study_options.metrics,
                      "the metrics to analyse and plot, e.g. crater_depth,residual_velocity (default: every metric the runs produce; "
                      "docs/study.md lists them)");
    study->add_flag("--overwrite", study_options.overwrite, "replace an existing output folder when the study ends");
    std::string study_reference;
    study->add_option("--reference", study_reference,
                      "write the study's series (one series, three or more resolutions) as the scene's element reference "
                      "FILE (docs/validation.md, \"Element references\")");
    study->add_flag("-q,--quiet", study_options.quiet, "no progress and no summary, only where the output went");
    study->add_option("--max-memory", memory_text, memory_help)->check(memory_check);

    std::string check_file;
    auto* check = app.add_subcommand("check", "read and check a scene without running it");
    check->add_option("scene", check_file, "scene file")->required();
    check->add_option("--max-memory", memory_text, memory_help)->check(memory_check);

    gpa::app::RenderCommandOptions render_options;
    std::string render_target, render_output;
    auto* render = app.add_subcommand("render", "a PNG picture of a snapshot of a run coloured by a field (docs/render.md)");
    render->add_option("RUN_DIR", render_target, "the run's output folder (or its .pvd file)")->required();
    render->add_option("-f,--field", render_options.field,
                       "the field to colour by; a vector's magnitude, or one component as velocity:z (default velocity; "
                       "--list shows the fields)");
    render->add_option("-o,--output", render_output, "the PNG file, or a folder for it (default: RUN/<field>-<snapshot>.png)");
    auto* render_snapshot = render->add_option("--snapshot", render_options.snapshot,
                                               "the snapshot: its number in the .pvd (from 0) or last (default last)");
    render->add_option("--time", render_options.time, "the snapshot nearest to this time, e.g. 40us (plain numbers in s)")
        ->excludes(render_snapshot);
    auto* render_size = render->add_option("--size", render_options.size, "picture size WIDTHxHEIGHT in pixels, e.g. 1200x900");
    render->add_option("--width", render_options.width,
                       "picture width in pixels; the height follows the scene's proportions (default 800)")
        ->excludes(render_size);
    render->add_option("--range", render_options.range,
                       "colour range MIN:MAX in SI units or with a unit (2GPa:5GPa); either end may be left out (default the "
                       "field's own minimum and maximum)");
    auto* render_mirror = render->add_flag("--mirror", render_options.mirror, "2D: mirror about x = 0 (default for axisymmetric runs)");
    render->add_flag("--no-mirror", render_options.no_mirror, "2D: do not mirror an axisymmetric run")->excludes(render_mirror);
    render->add_option("--view", render_options.view,
                       "3D: the direction the picture looks along, +x, -x, +y, -y, +z or -z (default +y: x right, z up)");
    auto* render_region = render->add_option("--region", render_options.region,
                       "draw only this window, LEFT:RIGHT,BOTTOM:TOP in the picture's axes (2D: x and z), e.g. -30mm:30mm,-10mm:20mm "
                       "(plain numbers in m)");
    render->add_option("--frame", render_options.frame,
                       "snapshot (default: the drawing fits the snapshot) or run (one frame that holds every snapshot of the run, "
                       "so that motion shows)")
        ->excludes(render_region);
    render->add_flag("--no-failed-marks", render_options.no_failed_marks, "no black dot on failed nodes and cells");
    render->add_option("--geometry", render_options.geometry,
                       "axisymmetric, plane-strain or 3d (default: the run's scene.toml or summary.json)");
    render->add_flag("--list", render_options.list, "list the snapshots and the fields of the chosen one, and draw nothing");
    render->add_flag("-q,--quiet", render_options.quiet, "print nothing when the picture is written");

    std::vector<std::string> material_names;
    auto* materials = app.add_subcommand("materials", "list the built-in material library, or print every constant of the named materials");
    materials->add_option("names", material_names,
                          "materials to print in full, as [[material]] tables a scene can use (letter case ignored)");

    int demo_threads = 0;
    std::string demo_output;
    auto* demo = app.add_subcommand("demo", "demonstrate the engine's kernels on lattices");
    demo->add_option("--threads", demo_threads, "threads (0 = all hardware threads)")->check(threads_check);
    demo->add_option("-o,--output", demo_output, "folder for a ParaView snapshot of the demonstration lattice")->check(folder_check);

    // A first word that is neither an option nor a command is named (CLI11 would only say that
    // a subcommand is required).
    if (argc > 1 && argv[1][0] != '-' && std::find(commands.begin(), commands.end(), argv[1]) == commands.end()) {
        fmt::print(stderr, "gpa: unknown command '{}'; the commands are run, study, check, render, materials and demo (gpa --help)\n",
                   argv[1]);
        return 2;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line, exit 2, like every other refusal.
        fmt::print(stderr, "gpa: {} (gpa --help)\n", e.what());
        return 2;
    }
    gpa::MemoryLimit memory;
    if (!memory_text.empty()) {
        parse_memory(memory_text, memory.bytes);
        memory.source = "--max-memory " + memory_text;
    }
    try {
        if (run->parsed()) {
            if (!scene.empty()) run_options.scene = scene;
            if (!output.empty()) run_options.output = output;
            if (!resume.empty()) run_options.resume = resume;
            run_options.memory = memory;
            return gpa::app::run_scene(run_options);
        }
        if (study->parsed()) {
            study_options.scene = study_scene;
            if (!study_output.empty()) study_options.output = study_output;
            if (!study_reference.empty()) study_options.reference = study_reference;
            study_options.memory = memory;
            return gpa::app::run_study(study_options);
        }
        if (check->parsed()) return gpa::app::check_scene(check_file, memory);
        if (render->parsed()) {
            render_options.run = render_target;
            if (!render_output.empty()) render_options.output = render_output;
            return gpa::app::render_run(render_options);
        }
        if (materials->parsed()) return gpa::app::list_materials(material_names);
        return gpa::app::run_demo(demo_threads, demo_output);
    } catch (const gpa::InputError& e) {
        fmt::print(stderr, "gpa: {}\n", e.what());
        return 2;
    } catch (const gpa::LimitError& e) {
        fmt::print(stderr, "gpa: refused: {}\n", e.what());
        return 2;
    } catch (const gpa::io::OutputError& e) {
        fmt::print(stderr, "gpa: {}\n", e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr, "gpa: out of memory (set a limit with --max-memory to have such a scene refused before it starts)\n");
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa: error: {}\n", e.what());
        return 1;
    }
}
