// gpa as a library in ten lines: runs a scene file to its end, writing what `gpa run` writes,
// and prints the report `gpa run` prints.   usage: run_scene SCENE.toml OUTPUT_FOLDER
#include <cstdio>
#include <exception>

#include "gpa/io/run_loop.hpp"

int main(int argc, char** argv) {
    if (argc != 3) return std::fprintf(stderr, "usage: run_scene SCENE.toml OUTPUT_FOLDER\n"), 2;
    try {
        gpa::io::RunSettings settings;
        settings.output = argv[2];
        settings.overwrite = true;
        gpa::io::RunLoop run(gpa::io::SceneSource::from_file(argv[1]), settings);
        const gpa::io::RunResult result = run.run();
        std::printf("%s: %s\n%s", run.scene().name.c_str(), result.message.c_str(), gpa::io::run_report(run.simulation()).c_str());
        return result.status == gpa::io::RunStatus::Finished ? 0 : 3;
    } catch (const std::exception& e) {  // a bad scene, a folder in use, no room: the same messages as gpa run
        return std::fprintf(stderr, "run_scene: %s\n", e.what()), 2;
    }
}
