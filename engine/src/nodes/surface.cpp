#include "gpa/engine/surface.hpp"

#include <algorithm>
#include <cmath>
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

// Twice the signed area of the xy projection of (a, b, p): > 0 when p is left of a -> b.
double orient(const std::array<double, 3>& a, const std::array<double, 3>& b, double px, double py) {
    return (b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0]);
}

// The top-left rule for an edge a -> b of a counter-clockwise triangle in the xy projection: a
// point exactly on it belongs to this triangle when the edge is a top edge (horizontal, the
// triangle below it: b left of a) or a left edge (going down: b below a).
bool owns_edge(const std::array<double, 3>& a, const std::array<double, 3>& b) {
    const double dy = b[1] - a[1];
    return dy < 0.0 || (dy == 0.0 && b[0] < a[0]);
}

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
    // About one grid cell per triangle's worth of the xy extent.
    const double side = std::sqrt(static_cast<double>(std::max<std::size_t>(s.triangles.size(), 1)));
    for (int c = 0; c < 2; ++c) {
        const double extent = upper_[c] - lower_[c];
        cells_[c] = static_cast<std::size_t>(std::clamp(side, 1.0, 2048.0));
        cell_size_[c] = extent > 0.0 ? extent / static_cast<double>(cells_[c]) : 1.0;
    }
    const auto cell_of = [&](double x, int c) {
        const double k = std::floor((x - lower_[c]) / cell_size_[c]);
        return static_cast<std::size_t>(std::clamp(k, 0.0, static_cast<double>(cells_[c] - 1)));
    };
    std::vector<std::vector<std::uint32_t>> buckets(cells_[0] * cells_[1]);
    for (std::size_t t = 0; t < s.triangles.size(); ++t) {
        std::array<double, 2> lo{INFINITY, INFINITY}, hi{-INFINITY, -INFINITY};
        for (const std::uint32_t v : s.triangles[t]) {
            for (int c = 0; c < 2; ++c) {
                lo[c] = std::min(lo[c], s.vertices[v][c]);
                hi[c] = std::max(hi[c], s.vertices[v][c]);
            }
        }
        for (std::size_t i = cell_of(lo[0], 0); i <= cell_of(hi[0], 0); ++i) {
            for (std::size_t j = cell_of(lo[1], 1); j <= cell_of(hi[1], 1); ++j) buckets[j * cells_[0] + i].push_back(static_cast<std::uint32_t>(t));
        }
    }
    offsets_.assign(buckets.size() + 1, 0);
    for (std::size_t b = 0; b < buckets.size(); ++b) offsets_[b + 1] = offsets_[b] + static_cast<std::uint32_t>(buckets[b].size());
    members_.reserve(offsets_.back());
    for (const auto& b : buckets) members_.insert(members_.end(), b.begin(), b.end());
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
    bool in = false;
    for (std::uint32_t m = offsets_[b]; m < offsets_[b + 1]; ++m) {
        const auto& tri = s.triangles[members_[m]];
        std::array<double, 3> a = s.vertices[tri[0]], q = s.vertices[tri[1]], r = s.vertices[tri[2]];
        const double area = orient(a, q, r[0], r[1]);
        if (area == 0.0) continue;   // seen edge-on from above: the ray does not cross it
        if (area < 0.0) std::swap(q, r);  // counter-clockwise in the projection
        // The column through p crosses the triangle's projection (edges by the top-left rule).
        bool covered = true;
        for (const auto& [e0, e1] : {std::pair{&a, &q}, std::pair{&q, &r}, std::pair{&r, &a}}) {
            const double w = orient(*e0, *e1, p[0], p[1]);
            if (w < 0.0 || (w == 0.0 && !owns_edge(*e0, *e1))) {
                covered = false;
                break;
            }
        }
        if (!covered) continue;
        // The triangle's height over (p_x, p_y), from its plane; crossed when above p.
        const auto n = cross(minus(q, a), minus(r, a));
        const double z = a[2] - (n[0] * (p[0] - a[0]) + n[1] * (p[1] - a[1])) / n[2];
        if (z > p[2]) in = !in;
    }
    return in;
}

}  // namespace gpa
