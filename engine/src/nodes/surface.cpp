#include "gpa/engine/surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <utility>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

namespace {

std::string point_text(const std::array<double, 3>& p) { return fmt::format("({:.6g}, {:.6g}, {:.6g})", p[0], p[1], p[2]); }

std::array<double, 3> minus(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

std::array<double, 3> cross(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

using Snapped = std::array<std::int64_t, 3>;
__extension__ typedef __int128 Wide;  // exact products of grid coordinates (GCC and Clang)

// Twice the signed area of the xy projection of (a, b, p), exactly: > 0 when p is left of a -> b.
Wide orient2d(const Snapped& a, const Snapped& b, const Snapped& p) {
    return static_cast<Wide>(b[0] - a[0]) * (p[1] - a[1]) - static_cast<Wide>(b[1] - a[1]) * (p[0] - a[0]);
}

// (p - a) . ((b - a) x (c - a)), exactly (coordinates below 2^32: each term below 2^97): > 0 when p
// lies on the side the normal of (a, b, c) points to by the right-hand rule.
Wide orient3d(const Snapped& a, const Snapped& b, const Snapped& c, const Snapped& p) {
    const Wide ux = b[0] - a[0], uy = b[1] - a[1], uz = b[2] - a[2];
    const Wide vx = c[0] - a[0], vy = c[1] - a[1], vz = c[2] - a[2];
    const Wide wx = p[0] - a[0], wy = p[1] - a[1], wz = p[2] - a[2];
    return wx * (uy * vz - uz * vy) + wy * (uz * vx - ux * vz) + wz * (ux * vy - uy * vx);
}

// The top-left rule for an edge a -> b of a counter-clockwise triangle in the xy projection: a
// point exactly on it belongs to this triangle when the edge is a top edge (horizontal, the
// triangle below it: b left of a) or a left edge (going down: b below a).
bool owns_edge(const Snapped& a, const Snapped& b) {
    const std::int64_t dy = b[1] - a[1];
    return dy < 0 || (dy == 0 && b[0] < a[0]);
}

// Buckets along each axis of the xy grid for `triangles` triangles, and the entries (triangle,
// bucket) it would hold: a triangle is entered in every bucket its xy box covers.
constexpr std::size_t max_buckets_per_axis = 2048;

}  // namespace

void check_surface(const TriangleSurface& s, const std::string& what) {
    if (s.triangles.size() < 4) {
        throw InputError(fmt::format("{}: {} triangle{}: a closed surface needs at least 4", what, s.triangles.size(),
                                     s.triangles.size() == 1 ? "" : "s"));
    }
    for (std::size_t v = 0; v < s.vertices.size(); ++v) {
        for (const double c : s.vertices[v]) {
            if (!std::isfinite(c)) throw InputError(fmt::format("{}: vertex {} is not finite {}", what, v, point_text(s.vertices[v])));
        }
    }
    // The inside test (SurfaceInside) cuts the surface's box into buckets along x and y and snaps
    // points to a grid across its largest extent: along each axis the box must be finite and, unless
    // flat, at least the smallest normal double wide, or a bucket's size comes out infinite or zero
    // and a point's bucket not a number.
    if (!s.vertices.empty()) {
        std::array<double, 3> lo = s.vertices.front(), hi = lo;
        for (const auto& v : s.vertices) {
            for (std::size_t c = 0; c < 3; ++c) {
                lo[c] = std::min(lo[c], v[c]);
                hi[c] = std::max(hi[c], v[c]);
            }
        }
        for (std::size_t c = 0; c < 3; ++c) {
            const double width = hi[c] - lo[c];
            if (std::isfinite(width) && !(width > 0.0 && width < std::numeric_limits<double>::min())) continue;
            throw InputError(fmt::format("{}: along {} its vertices reach from {} to {} m: too {} for the inside test, which "
                                         "needs a width of 0 or from {:.3g} to {:.3g} m",
                                         what, "xyz"[c], lo[c], hi[c], std::isfinite(width) ? "close together" : "far apart",
                                         std::numeric_limits<double>::min(), std::numeric_limits<double>::max()));
        }
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> edges;  // undirected edge -> triangles sharing it
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        const auto& tri = s.triangles[t];
        for (const std::uint32_t v : tri) {
            if (v >= s.vertices.size()) throw InputError(fmt::format("{}: triangle {} names vertex {}, of {}", what, t, v, s.vertices.size()));
        }
        const auto& a = s.vertices[tri[0]];
        const auto n = cross(minus(s.vertices[tri[1]], a), minus(s.vertices[tri[2]], a));
        if (!(n[0] * n[0] + n[1] * n[1] + n[2] * n[2] > 0.0)) {
            throw InputError(fmt::format("{}: triangle {} at {} has no area (two of its corners coincide or all three are in "
                                         "a line)", what, t, point_text(a)));
        }
        for (int k = 0; k < 3; ++k) {
            const std::uint32_t p = tri[static_cast<std::size_t>(k)], q = tri[static_cast<std::size_t>((k + 1) % 3)];
            ++edges[{std::min(p, q), std::max(p, q)}];
        }
    }
    for (const auto& [edge, count] : edges) {
        if (count != 2) {
            throw InputError(fmt::format("{}: the edge from {} to {} belongs to {} triangle{}, where a closed surface has 2 on "
                                         "every edge: the surface {} (export it as a closed, watertight solid)",
                                         what, point_text(s.vertices[edge.first]), point_text(s.vertices[edge.second]), count,
                                         count == 1 ? "" : "s", count == 1 ? "has a hole" : "meets itself there"));
        }
    }
}

double enclosed_volume(const TriangleSurface& s) {
    double six_v = 0.0;
    for (const auto& tri : s.triangles) {
        const auto& a = s.vertices[tri[0]];
        const auto n = cross(s.vertices[tri[1]], s.vertices[tri[2]]);
        six_v += a[0] * n[0] + a[1] * n[1] + a[2] * n[2];
    }
    return six_v / 6.0;
}

SurfaceInside::SurfaceInside(std::shared_ptr<const TriangleSurface> surface) : surface_(std::move(surface)) {
    const TriangleSurface& s = *surface_;
    lower_ = upper_ = s.vertices.empty() ? std::array<double, 3>{0, 0, 0} : s.vertices.front();
    for (const auto& v : s.vertices) {
        for (int c = 0; c < 3; ++c) {
            lower_[c] = std::min(lower_[c], v[c]);
            upper_[c] = std::max(upper_[c], v[c]);
        }
    }
    double extent = 0.0;
    for (int c = 0; c < 3; ++c) extent = std::max(extent, upper_[c] - lower_[c]);
    grid_step_ = extent > 0.0 ? extent / 2147483648.0 : 1.0;  // 2^31 steps across the largest extent
    snapped_.reserve(s.vertices.size());
    for (const auto& v : s.vertices) snapped_.push_back(snap(v));

    // The buckets: about one per triangle's worth of the xy extent, fewer where long triangles would
    // enter too many (at most 32 entries per triangle on average), so that memory stays linear.
    std::vector<std::array<double, 4>> boxes(s.triangles.size());  // x0, x1, y0, y1 of each triangle
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        boxes[t] = {INFINITY, -INFINITY, INFINITY, -INFINITY};
        for (const std::uint32_t v : s.triangles[t]) {
            boxes[t][0] = std::min(boxes[t][0], s.vertices[v][0]);
            boxes[t][1] = std::max(boxes[t][1], s.vertices[v][0]);
            boxes[t][2] = std::min(boxes[t][2], s.vertices[v][1]);
            boxes[t][3] = std::max(boxes[t][3], s.vertices[v][1]);
        }
    }
    const auto cell_of = [&](double x, int c) {
        const double k = std::floor((x - lower_[c]) / cell_size_[c]);
        return static_cast<std::size_t>(std::clamp(k, 0.0, static_cast<double>(cells_[c] - 1)));
    };
    const auto set_grid = [&](std::size_t per_axis) {
        for (int c = 0; c < 2; ++c) {
            cells_[c] = per_axis;
            const double e = upper_[c] - lower_[c];
            cell_size_[c] = e > 0.0 ? e / static_cast<double>(per_axis) : 1.0;
        }
    };
    const auto entries = [&] {
        std::size_t n = 0;
        for (const auto& box : boxes) n += (cell_of(box[1], 0) - cell_of(box[0], 0) + 1) * (cell_of(box[3], 1) - cell_of(box[2], 1) + 1);
        return n;
    };
    const std::size_t budget = 32 * std::max<std::size_t>(s.triangles.size(), 64);
    std::size_t per_axis = static_cast<std::size_t>(
        std::clamp(std::sqrt(static_cast<double>(s.triangles.size())), 1.0, static_cast<double>(max_buckets_per_axis)));
    set_grid(per_axis);
    while (per_axis > 1 && entries() > budget) set_grid(per_axis = per_axis / 2);
    offsets_.assign(cells_[0] * cells_[1] + 1, 0);
    for (const auto& box : boxes) {
        for (std::size_t i = cell_of(box[0], 0); i <= cell_of(box[1], 0); ++i) {
            for (std::size_t j = cell_of(box[2], 1); j <= cell_of(box[3], 1); ++j) ++offsets_[j * cells_[0] + i + 1];
        }
    }
    for (std::size_t b = 0; b + 1 < offsets_.size(); ++b) offsets_[b + 1] += offsets_[b];
    members_.resize(offsets_.back());
    std::vector<std::size_t> next(offsets_.begin(), offsets_.end() - 1);
    for (std::size_t t = 0; t < boxes.size(); ++t) {
        const auto& box = boxes[t];
        for (std::size_t i = cell_of(box[0], 0); i <= cell_of(box[1], 0); ++i) {
            for (std::size_t j = cell_of(box[2], 1); j <= cell_of(box[3], 1); ++j) members_[next[j * cells_[0] + i]++] = static_cast<std::uint32_t>(t);
        }
    }
}

SurfaceInside::Snapped SurfaceInside::snap(const std::array<double, 3>& p) const {
    Snapped out{};
    for (int c = 0; c < 3; ++c) out[c] = std::llround((p[c] - lower_[c]) / grid_step_);
    return out;
}

bool SurfaceInside::inside(const std::array<double, 3>& p) const {
    for (int c = 0; c < 3; ++c) {
        if (!(p[c] > lower_[c] && p[c] < upper_[c])) return false;
    }
    const TriangleSurface& s = *surface_;
    const auto cell = [&](int c) {
        const double k = std::floor((p[c] - lower_[c]) / cell_size_[c]);
        return static_cast<std::size_t>(std::clamp(k, 0.0, static_cast<double>(cells_[c] - 1)));
    };
    const std::size_t b = cell(1) * cells_[0] + cell(0);
    const Snapped q = snap(p);
    bool in = false;
    for (std::size_t m = offsets_[b]; m < offsets_[b + 1]; ++m) {
        const auto& tri = s.triangles[members_[m]];
        const Snapped* a = &snapped_[tri[0]];
        const Snapped* u = &snapped_[tri[1]];
        const Snapped* w = &snapped_[tri[2]];
        const Wide area = orient2d(*a, *u, *w);
        if (area == 0) continue;       // seen edge-on from above: the ray does not cross it
        if (area < 0) std::swap(u, w);  // counter-clockwise in the projection
        // The column through q crosses the triangle's projection (edges by the top-left rule).
        bool covered = true;
        for (const auto& [e0, e1] : {std::pair{a, u}, std::pair{u, w}, std::pair{w, a}}) {
            const Wide side = orient2d(*e0, *e1, q);
            if (side < 0 || (side == 0 && !owns_edge(*e0, *e1))) {
                covered = false;
                break;
            }
        }
        if (!covered) continue;
        // (a, u, w) is counter-clockwise seen from above: its normal points up, and the triangle
        // is above q when q lies below its plane.
        if (orient3d(*a, *u, *w, q) < 0) in = !in;
    }
    return in;
}

}  // namespace gpa
