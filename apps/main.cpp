// gpa: the command-line program.
#include <exception>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "demo.hpp"

int main(int argc, char** argv) {
    CLI::App app{"gpa: high-velocity impact simulation with the Generalized Particle Algorithm"};
    app.require_subcommand(0, 1);
    int threads = 0;
    std::string output;
    auto* demo = app.add_subcommand("demo", "run the built-in demonstration of the engine kernels (the default)");
    demo->add_option("--threads", threads, "threads to use (0 = all hardware threads)")->check(CLI::Range(0, 4096));
    demo->add_option("-o,--output", output, "folder for a ParaView snapshot of the demonstration lattice");
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }
    try {
        return gpa::app::run_demo(threads, output);
    } catch (const std::exception& e) {
        fmt::print(stderr, "gpa: error: {}\n", e.what());
        return 1;
    }
}
