#include "gpa/engine/colouring.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

std::string_view name_of(ScatterScheme s) {
    switch (s) {
        case ScatterScheme::Slabs: return "slabs";
        case ScatterScheme::Cells: return "cells";
        case ScatterScheme::Graph: return "graph";
        case ScatterScheme::Serial: return "serial";
    }
    return "?";
}

namespace {

// Largest |x_c(j) - x_c(i)| over all listed pairs, per axis: how far a centre's writes reach.
// A maximum is exact in any order, so the parallel reduction is deterministic.
std::array<double, 3> pair_reach(const CompressedRows& lists, const PositionView& x) {
    using Reach = std::array<double, 3>;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, lists.rows(), 2048), Reach{0.0, 0.0, 0.0},
        [&](const tbb::blocked_range<std::size_t>& r, Reach reach) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                for (NodeIndex j : lists.row(i)) {
                    for (int c = 0; c < x.dim; ++c) {
                        reach[c] = std::max(reach[c], std::abs(x.component[c][j] - x.component[c][i]));
                    }
                }
            }
            return reach;
        },
        [](Reach a, const Reach& b) {
            for (int c = 0; c < 3; ++c) a[c] = std::max(a[c], b[c]);
            return a;
        });
}

struct Box {
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
};

Box centre_box(std::size_t n, const PositionView& x) {
    Box b;
    for (int c = 0; c < x.dim; ++c) {
        b.lo[c] = std::numeric_limits<double>::infinity();
        b.hi[c] = -std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < n; ++i) {
            b.lo[c] = std::min(b.lo[c], x.component[c][i]);
            b.hi[c] = std::max(b.hi[c], x.component[c][i]);
        }
    }
    return b;
}

// Groups centres by a key (stable counting sort, so each group keeps ascending node order) and
// puts group k in colour colour_of(k). Empty groups are dropped.
template <class ColourOf>
ScatterPlan plan_from_keys(ScatterScheme scheme, const std::vector<std::size_t>& key, std::size_t key_count,
                           std::size_t colour_count, ColourOf colour_of) {
    ScatterPlan plan;
    plan.scheme = scheme;
    std::vector<std::size_t> start(key_count + 1, 0);
    for (std::size_t k : key) ++start[k + 1];
    for (std::size_t k = 0; k < key_count; ++k) start[k + 1] += start[k];
    std::vector<NodeIndex> by_key(key.size());
    {
        std::vector<std::size_t> next(start.begin(), start.end() - 1);
        for (std::size_t i = 0; i < key.size(); ++i) by_key[next[key[i]]++] = static_cast<NodeIndex>(i);
    }
    plan.centres.reserve(key.size());
    for (std::size_t colour = 0; colour < colour_count; ++colour) {
        for (std::size_t k = 0; k < key_count; ++k) {
            if (colour_of(k) != colour || start[k] == start[k + 1]) continue;
            plan.centres.insert(plan.centres.end(), by_key.begin() + start[k], by_key.begin() + start[k + 1]);
            plan.group_offsets.push_back(plan.centres.size());
        }
        plan.colour_offsets.push_back(plan.group_offsets.size() - 1);
    }
    return plan;
}

}  // namespace

ScatterPlan make_serial_plan(const CompressedRows& lists) {
    ScatterPlan plan;
    plan.scheme = ScatterScheme::Serial;
    plan.centres.resize(lists.rows());
    for (std::size_t i = 0; i < lists.rows(); ++i) plan.centres[i] = static_cast<NodeIndex>(i);
    plan.group_offsets.push_back(plan.centres.size());
    plan.colour_offsets.push_back(1);
    return plan;
}

ScatterPlan make_slab_plan(const CompressedRows& lists, const PositionView& x) {
    const std::size_t n = lists.rows();
    if (n == 0) return make_serial_plan(lists);
    const Box box = centre_box(n, x);
    int axis = 0;
    for (int c = 1; c < x.dim; ++c) {
        if (box.hi[c] - box.lo[c] > box.hi[axis] - box.lo[axis]) axis = c;
    }
    // A centre writes nodes within `reach` of itself along the axis; with slabs at least
    // 2 * reach wide, centres two slabs apart can never write the same node.
    const double reach = pair_reach(lists, x)[axis];
    const double extent = box.hi[axis] - box.lo[axis];
    // A margin over 2 * reach: a centre on a slab boundary must not be put in the wrong slab by
    // the rounding of (x - lo) / width.
    double width = 2.0 * reach * (1.0 + 1e-9) + 1e-12 * extent;
    if (!(width > 0.0) || !std::isfinite(width)) width = extent + 1.0;
    // Wider slabs are always safe; more slabs than centres buy nothing.
    if (extent / width > static_cast<double>(n)) width = extent / static_cast<double>(n);
    const std::size_t slabs = static_cast<std::size_t>(extent / width) + 1;
    if (slabs < 2) return make_serial_plan(lists);
    std::vector<std::size_t> key(n);
    for (std::size_t i = 0; i < n; ++i) {
        key[i] = std::min(slabs - 1, static_cast<std::size_t>((x.component[axis][i] - box.lo[axis]) / width));
    }
    return plan_from_keys(ScatterScheme::Slabs, key, slabs, 2, [](std::size_t k) { return k % 2; });
}

ScatterPlan make_cell_plan(const CompressedRows& lists, const PositionView& x) {
    const std::size_t n = lists.rows();
    if (n == 0) return make_serial_plan(lists);
    const Box box = centre_box(n, x);
    const auto reach = pair_reach(lists, x);
    double edge = 0.0, extent = 0.0;
    for (int c = 0; c < x.dim; ++c) {
        edge = std::max(edge, reach[c]);
        extent = std::max(extent, box.hi[c] - box.lo[c]);
    }
    if (!(edge > 0.0)) return make_serial_plan(lists);
    edge = edge * (1.0 + 1e-9) + 1e-12 * extent;  // margin against rounding at cell boundaries
    // Centres in cells three apart along some axis write disjoint sets when the cell edge is at
    // least the reach. Keep the grid no larger than a few cells per centre.
    std::array<std::size_t, 3> cells{1, 1, 1};
    for (;;) {
        double total = 1.0;
        for (int c = 0; c < x.dim; ++c) {
            cells[c] = static_cast<std::size_t>((box.hi[c] - box.lo[c]) / edge) + 1;
            total *= static_cast<double>(cells[c]);
        }
        if (total <= 4.0 * static_cast<double>(n) + 64.0) break;
        edge *= 1.5;
    }
    std::vector<std::size_t> key(n);
    for (std::size_t i = 0; i < n; ++i) {
        std::size_t k = 0;
        for (int c = x.dim - 1; c >= 0; --c) {
            const auto cell = std::min(cells[c] - 1, static_cast<std::size_t>((x.component[c][i] - box.lo[c]) / edge));
            k = k * cells[c] + cell;
        }
        key[i] = k;
    }
    std::size_t key_count = 1;
    for (int c = 0; c < x.dim; ++c) key_count *= cells[c];
    const int dim = x.dim;
    const auto colour_of = [&cells, dim](std::size_t k) {
        std::size_t colour = 0, scale = 1;
        for (int c = 0; c < dim; ++c) {
            colour += (k % cells[c]) % 3 * scale;
            k /= cells[c];
            scale *= 3;
        }
        return colour;
    };
    const std::size_t colours = dim == 3 ? 27 : 9;
    return plan_from_keys(ScatterScheme::Cells, key, key_count, colours, colour_of);
}

ScatterPlan make_graph_plan(const CompressedRows& lists, std::size_t node_count, std::size_t group_size) {
    const std::size_t n = lists.rows();
    // writers(m): the centres that write node m (m itself, if a centre, and every centre that
    // lists m), as a transposed list.
    CompressedRows writers;
    writers.offsets.assign(node_count + 1, 0);
    for (std::size_t i = 0; i < n; ++i) {
        ++writers.offsets[i + 1];
        for (NodeIndex j : lists.row(i)) {
            if (j >= node_count) throw InputError(fmt::format("make_graph_plan: centre {} lists node {} of {}", i, j, node_count));
            ++writers.offsets[j + 1];
        }
    }
    for (std::size_t m = 0; m < node_count; ++m) writers.offsets[m + 1] += writers.offsets[m];
    writers.indices.resize(writers.offsets.back());
    {
        std::vector<std::size_t> next(writers.offsets.begin(), writers.offsets.end() - 1);
        for (std::size_t i = 0; i < n; ++i) {
            writers.indices[next[i]++] = static_cast<NodeIndex>(i);
            for (NodeIndex j : lists.row(i)) writers.indices[next[j]++] = static_cast<NodeIndex>(i);
        }
    }
    // Greedy colouring in node order: a centre takes the smallest colour that no earlier centre
    // writing one of the same nodes has.
    std::vector<std::uint32_t> colour(n, 0);
    std::vector<std::size_t> taken_by;  // taken_by[c] == i + 1 when colour c is forbidden for centre i
    std::uint32_t colours = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const auto forbid_writers_of = [&](std::size_t m) {
            for (std::size_t k = writers.offsets[m]; k < writers.offsets[m + 1]; ++k) {
                const NodeIndex other = writers.indices[k];
                if (other < i) taken_by[colour[other]] = i + 1;
            }
        };
        forbid_writers_of(i);
        for (NodeIndex j : lists.row(i)) forbid_writers_of(j);
        std::uint32_t c = 0;
        while (c < taken_by.size() && taken_by[c] == i + 1) ++c;
        colour[i] = c;
        if (c >= colours) {
            colours = c + 1;
            taken_by.resize(colours, 0);
        }
    }
    if (group_size == 0) group_size = std::clamp<std::size_t>(n / (16 * std::max<std::size_t>(colours, 1)), 16, 4096);
    ScatterPlan plan;
    plan.scheme = ScatterScheme::Graph;
    plan.centres.reserve(n);
    std::vector<std::vector<NodeIndex>> members(colours);
    for (std::size_t i = 0; i < n; ++i) members[colour[i]].push_back(static_cast<NodeIndex>(i));
    for (std::uint32_t c = 0; c < colours; ++c) {
        for (std::size_t k = 0; k < members[c].size(); k += group_size) {
            const std::size_t end = std::min(members[c].size(), k + group_size);
            plan.centres.insert(plan.centres.end(), members[c].begin() + k, members[c].begin() + end);
            plan.group_offsets.push_back(plan.centres.size());
        }
        plan.colour_offsets.push_back(plan.group_offsets.size() - 1);
    }
    return plan;
}

ScatterPlan make_plan(ScatterScheme scheme, const CompressedRows& lists, const PositionView& x,
                      std::size_t node_count) {
    switch (scheme) {
        case ScatterScheme::Slabs: return make_slab_plan(lists, x);
        case ScatterScheme::Cells: return make_cell_plan(lists, x);
        case ScatterScheme::Graph: return make_graph_plan(lists, node_count);
        case ScatterScheme::Serial: break;
    }
    return make_serial_plan(lists);
}

bool plan_is_conflict_free(const ScatterPlan& plan, const CompressedRows& lists, std::size_t node_count) {
    std::vector<int> seen(lists.rows(), 0);
    for (NodeIndex i : plan.centres) {
        if (i >= lists.rows() || seen[i]++) return false;
    }
    if (plan.centres.size() != lists.rows()) return false;
    std::vector<std::size_t> written_by(node_count, std::numeric_limits<std::size_t>::max());
    for (std::size_t colour = 0; colour < plan.colours(); ++colour) {
        std::fill(written_by.begin(), written_by.end(), std::numeric_limits<std::size_t>::max());
        for (std::size_t g = plan.colour_offsets[colour]; g < plan.colour_offsets[colour + 1]; ++g) {
            const auto mark = [&](std::size_t m) {
                if (written_by[m] != std::numeric_limits<std::size_t>::max() && written_by[m] != g) return false;
                written_by[m] = g;
                return true;
            };
            for (NodeIndex i : plan.group(g)) {
                if (!mark(i)) return false;
                for (NodeIndex j : lists.row(i)) {
                    if (!mark(j)) return false;
                }
            }
        }
    }
    return true;
}

}  // namespace gpa
