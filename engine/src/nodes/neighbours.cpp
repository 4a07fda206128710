#include "gpa/engine/neighbours.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

namespace {

constexpr std::size_t search_block = 1024;  // centres per task; fixed so lists never depend on threads
// Rows per task of the cut of candidates to pairs (filter_rows): each row is cut on its own, so the
// split never changes the lists; small enough that 10^3 nodes still give every thread work.
constexpr std::size_t filter_block = 128;

double squared_distance(const NodeStore& s, std::size_t i, std::size_t j) {
    double r2 = 0.0;
    for (int c = 0; c < s.dim(); ++c) {
        const double d = s.position[c][j] - s.position[c][i];
        r2 += d * d;
    }
    return r2;
}

bool is_pair(const NodeStore& s, double a, std::size_t i, std::size_t j) {
    return within_influence(squared_distance(s, i, j), pair_smoothing_length(a, s.diameter[i], s.diameter[j]));
}

// The search's test for the pairs (i, j0) and (i, j1) at once, in the lanes of a GCC vector, each
// lane the arithmetic of is_pair (skin 0: r_ij < 2 h_ij, within_influence) or of the candidate
// rule (r_ij < 2 h_ij + skin: pairs, or nodes that may become pairs before the next search).
template <int D>
std::array<bool, 2> within_reach(const std::array<const double*, D>& x, const double* d, const std::array<double, D>& xi, double di,
                                 double a, double skin, NodeIndex j0, NodeIndex j1) {
    using Lanes = double __attribute__((vector_size(16)));
    Lanes r2 = Lanes{0.0, 0.0};
    for (int c = 0; c < D; ++c) {
        const Lanes dx = Lanes{x[c][j0], x[c][j1]} - xi[c];
        r2 += dx * dx;
    }
    const Lanes h = pair_smoothing_length(a, Lanes{di, di}, Lanes{d[j0], d[j1]});
    const Lanes reach = 2.0 * h + skin;
    const auto near = skin > 0.0 ? (r2 < reach * reach) : (r2 < 4.0 * h * h);
    return {near[0] != 0, near[1] != 0};
}

// Copies the nodes js[0 .. count) within reach of centre i (within_reach; never i itself) to
// `within`, in order, and returns how many: the dimension fixed at compile time, two nodes at a
// time (an odd last node takes both lanes and its second is dropped), no branch on the outcome.
template <int D>
std::size_t gather_within(const NodeStore& s, double a, double skin, std::size_t i, const NodeIndex* js, std::size_t count,
                          NodeIndex* within) {
    std::array<const double*, D> x;
    for (int c = 0; c < D; ++c) x[c] = s.position[c].data();
    std::array<double, D> xi;
    for (int c = 0; c < D; ++c) xi[c] = x[c][i];
    const double* d = s.diameter.data();
    std::size_t found = 0;
    for (std::size_t k = 0; k < count; k += 2) {
        const bool second = k + 1 < count;
        const NodeIndex j0 = js[k], j1 = second ? js[k + 1] : j0;
        const auto near = within_reach<D>(x, d, xi, d[i], a, skin, j0, j1);
        within[found] = j0;
        found += static_cast<std::size_t>(near[0] & (j0 != i));
        if (second) {
            within[found] = j1;
            found += static_cast<std::size_t>(near[1] & (j1 != i));
        }
    }
    return found;
}

}  // namespace

double largest_interaction_radius(const NodeStore& nodes, double a, std::size_t count) {
    double d_max = 0.0;
    for (std::size_t i = 0; i < count; ++i) d_max = std::max(d_max, nodes.diameter[i]);
    return 2.0 * a * d_max;
}

namespace {

// Puts the `count` nodes member(0), ..., member(count - 1) (increasing indices) into the grid.
template <class Member>
void build_grid(CellGrid& grid, const NodeStore& store, std::size_t count, Member member, double min_cell_size) {
    grid.dim = store.dim();
    std::array<double, 3> hi{0, 0, 0};
    grid.origin = {0, 0, 0};
    for (int c = 0; c < grid.dim; ++c) {
        grid.origin[c] = std::numeric_limits<double>::infinity();
        hi[c] = -std::numeric_limits<double>::infinity();
        for (std::size_t k = 0; k < count; ++k) {
            grid.origin[c] = std::min(grid.origin[c], store.position[c][member(k)]);
            hi[c] = std::max(hi[c], store.position[c][member(k)]);
        }
        if (count == 0) grid.origin[c] = hi[c] = 0.0;
        if (!std::isfinite(grid.origin[c]) || !std::isfinite(hi[c])) {
            throw InputError(fmt::format("neighbour search: a node has a non-finite coordinate {}", c));
        }
    }
    grid.cell_size = min_cell_size > 0.0 ? min_cell_size : 1.0;
    // Bound the grid by the node count: far-apart bodies must not make an enormous empty grid.
    for (;;) {
        double total = 1.0;
        grid.cells = {1, 1, 1};
        for (int c = 0; c < grid.dim; ++c) {
            const double n = std::floor((hi[c] - grid.origin[c]) / grid.cell_size) + 1.0;
            grid.cells[c] = static_cast<std::size_t>(std::min(n, 1e12));
            total *= n;
        }
        if (total <= 2.0 * static_cast<double>(count) + 64.0) break;
        grid.cell_size *= 1.25;
    }
    const std::size_t total = grid.cells[0] * grid.cells[1] * grid.cells[2];
    grid.cell_start.assign(total + 1, 0);
    std::vector<std::size_t> key(count);
    for (std::size_t k = 0; k < count; ++k) {
        key[k] = grid.linear(grid.cell_of(store, member(k)));
        ++grid.cell_start[key[k] + 1];
    }
    std::partial_sum(grid.cell_start.begin(), grid.cell_start.end(), grid.cell_start.begin());
    grid.nodes.resize(count);
    std::vector<std::size_t> next(grid.cell_start.begin(), grid.cell_start.end() - 1);
    for (std::size_t k = 0; k < count; ++k) grid.nodes[next[key[k]]++] = static_cast<NodeIndex>(member(k));
}

}  // namespace

void CellGrid::build(const NodeStore& store, std::size_t count, double min_cell_size) {
    build_grid(*this, store, count, [](std::size_t k) { return k; }, min_cell_size);
}

void CellGrid::build(const NodeStore& store, const std::vector<NodeIndex>& members, double min_cell_size) {
    build_grid(*this, store, members.size(), [&](std::size_t k) { return static_cast<std::size_t>(members[k]); }, min_cell_size);
}

DiameterSpread diameter_spread(const NodeStore& nodes, std::size_t count) {
    DiameterSpread s;
    if (count == 0) return s;
    double sum = 0.0;
    for (std::size_t i = 0; i < count; ++i) {
        sum += nodes.diameter[i];
        s.largest = std::max(s.largest, nodes.diameter[i]);
    }
    s.cut = 2.0 * sum / static_cast<double>(count);
    if (!(s.largest > s.cut)) {
        // Nothing outsized (or diameters that are not finite: the phases report those).
        s.bulk = s.largest;
        s.cut = std::max(s.cut, s.largest);
        return s;
    }
    for (std::size_t i = 0; i < count; ++i) {
        if (nodes.diameter[i] <= s.cut) s.bulk = std::max(s.bulk, nodes.diameter[i]);
    }
    return s;
}

double bulk_interaction_radius(const NodeStore& nodes, double a, std::size_t count) {
    return 2.0 * a * diameter_spread(nodes, count).bulk;
}

std::array<std::size_t, 3> CellGrid::cell_of(const NodeStore& store, std::size_t i) const {
    std::array<std::size_t, 3> c{0, 0, 0};
    for (int k = 0; k < dim; ++k) {
        // The cell floor((x - origin) / edge), clamped to the grid: for a positive quotient the
        // conversion's truncation is the floor, without floor's own tests and branches (the
        // baseline x86-64 build has no rounding instruction; the search calls this for every node).
        const double f = (store.position[k][i] - origin[k]) / cell_size;
        const double last = static_cast<double>(cells[k] - 1);
        c[k] = !(f > 0.0) ? 0 : (f >= last ? cells[k] - 1 : static_cast<std::size_t>(f));
    }
    return c;
}

bool needs_search(const NodeStore& nodes, std::size_t centres) {
    for (std::size_t i = 0; i < centres; ++i) {
        if (nodes.connectivity[i] == Connectivity::Variable) return true;
    }
    for (std::size_t i = 1; i < nodes.size(); ++i) {
        if (nodes.body[i] != nodes.body[0]) return true;
    }
    return false;
}

void find_neighbours(const NodeStore& nodes, double a, std::size_t centres, CompressedRows& out,
                     NeighbourScratch& scratch, const CompressedRows* extra_fixed, double skin, bool fixed_may_switch) {
    find_neighbours(nodes, InfluenceDistance(a), centres, out, scratch, extra_fixed, skin, fixed_may_switch);
}

void find_neighbours(const NodeStore& nodes, InfluenceDistance influence, std::size_t centres, CompressedRows& out,
                     NeighbourScratch& scratch, const CompressedRows* extra_fixed, double skin, bool fixed_may_switch,
                     std::span<const NodeIndex> only) {
    const double a = influence.value();
    if (!(skin >= 0.0) || !std::isfinite(skin)) throw InputError(fmt::format("find_neighbours: skin {} must be a finite length >= 0", skin));
    const std::size_t n = nodes.size();
    if (centres > n) throw InputError(fmt::format("find_neighbours: {} centres of {} nodes", centres, n));
    for (std::size_t k = 0; k < only.size(); ++k) {
        if (only[k] >= centres || (k > 0 && only[k] <= only[k - 1])) {
            throw InputError(fmt::format("find_neighbours: the centres to search must ascend below {} (entry {} is {})", centres, k, only[k]));
        }
    }
    // The rows to make: every centre's, or those of `only`.
    const std::size_t rows = only.empty() ? centres : only.size();
    const auto centre_of = [&](std::size_t k) -> std::size_t { return only.empty() ? k : only[k]; };
    if (nodes.fixed_neighbours.rows() != 0 && nodes.fixed_neighbours.rows() < centres) {
        throw InputError(fmt::format("find_neighbours: fixed lists cover {} of {} centres",
                                     nodes.fixed_neighbours.rows(), centres));
    }
    if (extra_fixed && extra_fixed->rows() != 0 && extra_fixed->rows() < centres) {
        throw InputError(fmt::format("find_neighbours: extra fixed lists cover {} of {} centres", extra_fixed->rows(), centres));
    }
    // Candidates that outlive switching (see the header): needed only where fixed nodes may switch.
    const bool candidates = skin > 0.0 && fixed_may_switch;
    const bool search = needs_search(nodes, centres) || candidates;
    // Cells of half the reach, and the 5 (or 5 x 5 x 5) cells around a centre's: the cells cover
    // 2.5 reaches across instead of 3, which spares about a third of the distance checks in 2D
    // and half in 3D. (The grid may enlarge its cells to bound their number; the span follows.)
    // The reach is that of the bulk of the nodes; outsized nodes (DiameterSpread) have a grid of
    // their own, in cells of their reach, which every centre searches too.
    const DiameterSpread spread = search ? diameter_spread(nodes, n) : DiameterSpread{};
    const bool split = search && spread.any_outsized();
    const double reach = 2.0 * a * spread.bulk + skin;
    if (split) {
        scratch.bulk.clear();
        scratch.outsized.clear();
        for (std::size_t i = 0; i < n; ++i) (nodes.diameter[i] > spread.cut ? scratch.outsized : scratch.bulk).push_back(static_cast<NodeIndex>(i));
        scratch.grid.build(nodes, scratch.bulk, 0.5 * reach);
        scratch.outsized_grid.build(nodes, scratch.outsized, 0.5 * (2.0 * a * spread.largest + skin));
    } else if (search) {
        scratch.grid.build(nodes, n, 0.5 * reach);
    }
    const CellGrid& grid = scratch.grid;
    const int dim = nodes.dim();
    // Which cells hold only fixed nodes of one body (NeighbourScratch::cell_body): a fixed centre
    // whose cells within reach all do has no pair there but its lattice neighbours. Only fixed
    // centres look (an all-variable search makes no map).
    bool any_fixed_centre = false;
    for (std::size_t i = 0; i < centres && !any_fixed_centre; ++i) any_fixed_centre = nodes.connectivity[i] == Connectivity::Fixed;
    if (search && any_fixed_centre) {
        const std::size_t cell_count = grid.cell_start.size() - 1;
        scratch.cell_body.resize(cell_count);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cell_count, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t cell = r.begin(); cell != r.end(); ++cell) {
                std::int32_t state = NeighbourScratch::kEmptyCell;
                for (std::size_t k = grid.cell_start[cell]; k < grid.cell_start[cell + 1] && state != NeighbourScratch::kMixedCell; ++k) {
                    const NodeIndex j = grid.nodes[k];
                    if (nodes.connectivity[j] != Connectivity::Fixed || (state >= 0 && state != nodes.body[j])) {
                        state = NeighbourScratch::kMixedCell;
                    } else {
                        state = nodes.body[j];
                    }
                }
                scratch.cell_body[cell] = state;
            }
        });
    }
    scratch.quiet.assign(candidates ? centres : 0, 0);
    // A neighbour is less than `reach` away along each axis, so at most ceil(reach / edge) cells.
    const std::size_t span = search && grid.cell_size > 0.0 ? static_cast<std::size_t>(std::ceil(reach / grid.cell_size)) : 1;
    // The cells an outsized centre i searches in the bulk grid: its pairs there are closer than
    // a (d_i + d_bulk) + skin. In the outsized grid every centre searches a (d_i + d_largest) + skin.
    const auto cells_within = [&](const CellGrid& g, double distance) {
        return g.cell_size > 0.0 ? static_cast<std::size_t>(std::ceil(distance / g.cell_size)) : std::size_t{1};
    };

    // Lattice pairs link two fixed nodes; a lattice neighbour that has switched is a variable pair
    // now, found by the search like any other node (spec section 2, mixed pairs).
    const auto lattice_neighbour = [&](std::size_t i, NodeIndex j) {
        for (NodeIndex k : nodes.fixed_neighbours.row_or_empty(i)) {
            if (k == j) return true;
        }
        if (extra_fixed) {
            for (NodeIndex k : extra_fixed->row_or_empty(i)) {
                if (k == j) return true;
            }
        }
        return false;
    };
    // Calls emit(j) for every neighbour j of centre i, in the order described in the header.
    const auto visit = [&](std::size_t i, auto&& emit) {
        const bool fixed = nodes.connectivity[i] == Connectivity::Fixed;
        // Every lattice neighbour still fixed: a centre can be quiet only then (below), since the
        // cut keeps a quiet row whole, and a lattice neighbour that has switched is a pair only
        // within reach, which the box below need not cover once the lattice has stretched.
        bool lattice_fixed = true;
        if (fixed) {
            for (NodeIndex j : nodes.fixed_neighbours.row_or_empty(i)) {
                const bool fixed_j = nodes.connectivity[j] == Connectivity::Fixed;
                lattice_fixed &= fixed_j;
                if (candidates || fixed_j) emit(j);
            }
            if (extra_fixed) {
                for (NodeIndex j : extra_fixed->row_or_empty(i)) {
                    const bool fixed_j = nodes.connectivity[j] == Connectivity::Fixed;  // a ghost has its source's mode
                    lattice_fixed &= fixed_j;
                    if (candidates || fixed_j) emit(j);
                }
            }
        }
        if (!search) return;
        const std::int32_t own_body = nodes.body[i];
        // The cells of g within `cells_around` of the centre's, as a box of cell coordinates.
        const auto box = [&](const CellGrid& g, std::size_t cells_around, std::array<std::size_t, 3>& lo, std::array<std::size_t, 3>& hi) {
            const auto home = g.cell_of(nodes, i);
            for (int k = 0; k < dim; ++k) {
                lo[k] = home[k] < cells_around ? 0 : home[k] - cells_around;
                hi[k] = std::min(g.cells[k] - 1, home[k] + cells_around);
            }
        };
        // True when every cell of the box holds only fixed nodes of the centre's body, or none.
        const auto quiet_box = [&](const std::array<std::size_t, 3>& lo, const std::array<std::size_t, 3>& hi) {
            std::array<std::size_t, 3> c{0, 0, 0};
            for (c[2] = lo[2]; c[2] <= hi[2]; ++c[2]) {
                for (c[1] = lo[1]; c[1] <= hi[1]; ++c[1]) {
                    for (c[0] = lo[0]; c[0] <= hi[0]; ++c[0]) {
                        const std::int32_t state = scratch.cell_body[grid.linear(c)];
                        if (state != NeighbourScratch::kEmptyCell && state != own_body) return false;
                    }
                }
            }
            return true;
        };
        // Scans the box of cells within cells_around of the centre's for nodes closer than
        // `distance` (the largest reach of a pair of this centre in g). A cell of the box that lies
        // wholly beyond that distance holds no pair and is skipped: in 3D the corner cells of the
        // 5 x 5 x 5 box, about a third of its volume. The skip leaves the order of the rest, so
        // the lists are the same entry for entry.
        const auto scan = [&](const CellGrid& g, std::size_t cells_around, double distance) {
            std::array<std::size_t, 3> lo{0, 0, 0}, hi{0, 0, 0};
            box(g, cells_around, lo, hi);
            if (fixed && lattice_fixed && &g == &grid && quiet_box(lo, hi)) {
                if (candidates) scratch.quiet[i] = 1;
                return;
            }
            // Per axis, the gap from the centre to each cell row of the box (0 where the centre
            // lies within the row's span), for boxes up to 16 cells across (larger ones, outsized
            // centres, are scanned whole). The limit carries a margin far above the rounding that
            // can put a node just outside its cell's span (a billionth of the distance, and 1e-12
            // of the largest coordinate of the centre and the grid).
            constexpr std::size_t widest = 16;
            std::array<std::array<double, widest>, 3> gap;  // rows [0, hi - lo] of each axis set below
            gap[1][0] = gap[2][0] = 0.0;                     // the single row of an axis beyond dim
            bool cull = true;
            double largest_coordinate = 0.0;
            for (int k = 0; k < dim; ++k) {
                if (hi[k] - lo[k] + 1 > widest) cull = false;
                const double far_edge = g.origin[k] + static_cast<double>(g.cells[k]) * g.cell_size;
                largest_coordinate = std::max({largest_coordinate, std::abs(nodes.position[k][i]), std::abs(g.origin[k]), std::abs(far_edge)});
            }
            if (cull) {
                for (int k = 0; k < dim; ++k) {
                    const double x = nodes.position[k][i];
                    for (std::size_t c = lo[k]; c <= hi[k]; ++c) {
                        const double lower = g.origin[k] + static_cast<double>(c) * g.cell_size;
                        const double upper = lower + g.cell_size;
                        gap[static_cast<std::size_t>(k)][c - lo[k]] = x < lower ? lower - x : (x > upper ? x - upper : 0.0);
                    }
                }
            }
            const double limit = distance * (1.0 + 1e-9) + 1e-12 * largest_coordinate;
            const double limit2 = limit * limit;
            std::array<std::size_t, 3> c{0, 0, 0};
            for (c[2] = lo[2]; c[2] <= hi[2]; ++c[2]) {
                const double gz = cull ? gap[2][c[2] - lo[2]] : 0.0;
                for (c[1] = lo[1]; c[1] <= hi[1]; ++c[1]) {
                    const double gy = cull ? gap[1][c[1] - lo[1]] : 0.0;
                    for (c[0] = lo[0]; c[0] <= hi[0]; ++c[0]) {
                        const double gx = cull ? gap[0][c[0] - lo[0]] : 0.0;
                        if (cull && gx * gx + gy * gy + gz * gz > limit2) continue;
                        const std::size_t cell = g.linear(c);
                        // The distance first: most nodes of the cells are out of reach, and the
                        // lattice look-up below walks the centre's lattice row. The nodes within
                        // reach are gathered without a branch on the test (a third or so pass it,
                        // in no pattern a predictor follows), up to 32 at a time, then taken in order.
                        std::array<NodeIndex, 32> within;
                        const std::size_t end = g.cell_start[cell + 1];
                        for (std::size_t k = g.cell_start[cell]; k < end;) {
                            const std::size_t stop = std::min(end, k + within.size());
                            const std::size_t found = dim == 2 ? gather_within<2>(nodes, a, skin, i, &g.nodes[k], stop - k, within.data())
                                                               : gather_within<3>(nodes, a, skin, i, &g.nodes[k], stop - k, within.data());
                            k = stop;
                            for (std::size_t h = 0; h < found; ++h) {
                                const NodeIndex j = within[h];
                                if (fixed && nodes.body[j] == own_body) {
                                    // A lattice neighbour is in the row already; another fixed node of the
                                    // body is no pair of a fixed centre, but may become one when either switches.
                                    if (candidates ? lattice_neighbour(i, j) : nodes.connectivity[j] == Connectivity::Fixed) continue;
                                }
                                emit(j);
                            }
                        }
                    }
                }
            }
        };
        if (!split) {
            scan(grid, span, reach);
            return;
        }
        const double d_i = nodes.diameter[i];
        const double bulk_distance = d_i > spread.cut ? a * (d_i + spread.bulk) + skin : reach;
        scan(grid, d_i > spread.cut ? cells_within(grid, bulk_distance) : span, bulk_distance);
        const double outsized_distance = a * (d_i + spread.largest) + skin;
        scan(scratch.outsized_grid, cells_within(scratch.outsized_grid, outsized_distance), outsized_distance);
    };

    // One gather per row, in waves of blocks: the blocks of a wave (search_block centres each, in
    // parallel) gather their rows into buffers of their own, then the wave's rows are copied after
    // the last wave's. (Counting every row first and filling after, straight into the lists, walked
    // every cell twice.) A wave is a thirty-second of the blocks, or four per thread if that is
    // more, so that its buffers add little to the peak of a search: the lists themselves. Where a
    // row lands depends on the rows before it alone, not on the waves or the threads.
    resize_discarding(out.offsets, rows + 1);
    out.offsets[0] = 0;
    const std::size_t blocks = (rows + search_block - 1) / search_block;
    const auto threads = static_cast<std::size_t>(std::max(1, tbb::this_task_arena::max_concurrency()));
    const std::size_t wave = std::max((blocks + 31) / 32, 4 * threads);
    std::vector<std::vector<NodeIndex>>& buffers = scratch.block_entries;
    buffers.resize(std::min(blocks, wave));
    // The lists' size, guessed before the first wave from every 32nd row (counted, a thirty-second
    // of a scan more): room made then costs no copy, while lists that outgrow their room in a later
    // wave are copied, the old array beside the new one (the first waves' rows, in locality order,
    // may be a face's, with half the neighbours of the bulk). No room is made for a guess beyond
    // the memory limit: the waves' own checks then stop the search with the limit's error, at the
    // entries actually made, instead of an allocation failing or a guess refusing lists that fit.
    constexpr std::size_t sample_stride = 32;
    const std::size_t sampled = (rows + sample_stride - 1) / sample_stride;
    const std::size_t sample_entries = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, sampled, 64), std::size_t{0},
        [&](const tbb::blocked_range<std::size_t>& r, std::size_t sum) {
            for (std::size_t s = r.begin(); s != r.end(); ++s) visit(centre_of(s * sample_stride), [&](NodeIndex) { ++sum; });
            return sum;
        },
        std::plus<>());
    const std::size_t estimate = sampled > 0 ? sample_entries * rows / sampled : 0;
    bool estimate_fits = true;
    if (scratch.check_entries && only.empty()) {
        try {
            scratch.check_entries(estimate);
        } catch (const LimitError&) {
            estimate_fits = false;
        }
    }
    if (estimate_fits && estimate > out.indices.capacity()) {
        std::vector<NodeIndex>().swap(out.indices);  // the old lists go before the new ones are made
        out.indices.reserve(estimate + estimate / per_entry_slack);
    }
    for (std::size_t first_block = 0; first_block < blocks; first_block += wave) {
        const std::size_t last_block = std::min(blocks, first_block + wave);
        const std::size_t first_row = first_block * search_block, last_row = std::min(rows, last_block * search_block);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(first_block, last_block, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t b = r.begin(); b != r.end(); ++b) {
                std::vector<NodeIndex>& entries = buffers[b - first_block];
                entries.clear();
                const std::size_t end = std::min(rows, (b + 1) * search_block);
                for (std::size_t k = b * search_block; k != end; ++k) {
                    const std::size_t before = entries.size();
                    visit(centre_of(k), [&](NodeIndex j) { entries.push_back(j); });
                    out.offsets[k + 1] = entries.size() - before;
                }
            }
        });
        for (std::size_t k = first_row; k < last_row; ++k) out.offsets[k + 1] += out.offsets[k];
        const std::size_t entries = out.offsets[last_row];
        // The memory limit (Simulation) sees the entries made so far, before they are placed.
        if (scratch.check_entries && only.empty()) scratch.check_entries(entries);
        if (entries > out.indices.capacity()) {
            // Room for all rows at the rate of those made so far.
            const auto rate = static_cast<double>(entries) / static_cast<double>(last_row);
            const std::size_t guess = std::max(entries, static_cast<std::size_t>(rate * static_cast<double>(rows)));
            out.indices.reserve(guess + guess / per_entry_slack);
        }
        out.indices.resize(entries);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(first_block, last_block, 1), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t b = r.begin(); b != r.end(); ++b) {
                const std::vector<NodeIndex>& made = buffers[b - first_block];
                std::copy(made.begin(), made.end(), out.indices.begin() + static_cast<std::ptrdiff_t>(out.offsets[b * search_block]));
            }
        });
    }
    if (blocks == 0) {
        out.indices.clear();
        if (scratch.check_entries && only.empty()) scratch.check_entries(0);
    }
}

CompressedRows find_neighbours(const NodeStore& nodes, double a, std::size_t centres) {
    CompressedRows out;
    NeighbourScratch scratch;
    find_neighbours(nodes, a, centres, out, scratch);
    return out;
}

namespace {

// The kept entries of the cut as bits, each row's in words of its own: row i starts at word
// i + floor(offsets[i] / 64) and takes ceil(size / 64) words, which never reach the next row's
// first word (floor((o + n) / 64) - floor(o / 64) >= floor(n / 64), and one more word per row).
// So a task writes whole words of its own rows, and the bits take one word per row and one per 64
// candidates: 1 + n / 8 bytes per row where a byte per candidate took n (31 in 2D, 130 in 3D at
// a = 1.3 with the default skin).
std::size_t first_keep_word(std::size_t row, std::size_t first_entry) { return row + (first_entry >> 6); }

template <int D>
void filter_rows(const NodeStore& nodes, double a, const CompressedRows& candidates,
                 const std::vector<std::uint32_t>& lattice_entries, const LatticeRowsKept& kept_rows, CompressedRows& out,
                 std::vector<std::uint64_t>& keep) {
    const std::size_t rows = candidates.rows();
    std::array<const double*, D> x{};
    for (int c = 0; c < D; ++c) x[c] = nodes.position[c].data();
    const double* d = nodes.diameter.data();
    const NodeIndex* index = candidates.indices.data();
    // Pass 1: mark the kept entries and count them per row (the counts go to offsets[i + 1]).
    // The rule of spec section 2 as it stands now (nodes may have switched since the search): a
    // lattice entry is kept while both its nodes are fixed, and otherwise like any other entry,
    // when r_ij < 2 h_ij and it is not a pair of two fixed nodes of one body.
    const Connectivity* mode = nodes.connectivity.data();
    const std::int32_t* body = nodes.body.data();
    const std::size_t* candidate_offsets = candidates.offsets.data();
    const std::uint32_t* lattice_counts = lattice_entries.empty() ? nullptr : lattice_entries.data();  // none: 0 per row
    std::size_t* counts = out.offsets.data();
    std::uint64_t* keep_out = keep.data();
    // A fixed centre's row of lattice entries alone is kept whole where no lattice pair can have
    // lost a node to switching (LatticeRowsKept): its count is its length, its entries are
    // copied in pass 2, and neither pass reads them one by one.
    const bool no_switching = !kept_rows.switching;
    const std::uint8_t* const quiet = kept_rows.quiet;
    const auto whole = [mode, lattice_counts, quiet, no_switching](std::size_t i, std::size_t first, std::size_t last) {
        return lattice_counts && mode[i] == Connectivity::Fixed && first + lattice_counts[i] >= last &&
               (no_switching || (quiet && quiet[i]));
    };
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, filter_block), [&](const tbb::blocked_range<std::size_t>& r) {
        // The pointers and a as locals of the task, so that the loop need not load them again
        // after each store through a pointer that might alias its captures.
        const std::array<const double*, D> xs = x;
        const double* const ds = d;
        const NodeIndex* const js = index;
        const Connectivity* const modes = mode;
        const std::int32_t* const bodies = body;
        const double influence = a;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const std::size_t first = candidate_offsets[i], last = candidate_offsets[i + 1];
            if (whole(i, first, last)) {
                counts[i + 1] = last - first;
                continue;
            }
            const std::size_t lattice_end = lattice_counts ? std::min(last, first + lattice_counts[i]) : first;
            const bool fixed_centre = modes[i] == Connectivity::Fixed;
            std::array<double, D> xi;
            for (int c = 0; c < D; ++c) xi[c] = xs[c][i];
            const double di = ds[i];
            const std::int32_t body_i = bodies[i];
            std::size_t kept = 0;
            std::uint64_t* word = keep_out + first_keep_word(i, first);
            // The row in runs of up to 64 entries, one word each: no test for a full word per entry.
            for (std::size_t start = first; start < last; start += 64) {
                const std::size_t stop = std::min(last, start + 64);
                std::uint64_t bits = 0;
                for (std::size_t e = start; e < stop; ++e) {
                    const NodeIndex j = js[e];
                    const bool both_fixed = fixed_centre && modes[j] == Connectivity::Fixed;
                    bool pair;
                    if (e < lattice_end && both_fixed) {
                        pair = true;
                    } else if (both_fixed && bodies[j] == body_i) {
                        pair = false;
                    } else {
                        double r2 = 0.0;
                        for (int c = 0; c < D; ++c) {
                            const double dx = xs[c][j] - xi[c];
                            r2 += dx * dx;
                        }
                        // The search's rule, within_influence(r^2, h_ij) (weights.hpp).
                        pair = within_influence(r2, pair_smoothing_length(influence, di, ds[j]));
                    }
                    bits |= std::uint64_t{pair} << (e - start);
                    kept += pair;
                }
                *word++ = bits;
            }
            counts[i + 1] = kept;
        }
    });
    for (std::size_t i = 0; i < rows; ++i) out.offsets[i + 1] += out.offsets[i];
    resize_discarding(out.indices, out.offsets[rows], per_entry_slack);
    // Pass 2: copy the kept entries in order, a set bit at a time (the lowest first), without a
    // branch on each candidate, which no predictor guesses (about a third of them go).
    const std::uint64_t* kept = keep.data();
    NodeIndex* kept_index = out.indices.data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, filter_block), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            NodeIndex* o = kept_index + out.offsets[i];
            const std::size_t first = candidates.offsets[i], last = candidates.offsets[i + 1];
            if (whole(i, first, last)) {
                std::copy(index + first, index + last, o);
                continue;
            }
            const std::uint64_t* word = kept + first_keep_word(i, first);
            for (std::size_t base = first; base < last; base += 64, ++word) {
                for (std::uint64_t bits = *word; bits != 0; bits &= bits - 1) *o++ = index[base + static_cast<std::size_t>(std::countr_zero(bits))];
            }
        }
    });
}

}  // namespace

void filter_candidates(const NodeStore& nodes, double a, const CompressedRows& candidates,
                       const std::vector<std::uint32_t>& lattice_entries, CompressedRows& out,
                       std::vector<std::uint64_t>& keep, const LatticeRowsKept& kept_rows) {
    const std::size_t rows = candidates.rows();
    if (!lattice_entries.empty() && lattice_entries.size() < rows) {
        throw InputError(fmt::format("filter_candidates: {} lattice counts for {} rows", lattice_entries.size(), rows));
    }
    if (kept_rows.quiet && kept_rows.quiet_rows < rows) {
        throw InputError(fmt::format("filter_candidates: {} quiet flags for {} rows", kept_rows.quiet_rows, rows));
    }
    resize_discarding(keep, rows + candidates.entries() / 64 + 1, per_entry_slack);  // first_keep_word's words
    resize_discarding(out.offsets, rows + 1);
    out.offsets[0] = 0;
    if (nodes.dim() == 2) {
        filter_rows<2>(nodes, a, candidates, lattice_entries, kept_rows, out, keep);
    } else {
        filter_rows<3>(nodes, a, candidates, lattice_entries, kept_rows, out, keep);
    }
}


CompressedRows find_neighbours_brute_force(const NodeStore& nodes, double a, std::size_t centres,
                                           const CompressedRows* extra_fixed) {
    check_influence_distance(a);
    std::vector<std::vector<NodeIndex>> rows(centres);
    for (std::size_t i = 0; i < centres; ++i) {
        const bool fixed = nodes.connectivity[i] == Connectivity::Fixed;
        if (fixed) {
            for (NodeIndex j : nodes.fixed_neighbours.row_or_empty(i)) {
                if (nodes.connectivity[j] == Connectivity::Fixed) rows[i].push_back(j);
            }
            if (extra_fixed) {
                const auto extra = extra_fixed->row_or_empty(i);
                rows[i].insert(rows[i].end(), extra.begin(), extra.end());
            }
        }
        for (std::size_t j = 0; j < nodes.size(); ++j) {
            if (j == i || (fixed && nodes.body[j] == nodes.body[i] && nodes.connectivity[j] == Connectivity::Fixed)) continue;
            if (is_pair(nodes, a, i, j)) rows[i].push_back(static_cast<NodeIndex>(j));
        }
    }
    return make_compressed_rows(rows);
}

std::vector<NodeIndex> locality_order(const NodeStore& nodes, double cell_size, std::size_t first, std::size_t last) {
    const std::size_t n = nodes.size();
    std::vector<NodeIndex> order(n);
    std::iota(order.begin(), order.end(), NodeIndex{0});
    if (last <= first + 1) return order;
    const int dim = nodes.dim();
    std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
    for (int c = 0; c < dim; ++c) {
        const auto [mn, mx] = std::minmax_element(nodes.position[c].begin() + first, nodes.position[c].begin() + last);
        lo[c] = *mn;
        hi[c] = *mx;
    }
    int slowest = 0;
    for (int c = 1; c < dim; ++c) {
        if (hi[c] - lo[c] > hi[slowest] - lo[slowest]) slowest = c;
    }
    std::array<int, 3> axes{0, 1, 2};  // fastest to slowest
    std::rotate(axes.begin(), axes.begin() + slowest + 1, axes.begin() + dim);
    const double edge = cell_size > 0.0 ? cell_size : 1.0;
    std::vector<std::pair<std::uint64_t, NodeIndex>> keyed(last - first);
    for (std::size_t i = first; i < last; ++i) {
        std::uint64_t key = 0;
        for (int k = dim - 1; k >= 0; --k) {
            const int c = axes[k];
            const double span = std::floor((hi[c] - lo[c]) / edge) + 1.0;
            const auto cell = static_cast<std::uint64_t>(std::floor((nodes.position[c][i] - lo[c]) / edge));
            key = key * static_cast<std::uint64_t>(std::min(span, 2.0e6)) + std::min<std::uint64_t>(cell, 1999999);
        }
        keyed[i - first] = {key, static_cast<NodeIndex>(i)};
    }
    // Ties broken by node index: the order of a stable sort, without its buffer.
    std::sort(keyed.begin(), keyed.end());
    for (std::size_t k = 0; k < keyed.size(); ++k) order[first + k] = keyed[k].second;
    return order;
}

}  // namespace gpa
