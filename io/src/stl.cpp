#include "gpa/io/stl.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
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

void read_binary(std::string_view bytes, SurfaceBuilder& out, const std::string& what) {
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

// ASCII STL read as words (any whitespace, CR or LF line ends): "solid [name]" up to its line's
// end, then per facet "facet normal nx ny nz", "outer loop", three "vertex x y z", "endloop",
// "endfacet", and "endsolid [name]" (another solid may follow). Messages give the line.
void read_ascii(std::string_view text, SurfaceBuilder& out, const std::string& what) {
    std::size_t at = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0, line = 1;
    const auto fail = [&](const std::string& why) { throw InputError(fmt::format("{}:{}: {}", what, line, why)); };
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; };
    // The next word ("" at the end), counting the lines passed.
    const auto word = [&]() -> std::string_view {
        while (at < text.size() && space(text[at])) {
            if (text[at] == '\n' || (text[at] == '\r' && (at + 1 >= text.size() || text[at + 1] != '\n'))) ++line;
            ++at;
        }
        const std::size_t start = at;
        while (at < text.size() && !space(text[at])) ++at;
        return text.substr(start, at - start);
    };
    const auto rest_of_line = [&] {
        while (at < text.size() && text[at] != '\n' && text[at] != '\r') ++at;
    };
    const auto expect = [&](std::string_view wanted, std::string_view context) {
        const std::string_view w = word();
        if (w != wanted) fail(fmt::format("\"{}\" where {} needs \"{}\"", w.empty() ? "the end of the file" : std::string(w), context, wanted));
    };
    const auto number = [&]() {
        const std::string w(word());
        char* end = nullptr;
        const double v = w.empty() ? NAN : std::strtod(w.c_str(), &end);  // (subnormal values are kept)
        if (w.empty() || end != w.c_str() + w.size() || !std::isfinite(v)) {
            fail(fmt::format("\"{}\" is not a finite number", w.empty() ? "the end of the file" : w));
        }
        return v;
    };
    bool in_solid = false;
    for (std::string_view w = word(); !w.empty(); w = word()) {
        if (w == "solid" && !in_solid) {
            rest_of_line();  // its name
            in_solid = true;
        } else if (w == "endsolid" && in_solid) {
            rest_of_line();
            in_solid = false;
        } else if (w == "facet" && in_solid) {
            expect("normal", "a facet");
            for (int k = 0; k < 3; ++k) (void)number();
            expect("outer", "a facet");
            expect("loop", "a facet");
            std::array<std::array<double, 3>, 3> corners{};
            for (auto& c : corners) {
                expect("vertex", "a facet's loop of three vertices");
                for (double& x : c) x = number();
            }
            expect("endloop", "a facet's loop of three vertices");
            expect("endfacet", "a facet");
            out.add(corners);
        } else {
            fail(fmt::format("\"{}\" {}", w, in_solid ? "where a facet or \"endsolid\" belongs" : "where \"solid\" belongs"));
        }
    }
    if (in_solid) throw InputError(fmt::format("{}: no \"endsolid\": the file is cut short", what));
}

// The largest file either form may be: a binary one of max_stl_triangles triangles (and a byte to spare).
constexpr std::uint64_t max_stl_bytes = 84 + 50 * std::uint64_t(max_stl_triangles) + 1;

std::string too_large(const std::string& what) {
    return fmt::format("{}: is too large (an STL file holds at most {} triangles)", what, max_stl_triangles);
}

}  // namespace

TriangleSurface read_stl(const std::filesystem::path& file, double unit, const MemoryLimit& memory) {
    const std::string what = file.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such STL file", what));
    // The size before reading, so that a huge file is refused without reading it.
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw InputError(fmt::format("{}: cannot be read", what));
    if (size > max_stl_bytes) throw InputError(too_large(what));
    const double triangles = static_cast<double>(size) / 50.0;
    const double need = static_cast<double>(size) + triangles * bytes_per_stl_triangle;
    if (need > static_cast<double>(limit_bytes(memory))) {
        throw LimitError(fmt::format("{}: its up to {:.4g} triangles ({} bytes) need an estimated {} of memory to read and make "
                                     "ready for the inside test; {}",
                                     what, std::floor(triangles), size, format_bytes(need), describe_limit(memory)));
    }
    std::ifstream in(file, std::ios::binary);
    std::string bytes(static_cast<std::size_t>(size), '\0');
    if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) throw InputError(fmt::format("{}: cannot be read", what));
    return parse_stl(bytes, what, unit);
}

TriangleSurface parse_stl(std::string_view bytes, const std::string& what, double unit) {
    if (!(unit > 0.0) || !std::isfinite(unit)) throw InputError(fmt::format("{}: its unit {} m must be a positive length", what, unit));
    if (bytes.size() > max_stl_bytes) throw InputError(too_large(what));
    const std::uint64_t size = bytes.size();
    SurfaceBuilder out(unit, what);
    std::uint32_t count = 0;
    if (size >= 84) std::memcpy(&count, bytes.data() + 80, 4);
    const bool text = bytes.find('\0') == std::string_view::npos;  // a binary file has zeros
    const std::size_t skip = bytes.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;  // a UTF-8 byte-order mark
    if (size >= 84 && size == 84 + 50 * std::uint64_t(count) && !(text && bytes.compare(skip, 5, "solid") == 0)) {
        read_binary(bytes, out, what);
    } else if (text && bytes.compare(skip, 5, "solid") == 0) {
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
