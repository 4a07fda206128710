// libFuzzer target on the scene reader: any bytes either make a Scene (which the engine then
// sets up within a small memory limit) or a SceneError whose message is one line; no other
// exception, no crash, no leak, no undefined behaviour (the build has the address and
// undefined-behaviour sanitizers). Run by scripts/sanitize.sh, seeded with scenes/ and the
// malformed-scene corpus tests/io/bad_scenes/.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    gpa::Scene scene;
    try {
        scene = gpa::io::parse_scene(text, "fuzz.toml");
    } catch (const gpa::io::SceneError& e) {
        const std::string message = e.what();
        if (message.find('\n') != std::string::npos || message.rfind("fuzz.toml", 0) != 0) {
            std::fprintf(stderr, "a scene error that is not one line naming the file: %s\n", message.c_str());
            std::abort();
        }
        return 0;
    }
    // A scene that reads: its set-up, with at most about ten thousand nodes (16 MiB).
    try {
        gpa::Simulation sim(scene, 1, gpa::MemoryLimit{16u << 20, "the fuzz target's limit"});
    } catch (const gpa::InputError&) {
    } catch (const gpa::LimitError&) {
    }
    return 0;
}
