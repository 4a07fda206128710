#include "gpa/io/stl.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string_view>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa::io {

namespace {

// Collects corners into shared vertices (exact coordinates), scaled to metres.
class SurfaceBuilder {
public:
    SurfaceBuilder(double unit, std::string what) : unit_(unit), what_(std::move(what)) {}
    void add(const std::array<std::array<double, 3>, 3>& corners) {
        if (surface_.triangles.size() >= max_stl_triangles) {
            throw InputError(fmt::format("{}: more than {} triangles", what_, max_stl_triangles));
        }
        std::array<std::uint32_t, 3> tri{};
        for (int k = 0; k < 3; ++k) {
            const auto& c = corners[static_cast<std::size_t>(k)];
            const auto [it, added] = index_.try_emplace(c, static_cast<std::uint32_t>(surface_.vertices.size()));
            if (added) surface_.vertices.push_back({c[0] * unit_, c[1] * unit_, c[2] * unit_});
            tri[static_cast<std::size_t>(k)] = it->second;
        }
        surface_.triangles.push_back(tri);
    }
    TriangleSurface finish() {
        check_surface(surface_, what_);
        return std::move(surface_);
    }

private:
    double unit_;
    std::string what_;
    TriangleSurface surface_;
    std::map<std::array<double, 3>, std::uint32_t> index_;
};

void read_binary(const std::string& bytes, SurfaceBuilder& out, const std::string& what) {
    std::uint32_t count = 0;
    std::memcpy(&count, bytes.data() + 80, 4);
    for (std::size_t t = 0; t < count; ++t) {
        const char* record = bytes.data() + 84 + 50 * t;
        std::array<std::array<double, 3>, 3> corners{};
        for (int k = 0; k < 3; ++k) {
            for (int c = 0; c < 3; ++c) {
                float v = 0.0f;
                std::memcpy(&v, record + 12 + 12 * k + 4 * c, 4);
                if (!std::isfinite(v)) throw InputError(fmt::format("{}: triangle {} has a coordinate that is not finite", what, t));
                corners[static_cast<std::size_t>(k)][static_cast<std::size_t>(c)] = static_cast<double>(v);
            }
        }
        out.add(corners);
    }
}

void read_ascii(const std::string& text, SurfaceBuilder& out, const std::string& what) {
    std::istringstream in(text);
    std::string line;
    std::size_t line_number = 0;
    std::array<std::array<double, 3>, 3> corners{};
    int corner = -1;  // -1: outside a loop
    bool ended = false;
    const auto fail = [&](const std::string& why) { throw InputError(fmt::format("{}:{}: {}", what, line_number, why)); };
    while (std::getline(in, line)) {
        ++line_number;
        std::istringstream words(line);
        std::string word;
        if (!(words >> word)) continue;
        if (word == "solid" || word == "facet" || word == "endfacet") continue;
        if (word == "endsolid") {
            ended = true;
            continue;
        }
        if (word == "outer") {
            if (corner != -1) fail("\"outer loop\" inside a loop");
            corner = 0;
        } else if (word == "vertex") {
            if (corner < 0 || corner > 2) fail(corner < 0 ? "a vertex outside \"outer loop\"" : "a facet with more than three vertices");
            auto& c = corners[static_cast<std::size_t>(corner)];
            for (int k = 0; k < 3; ++k) {
                std::string number;
                if (!(words >> number)) fail("a vertex needs three coordinates");
                try {
                    std::size_t used = 0;
                    c[static_cast<std::size_t>(k)] = std::stod(number, &used);
                    if (used != number.size() || !std::isfinite(c[static_cast<std::size_t>(k)])) throw std::invalid_argument(number);
                } catch (const std::exception&) {
                    fail(fmt::format("\"{}\" is not a finite number", number));
                }
            }
            ++corner;
        } else if (word == "endloop") {
            if (corner != 3) fail(fmt::format("a facet with {} vertices: each needs three", std::max(corner, 0)));
            out.add(corners);
            corner = -1;
        } else {
            fail(fmt::format("\"{}\" is not a word of an ASCII STL file (solid, facet, outer loop, vertex, endloop, endfacet, "
                             "endsolid)", word));
        }
    }
    if (corner != -1) fail("the file ends inside a facet");
    if (!ended) throw InputError(fmt::format("{}: no \"endsolid\": the file is cut short", what));
}

}  // namespace

TriangleSurface read_stl(const std::filesystem::path& file, double unit) {
    const std::string what = file.string();
    if (!(unit > 0.0) || !std::isfinite(unit)) throw InputError(fmt::format("{}: its unit {} m must be a positive length", what, unit));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such STL file", what));
    const auto size = std::filesystem::file_size(file, ec);
    if (ec || size > 84 + 50 * std::uint64_t(max_stl_triangles) + 1) {
        throw InputError(fmt::format("{}: {} (an STL file holds at most {} triangles)", what, ec ? "cannot be read" : "is too large",
                                     max_stl_triangles));
    }
    std::ifstream in(file, std::ios::binary);
    std::string bytes(static_cast<std::size_t>(size), '\0');
    if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) throw InputError(fmt::format("{}: cannot be read", what));
    SurfaceBuilder out(unit, what);
    std::uint32_t count = 0;
    if (size >= 84) std::memcpy(&count, bytes.data() + 80, 4);
    if (size >= 84 && size == 84 + 50 * std::uint64_t(count)) {
        read_binary(bytes, out, what);
    } else if (bytes.rfind("solid", 0) == 0 && bytes.find('\0') == std::string::npos) {  // text (a binary file has zeros)
        read_ascii(bytes, out, what);
    } else if (size >= 84) {
        throw InputError(fmt::format("{}: a binary STL file of {} triangles is {} bytes long, this one {} (cut short or not an "
                                     "STL file)", what, count, 84 + 50 * std::uint64_t(count), size));
    } else {
        throw InputError(fmt::format("{}: not an STL file (too short for a binary one, and no \"solid\" for an ASCII one)", what));
    }
    return out.finish();
}

}  // namespace gpa::io
