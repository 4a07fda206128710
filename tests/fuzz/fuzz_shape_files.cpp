// libFuzzer target on the readers of the files a body's shape may come from: STL surfaces
// (io/stl.hpp) and CSV node tables (io/node_file.hpp). The same bytes go to both. Each either
// makes a checked surface (whose inside test is then built and asked about a few points, and
// whose enclosed volume is computed) or node set (3D and axisymmetric, whose covered region is
// asked about the same way), or an InputError whose message is one line naming the file; no other
// exception, no crash, no leak, no undefined behaviour (the build has the address and
// undefined-behaviour sanitizers). Run by scripts/sanitize.sh, seeded with tests/fuzz/stl_seeds/
// (binary and ASCII solids, one malformed) and the node tables of tests/io/bad_scenes/nodes/.
//
// No cap on the triangles is needed here: a binary file's count must match its length, so an
// input of n bytes holds fewer than n / 50 triangles (an ASCII facet takes more bytes still), and
// the memory stays linear in the input, which the script bounds with -max_len.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <string_view>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/node_set.hpp"
#include "gpa/engine/surface.hpp"
#include "gpa/io/node_file.hpp"
#include "gpa/io/stl.hpp"

namespace {

// splitmix64: the query points' fractions, a fixed function of the input so that a crash repeats.
std::uint64_t next(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

// An InputError's message must be one line that starts with the file's name.
void check_message(const gpa::InputError& e, const char* name) {
    const std::string message = e.what();
    if (message.find('\n') != std::string::npos || message.find('\r') != std::string::npos || message.rfind(name, 0) != 0) {
        std::fprintf(stderr, "an error that is not one line naming the file %s: %s\n", name, message.c_str());
        std::abort();
    }
}

// The bytes as a CSV node table of a 3D and of an axisymmetric scene; a set that reads is asked
// whether it covers its own nodes (it must) and points beyond its box (it must not).
void read_as_nodes(std::string_view bytes) {
    for (const gpa::GeometryKind g : {gpa::GeometryKind::ThreeD, gpa::GeometryKind::Axisymmetric}) {
        auto set = std::make_shared<gpa::NodeSet>();
        try {
            *set = gpa::io::parse_node_csv(bytes, "fuzz.csv", 1.0, g);
        } catch (const gpa::InputError& e) {
            check_message(e, "fuzz.csv");
            continue;
        }
        const gpa::NodeSetShape shape(set, gpa::dimension_of(g));
        for (std::size_t k = 0; k < shape.size(); k += 1 + shape.size() / 16) {
            if (!shape.covers(set->positions[k])) {
                std::fprintf(stderr, "node %zu of a node set is not in the region it covers\n", k);
                std::abort();
            }
            auto beyond = set->positions[k];
            beyond[0] = shape.upper()[0] + shape.diameter(k);
            if (shape.covers(beyond)) {
                std::fprintf(stderr, "a point beyond a node set's box is covered\n");
                std::abort();
            }
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    read_as_nodes(bytes);
    auto surface = std::make_shared<gpa::TriangleSurface>();
    try {
        // A unit of 1 m: the file's numbers are the metres, so their whole range reaches the
        // inside test (a smaller unit would only shrink it).
        *surface = gpa::io::parse_stl(bytes, "fuzz.stl", 1.0);
    } catch (const gpa::InputError& e) {
        check_message(e, "fuzz.stl");
        return 0;
    }
    volatile double volume = gpa::enclosed_volume(*surface);
    (void)volume;

    // The inside test at points that probe its exact arithmetic: a vertex, the middle of an edge
    // and the centroid of a triangle (on the surface: either answer), the box's centre, and points
    // spread over the box and a quarter of it beyond each side (outside there: must say so).
    const gpa::SurfaceInside inside(surface);
    const auto& lo = inside.lower();
    const auto& hi = inside.upper();
    std::uint64_t state = size;
    for (const char c : bytes) state = (state ^ static_cast<std::uint8_t>(c)) * 0x100000001B3ull;  // FNV-1a
    const auto& tri = surface->triangles[next(state) % surface->triangles.size()];
    const auto& a = surface->vertices[tri[0]];
    const auto& b = surface->vertices[tri[1]];
    const auto& c = surface->vertices[tri[2]];
    std::array<std::array<double, 3>, 12> points{};
    for (int k = 0; k < 3; ++k) {
        points[0][k] = a[k];
        points[1][k] = 0.5 * a[k] + 0.5 * b[k];
        points[2][k] = (a[k] + b[k] + c[k]) / 3.0;
        points[3][k] = 0.5 * lo[k] + 0.5 * hi[k];
    }
    for (std::size_t p = 4; p < points.size(); ++p) {
        for (int k = 0; k < 3; ++k) {
            const double f = -0.25 + 1.5 * static_cast<double>(next(state) >> 11) * 0x1.0p-53;  // in [-0.25, 1.25)
            points[p][k] = lo[k] + f * (hi[k] - lo[k]);
        }
    }
    for (const auto& p : points) {
        const bool in = inside.inside(p);
        const bool beyond = p[0] < lo[0] || p[0] > hi[0] || p[1] < lo[1] || p[1] > hi[1] || p[2] < lo[2] || p[2] > hi[2];
        if (in && beyond) {
            std::fprintf(stderr, "a point outside the surface's box (%g, %g, %g) is inside\n", p[0], p[1], p[2]);
            std::abort();
        }
    }
    return 0;
}
