// gpa: high-velocity impact simulation with the Generalized Particle Algorithm.
//   gpa run [SCENE] [-o DIR] [--threads N] [--overwrite] [--quiet]
//   gpa study SCENE [-o DIR] [--refine 1,1.5,2] [--variant NAME:key=value,...]... [--threads 1,2] [--overwrite] [-q]
//   gpa check SCENE
//   gpa materials
//   gpa demo [--threads N] [-o DIR]
#include <exception>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "demo.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/study.hpp"
#include "run.hpp"
#include "study.hpp"

int main(int argc, char** argv) {
    CLI::App app{"gpa: high-velocity impact simulation with the Generalized Particle Algorithm "
                 "(Johnson, Beissel and Stryk 2000)"};
    app.require_subcommand(1);

    gpa::app::RunOptions run_options;
    std::string scene, output;
    auto* run = app.add_subcommand("run", "run a scene (without one: the paper's Armco-iron cylinder impact)");
    run->add_option("scene", scene, "scene file (TOML, see docs/scene-format.md)");
    run->add_option("-o,--output", output, "output folder (default: runs/<scene>-<date>-<time>)");
    run->add_option("--threads", run_options.threads, "threads (0 = all hardware threads)")->check(CLI::Range(0, 4096));
    run->add_flag("--overwrite", run_options.overwrite, "replace an existing output folder when the run ends");
    run->add_flag("-q,--quiet", run_options.quiet, "no progress and no report, only where the output went");

    gpa::app::StudyOptions study_options;
    std::string study_scene, study_output;
    auto* study = app.add_subcommand("study", "run a scene over resolutions and method variants: wall time, memory, "
                                              "metrics, discretisation and reference errors (docs/study.md)");
    study->add_option("scene", study_scene, "scene file (TOML)")->required();
    study->add_option("-o,--output", study_output, "output folder (default: studies/<scene>-<date>-<time>)");
    study->add_option("--refine", study_options.refine,
                      "refinement factors: every body's spacing is divided by each (default 1,1.5,2)");
    study->add_option("--variant", study_options.variants,
                      "a method variant, NAME or NAME:key=value,...; repeat for more (default: the scene as written). Keys: " +
                          gpa::io::variant_keys_help())
        ->expected(1)
        ->take_all();
    study->add_option("--threads", study_options.threads, "thread counts, e.g. 1,2 (0 = all hardware threads; default 0)");
    study->add_flag("--overwrite", study_options.overwrite, "replace an existing output folder when the study ends");
    study->add_flag("-q,--quiet", study_options.quiet, "no progress and no summary, only where the output went");

    std::string check_file;
    auto* check = app.add_subcommand("check", "read and check a scene without running it");
    check->add_option("scene", check_file, "scene file")->required();

    auto* materials = app.add_subcommand("materials", "list the built-in material library");

    int demo_threads = 0;
    std::string demo_output;
    auto* demo = app.add_subcommand("demo", "demonstrate the engine's kernels on lattices");
    demo->add_option("--threads", demo_threads, "threads (0 = all hardware threads)")->check(CLI::Range(0, 4096));
    demo->add_option("-o,--output", demo_output, "folder for a ParaView snapshot of the demonstration lattice");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    try {
        if (run->parsed()) {
            if (!scene.empty()) run_options.scene = scene;
            if (!output.empty()) run_options.output = output;
            return gpa::app::run_scene(run_options);
        }
        if (study->parsed()) {
            study_options.scene = study_scene;
            if (!study_output.empty()) study_options.output = study_output;
            return gpa::app::run_study(study_options);
        }
        if (check->parsed()) return gpa::app::check_scene(check_file);
        if (materials->parsed()) return gpa::app::list_materials();
        return gpa::app::run_demo(demo_threads, demo_output);
    } catch (const gpa::InputError& e) {
        fmt::print(stderr, "gpa: {}\n", e.what());
        return 2;
    } catch (const gpa::io::OutputError& e) {
        fmt::print(stderr, "gpa: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa: error: {}\n", e.what());
        return 1;
    }
}
