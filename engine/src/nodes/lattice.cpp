#include "gpa/engine/lattice.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <unordered_map>
#include <vector>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

int check_lattice_stencil(int dim, int neighbours) {
    const bool ok = dim == 2 ? (neighbours == 4 || neighbours == 8)
                             : (neighbours == 6 || neighbours == 18 || neighbours == 26);
    if (!ok) {
        throw InputError(fmt::format("lattice neighbours = {} is not allowed in {}D (allowed: {})", neighbours, dim,
                                     dim == 2 ? "4 or 8" : "6, 18 or 26"));
    }
    return neighbours;
}

namespace {

// Lattice offsets of a stencil: within the 3^D box those with 1 (4/6), up to 2 (8/18) or up to 3
// (26) non-zero components, and beyond it those closer than `reach` (m, on the undeformed lattice
// of spacing `spacing`); in a fixed order (by z, y, x offset). 2D offsets are (dx, dz) in
// components 0 and 1.
std::vector<std::array<int, 3>> stencil_offsets(int dim, int neighbours, double reach, const std::array<double, 3>& spacing) {
    const int max_nonzero = (neighbours == 4 || neighbours == 6) ? 1 : (neighbours == 18 ? 2 : 3);
    std::array<int, 3> box{1, 1, 1};
    for (int c = 0; c < dim; ++c) box[c] = std::max(1, static_cast<int>(std::ceil(reach / spacing[c])));
    const int zr = dim == 3 ? box[2] : 0;
    std::vector<std::array<int, 3>> out;
    for (int dz = -zr; dz <= zr; ++dz) {
        for (int dy = -box[1]; dy <= box[1]; ++dy) {
            for (int dx = -box[0]; dx <= box[0]; ++dx) {
                const int nonzero = (dx != 0) + (dy != 0) + (dz != 0);
                if (nonzero == 0) continue;
                const bool in_box = std::abs(dx) <= 1 && std::abs(dy) <= 1 && std::abs(dz) <= 1;
                const double ex = dx * spacing[0], ey = dy * spacing[1], ez = dim == 3 ? dz * spacing[2] : 0.0;
                const bool within_reach = ex * ex + ey * ey + ez * ez < reach * reach;
                if ((in_box && nonzero <= max_nonzero) || within_reach) out.push_back({dx, dy, dz});
            }
        }
    }
    return out;
}

struct CellHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
        std::uint64_t h = 1469598103934665603ull;
        for (auto v : k) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
        return static_cast<std::size_t>(h);
    }
};

// The part of the cell centred at `centre` that block.inside covers (LatticeBlock::trim).
struct CellShare {
    double fraction = 0.0;
    std::array<double, 3> centroid{0, 0, 0};
};

CellShare trimmed_share(const LatticeBlock& block, const std::array<double, 3>& centre, int dim) {
    CellShare out;
    // Corners and centre: all inside, the cell is whole (its node at its centre, as untrimmed).
    bool all = block.inside(centre), any = all;
    for (int corner = 0; corner < (1 << dim); ++corner) {
        std::array<double, 3> q = centre;
        for (int c = 0; c < dim; ++c) q[c] += ((corner >> c) & 1 ? 0.5 : -0.5) * block.spacing[c];
        const bool in = block.inside(q);
        all = all && in;
        any = any || in;
    }
    if (all) {
        out.fraction = 1.0;
        out.centroid = centre;
        return out;
    }
    if (!any) return out;
    // Midpoints of m^D equal sub-cells, offsets (2a + 1 - m) / (2m) of the spacing from the
    // centre: the sub-cells a and m - 1 - a lie exactly opposite, so mirror cells get mirror nodes.
    // The offsets are summed as the integers 2a + 1 - m, so that the centroid's offset is exact
    // in sign and a mirror cell's node is the mirror of this one's bit for bit.
    const int m = block.trim_samples;
    std::array<std::int64_t, 3> sum{0, 0, 0};
    std::int64_t count = 0, total = 0;
    const int mz = dim == 3 ? m : 1;
    for (int az = 0; az < mz; ++az) {
        for (int ay = 0; ay < m; ++ay) {
            for (int ax = 0; ax < m; ++ax) {
                const std::array<int, 3> a{ax, ay, az};
                std::array<double, 3> q = centre;
                for (int c = 0; c < dim; ++c) {
                    q[c] += static_cast<double>(2 * a[c] + 1 - m) / static_cast<double>(2 * m) * block.spacing[c];
                }
                ++total;
                if (!block.inside(q)) continue;
                ++count;
                for (int c = 0; c < dim; ++c) sum[c] += 2 * a[c] + 1 - m;
            }
        }
    }
    if (count == 0) return out;
    out.fraction = static_cast<double>(count) / static_cast<double>(total);
    out.centroid = centre;
    for (int c = 0; c < dim; ++c) {
        out.centroid[c] += static_cast<double>(sum[c]) / static_cast<double>(2 * m * count) * block.spacing[c];
    }
    return out;
}

// Merges every part below block.smallest_share into its fullest face neighbour at least that full
// (LatticeBlock::trim; ties below), in place: the sliver's entries (cell, centre, node, share) go,
// the neighbour's share grows by the sliver's and its node moves to the centroid of both (weighted
// by share). A sliver with no such neighbour is dropped. The choice reads the shares as sampled, so
// merges do not chain.
void merge_slivers(const LatticeBlock& block, int dim, std::vector<std::array<std::int64_t, 3>>& cells,
                   std::vector<std::array<double, 3>>& centres, std::vector<std::array<double, 3>>& points,
                   std::vector<double>& shares) {
    std::unordered_map<std::array<std::int64_t, 3>, std::size_t, CellHash> index_of;
    index_of.reserve(cells.size());
    for (std::size_t k = 0; k < cells.size(); ++k) index_of.emplace(cells[k], k);
    const std::vector<double> sampled = shares;
    std::vector<std::array<double, 3>> moment(points.size());  // share-weighted sums of node positions
    for (std::size_t k = 0; k < points.size(); ++k) {
        for (int c = 0; c < 3; ++c) moment[k][c] = sampled[k] * points[k][c];
    }
    std::vector<bool> gone(cells.size(), false);
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (sampled[k] >= block.smallest_share) continue;
        gone[k] = true;
        // The fullest neighbour; at a tie the one along the lower axis, then the one nearer the
        // block's middle along it: a choice that mirrors with the cells (a mirror-symmetric shape
        // merges its slivers symmetrically).
        std::size_t best = cells.size();
        int best_axis = 0;
        double best_off_middle = 0.0;
        for (int c = 0; c < dim; ++c) {
            const auto a = static_cast<std::size_t>(c);
            const double middle = 0.5 * static_cast<double>(block.first[a] + block.last[a] - 1);
            for (const int step : {-1, 1}) {
                auto nb = cells[k];
                nb[a] += step;
                const auto it = index_of.find(nb);
                if (it == index_of.end() || sampled[it->second] < block.smallest_share) continue;
                const double off_middle = std::abs(static_cast<double>(nb[a]) - middle);
                const bool better = best == cells.size() || sampled[it->second] > sampled[best] ||
                                    (sampled[it->second] == sampled[best] &&
                                     (c < best_axis || (c == best_axis && off_middle < best_off_middle)));
                if (better) {
                    best = it->second;
                    best_axis = c;
                    best_off_middle = off_middle;
                }
            }
        }
        if (best == cells.size()) continue;
        shares[best] += sampled[k];
        for (int c = 0; c < 3; ++c) moment[best][c] += moment[k][c];
    }
    std::size_t kept = 0;
    for (std::size_t k = 0; k < cells.size(); ++k) {
        if (gone[k]) continue;
        cells[kept] = cells[k];
        centres[kept] = centres[k];
        shares[kept] = shares[k];
        if (shares[k] != sampled[k]) {
            for (int c = 0; c < 3; ++c) points[k][c] = moment[k][c] / shares[k];
        }
        points[kept] = points[k];
        ++kept;
    }
    cells.resize(kept);
    centres.resize(kept);
    points.resize(kept);
    shares.resize(kept);
}

}  // namespace

std::vector<MirrorPlane> lattice_mirror_planes(const LatticeBlock& block, const std::vector<MirrorPlane>& planes, int dim) {
    std::vector<MirrorPlane> out;
    const bool turned = !is_identity(block.rotation);
    for (const MirrorPlane& p : planes) {
        if (!turned && p.axis >= 0) {
            out.push_back(p);
            continue;
        }
        std::array<double, 3> n{0, 0, 0};
        if (p.axis >= 0) n[static_cast<std::size_t>(p.axis)] = 1.0; else n = p.normal;
        // n . x = c with x = pivot + R (x_b - pivot): n_b . (x_b - pivot) = c - n . pivot, n_b = R^T n.
        const auto nb = turn_back(block.rotation, n);
        // Along a lattice axis: every other component below 1e-9 (an angle of 1e-9 rad, the
        // tolerance of GhostPlane's `perpendicular` too).
        int axis = 0;
        for (int c = 1; c < dim; ++c) {
            if (std::abs(nb[c]) > std::abs(nb[axis])) axis = c;
        }
        bool along = true;
        for (int c = 0; c < dim; ++c) along = along && (c == axis || std::abs(nb[c]) < 1e-9);
        if (!along) continue;
        const int sign = nb[axis] > 0.0 ? +1 : -1;
        double offset = p.position;
        for (int c = 0; c < dim; ++c) offset -= n[c] * block.pivot[c];
        MirrorPlane local = p;
        local.axis = axis;
        local.position = block.pivot[axis] + sign * offset;
        local.side = p.side * sign;
        local.normal = {0, 0, 0};
        out.push_back(local);
    }
    return out;
}

std::size_t fill_lattice(NodeStore& nodes, const LatticeBlock& block) {
    const int dim = nodes.dim();
    check_lattice_stencil(dim, block.lattice_neighbours);
    for (int c = 0; c < dim; ++c) {
        if (!(block.spacing[c] > 0.0) || !std::isfinite(block.spacing[c])) {
            throw InputError(fmt::format("lattice spacing along axis {} is {} (must be positive)", c, block.spacing[c]));
        }
        if (block.last[c] < block.first[c]) {
            throw InputError(fmt::format("lattice cells along axis {}: last {} < first {}", c, block.last[c], block.first[c]));
        }
    }
    if (dim == 3 && !(block.spacing[0] == block.spacing[1] && block.spacing[1] == block.spacing[2])) {
        throw InputError("a 3D lattice needs dx = dy = dz (spec section 12)");
    }
    if (!(block.density > 0.0) || !std::isfinite(block.density)) {
        throw InputError(fmt::format("density {} must be positive", block.density));
    }

    // In 2D the lattice axes are (x, z) = components (0, 1); in 3D (x, y, z).
    const double cell_area = block.spacing[0] * block.spacing[1];
    const double cell_volume = dim == 3 ? cell_area * block.spacing[2] : cell_area;
    const double d0 = dim == 3 ? block.spacing[0] : std::sqrt(cell_area);
    // The stencil's reach is 2 a d0 with a at most 1.5 (spec section 2): 3 d0 and no more.
    if (!(block.stencil_reach >= 0.0) || block.stencil_reach > 3.0 * (1.0 + 1e-12)) {
        throw InputError(fmt::format("lattice stencil reach {} d0 is not within [0, 3]", block.stencil_reach));
    }

    const std::size_t first_new = nodes.size();
    std::vector<std::array<std::int64_t, 3>> cells;
    std::vector<std::array<double, 3>> centres;  // the cells' centres (the lattice's geometry)
    std::vector<std::array<double, 3>> points;   // the nodes: the centres, or trimmed parts' centroids
    std::vector<double> shares;                  // each node's share of its cell (1: whole)
    const bool trim = block.trim && static_cast<bool>(block.inside);
    if (trim && (block.trim_samples < 2 || block.trim_samples > 64 || !(block.smallest_share > 0.0 && block.smallest_share <= 1.0))) {
        throw InputError(fmt::format("trimmed lattice: {} samples per axis (2 to 64) and smallest share {} (in (0, 1])",
                                     block.trim_samples, block.smallest_share));
    }
    const std::int64_t zlast = dim == 3 ? block.last[2] : block.first[2] + 1;
    for (std::int64_t kz = block.first[2]; kz < zlast; ++kz) {
        for (std::int64_t ky = block.first[1]; ky < block.last[1]; ++ky) {
            for (std::int64_t kx = block.first[0]; kx < block.last[0]; ++kx) {
                const std::array<std::int64_t, 3> k{kx, ky, kz};
                std::array<double, 3> p{0, 0, 0};
                for (int c = 0; c < dim; ++c) {
                    p[c] = block.origin[c] + (static_cast<double>(k[c]) + 0.5) * block.spacing[c];
                }
                if (!trim) {
                    if (block.inside && !block.inside(p)) continue;
                    cells.push_back(k);
                    centres.push_back(p);
                    points.push_back(p);
                    shares.push_back(1.0);
                    continue;
                }
                const auto share = trimmed_share(block, p, dim);
                if (!(share.fraction > 0.0)) continue;
                cells.push_back(k);
                centres.push_back(p);
                points.push_back(share.centroid);
                shares.push_back(share.fraction);
            }
        }
    }
    if (trim) merge_slivers(block, dim, cells, centres, points, shares);

    const std::size_t added = cells.size();
    nodes.resize(first_new + added);
    std::unordered_map<std::array<std::int64_t, 3>, NodeIndex, CellHash> index_of;
    index_of.reserve(added);
    for (std::size_t k = 0; k < added; ++k) {
        const std::size_t i = first_new + k;
        const auto p = block.place(points[k]);
        for (int c = 0; c < dim; ++c) {
            nodes.position[c][i] = p[c];
            nodes.initial_position[c][i] = p[c];
            nodes.velocity[c][i] = block.velocity[c];
        }
        const bool whole = shares[k] == 1.0;
        double v0 = whole ? cell_volume : shares[k] * cell_volume;
        if (nodes.geometry() == GeometryKind::Axisymmetric) {
            if (!(p[0] > 0.0)) {
                throw InputError(fmt::format(
                    "axisymmetric lattice cell ({}, {}) has its node at x = {} m; nodes must have x > 0",
                    cells[k][0], cells[k][1], p[0]));
            }
            // A ring of cross-section dx dz (Pappus: 2 pi times the section's centroid radius).
            v0 = 2.0 * std::numbers::pi * p[0] * (whole ? cell_area : shares[k] * cell_area);
        }
        nodes.initial_volume[i] = v0;
        nodes.volume[i] = v0;
        nodes.mass[i] = block.density * v0;
        // A trimmed node's d0 is the side of the cube (square) of its size.
        const double node_d0 = whole ? d0 : d0 * (dim == 3 ? std::cbrt(shares[k]) : std::sqrt(shares[k]));
        nodes.initial_diameter[i] = node_d0;
        nodes.diameter[i] = node_d0;
        if (nodes.dim() == 3) {
            for (int c = 0; c < 6; ++c) nodes.left_cauchy_green[c][i] = c < 3 ? 1.0 : 0.0;
        }
        nodes.body[i] = block.body;
        nodes.id[i] = static_cast<std::uint32_t>(i);  // the fill order (node_store.hpp)
        nodes.material[i] = block.material;
        nodes.connectivity[i] = block.connectivity;
        index_of.emplace(cells[k], static_cast<NodeIndex>(i));
    }
    update_size_weights(nodes, first_new, first_new + added);

    // Fixed lists of the new nodes: their stencil neighbours that exist, in stencil order; and
    // where a stencil neighbour falls behind mirror planes, the ghost image of the cell that
    // mirrors it (the lattice continues across the plane, spec section 7).
    const auto offsets = stencil_offsets(dim, block.lattice_neighbours, block.stencil_reach * d0, block.spacing);
    auto& rows = nodes.fixed_neighbours;
    rows.offsets.resize(first_new + 1);
    rows.indices.resize(rows.offsets.back());
    auto& mirrors = nodes.fixed_mirrors;
    mirrors.offsets.resize(first_new + 1);
    mirrors.indices.resize(mirrors.offsets.back());
    nodes.fixed_mirror_planes.resize(mirrors.offsets.back());
    const auto cell_at = [&](const std::array<double, 3>& p) -> std::optional<NodeIndex> {
        std::array<std::int64_t, 3> k{block.first[0], block.first[1], block.first[2]};
        for (int c = 0; c < dim; ++c) {
            const double f = (p[c] - block.origin[c]) / block.spacing[c] - 0.5;
            const double r = std::round(f);
            if (std::abs(f - r) > 1e-6) return std::nullopt;  // the plane is not on a cell face
            k[c] = static_cast<std::int64_t>(r);
        }
        if (const auto it = index_of.find(k); it != index_of.end()) return it->second;
        return std::nullopt;
    };
    for (std::size_t k = 0; k < added; ++k) {
        for (const auto& o : offsets) {
            // 2D offsets are (dx, dz) in components 0 and 1.
            std::array<std::int64_t, 3> nb{cells[k][0] + o[0], cells[k][1] + o[1], cells[k][2] + o[2]};
            if (const auto it = index_of.find(nb); it != index_of.end()) {
                rows.indices.push_back(it->second);
                continue;
            }
            // The planes this missing neighbour lies behind; mirror it across all of them.
            std::array<double, 3> p = centres[k];
            for (int c = 0; c < dim; ++c) p[c] += o[c] * block.spacing[c];
            std::uint8_t mask = 0;
            bool distinct_axes = true;
            int axes_seen = 0;
            for (const auto& plane : block.mirror_planes) {
                if (plane.side * (p[plane.axis] - plane.position) < 0.0) {
                    if (axes_seen & (1 << plane.axis)) distinct_axes = false;
                    axes_seen |= 1 << plane.axis;
                    mask |= static_cast<std::uint8_t>(1u << plane.bit);
                    p[plane.axis] = 2.0 * plane.position - p[plane.axis];
                }
            }
            if (mask == 0 || !distinct_axes) continue;
            if (const auto source = cell_at(p)) {
                mirrors.indices.push_back(*source);
                nodes.fixed_mirror_planes.push_back(mask);
            }
        }
        rows.offsets.push_back(rows.indices.size());
        mirrors.offsets.push_back(mirrors.indices.size());
    }
    return first_new;
}

}  // namespace gpa
