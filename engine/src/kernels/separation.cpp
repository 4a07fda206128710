#include "gpa/engine/separation.hpp"

#include "gpa/engine/weights.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gpa {

namespace {

// n . sigma . n r^2 for n r = dx: the normal Cauchy stress of node i across a pair, times r^2
// (only its sign and the sum over both ends matter). Stress components in NodeStore order: 2D
// xx, zz, xz (theta-theta is out of plane); 3D xx, yy, zz, yz, xz, xy.
double normal_stress_r2(const NodeStore& nodes, std::size_t i, const std::array<double, 3>& dx) {
    const auto& s = nodes.deviatoric_stress;
    const double p = nodes.pressure[i] + nodes.viscous_pressure[i];
    if (nodes.dim() == 2) {
        const double xx = s[0][i] - p, zz = s[1][i] - p, xz = s[2][i];
        return dx[0] * dx[0] * xx + dx[1] * dx[1] * zz + 2.0 * dx[0] * dx[1] * xz;
    }
    const double xx = s[0][i] - p, yy = s[1][i] - p, zz = s[2][i] - p;
    const double yz = s[3][i], xz = s[4][i], xy = s[5][i];
    return dx[0] * dx[0] * xx + dx[1] * dx[1] * yy + dx[2] * dx[2] * zz +
           2.0 * (dx[1] * dx[2] * yz + dx[0] * dx[2] * xz + dx[0] * dx[1] * xy);
}

bool separable(const NodeStore& nodes, std::size_t i, std::size_t j, bool failed_pairs_separate) {
    return nodes.body[i] != nodes.body[j] || (failed_pairs_separate && (nodes.failed[i] || nodes.failed[j]));
}

// Both factors are formed from x_j - x_i and v_j - v_i, whose negatives give the same products, and
// the two stresses are added in a fixed order of the node numbers: the answer is the same from either end.
bool opening(const NodeStore& nodes, std::size_t i, std::size_t j) {
    const int d = nodes.dim();
    std::array<double, 3> dx{};
    double approach = 0.0;
    for (int c = 0; c < d; ++c) {
        dx[c] = nodes.position[c][j] - nodes.position[c][i];
        approach += (nodes.velocity[c][j] - nodes.velocity[c][i]) * dx[c];
    }
    if (approach < 0.0) return false;
    const std::size_t lo = i < j ? i : j, hi = i < j ? j : i;
    return normal_stress_r2(nodes, lo, dx) + normal_stress_r2(nodes, hi, dx) >= 0.0;
}

}  // namespace

bool pair_is_open(const NodeStore& nodes, std::size_t i, std::size_t j, bool failed_pairs_separate) {
    return separable(nodes, i, j, failed_pairs_separate) && opening(nodes, i, j);
}

namespace {

// Row i of remove_open_pairs: its entries [start, end) copied down to `out` without the open
// separable pairs; returns where the row now ends. Sets the row's closing speed and contact
// direction (when asked for) and counts its separable pairs.
std::size_t cut_row(CompressedRows& lists, const NodeStore& nodes, std::size_t i, std::size_t start, std::size_t end,
                    std::size_t out, bool failed_pairs_separate, double* closing_speed,
                    const std::array<double*, 3>& contact_direction, double influence_distance, SeparationCounts& counts) {
    const int d = nodes.dim();
    double closing = 0.0;
    bool touches_other_body = false;
    const std::size_t row_out = out;
    for (std::size_t e = start; e < end; ++e) {
        const NodeIndex j = lists.indices[e];
        if (separable(nodes, i, j, failed_pairs_separate)) {
            if (opening(nodes, i, j)) {
                ++counts.open;
                continue;
            }
            ++counts.closed;
            touches_other_body |= nodes.body[i] != nodes.body[j];
            if (closing_speed) {
                double dv_dx = 0.0, r2 = 0.0;
                for (int c = 0; c < d; ++c) {
                    const double dx = nodes.position[c][j] - nodes.position[c][i];
                    dv_dx += (nodes.velocity[c][j] - nodes.velocity[c][i]) * dx;
                    r2 += dx * dx;
                }
                if (dv_dx < 0.0 && r2 > 0.0) closing = std::max(closing, -dv_dx / std::sqrt(r2));
            }
        }
        lists.indices[out++] = j;
    }
    if (closing_speed) closing_speed[i] = closing;
    if (!contact_direction[0]) return out;
    // The outward direction of i's own body: minus the sum of the unit vectors to its kept
    // neighbours of that body (ghosts included, so that an axis or a plane is no surface), wanted
    // only where i touches another body.
    std::array<double, 3> outward{0.0, 0.0, 0.0};
    if (touches_other_body) {
        for (std::size_t e = row_out; e < out; ++e) {
            const NodeIndex j = lists.indices[e];
            if (nodes.body[j] != nodes.body[i]) continue;
            std::array<double, 3> dx{0.0, 0.0, 0.0};
            double r2 = 0.0;
            for (int c = 0; c < d; ++c) {
                dx[c] = nodes.position[c][j] - nodes.position[c][i];
                r2 += dx[c] * dx[c];
            }
            if (!(r2 > 0.0)) continue;
            const double r = std::sqrt(r2);
            const double h = pair_smoothing_length(influence_distance, nodes.diameter[i], nodes.diameter[j]);
            const double weight = std::max(0.0, 1.0 - 0.5 * r / h);
            for (int c = 0; c < d; ++c) outward[c] -= weight * dx[c] / r;
        }
    }
    for (int c = 0; c < d; ++c) contact_direction[c][i] = outward[c];
    return out;
}

}  // namespace

SeparationCounts remove_open_pairs(CompressedRows& lists, const NodeStore& nodes, std::size_t real_count,
                                   bool failed_pairs_separate, double* closing_speed,
                                   const std::array<double*, 3>& contact_direction, double influence_distance) {
    // Rows only shrink, so each block of rows is cut in place inside its own stretch of the entries
    // (in parallel: most entries are a body and a failed flag compared), then the blocks are moved
    // together in order. The entries keep their order whatever the blocks: the lists are those of
    // a single pass from the first row to the last, on any number of threads.
    constexpr std::size_t rows_per_block = 1024;
    const std::size_t blocks = (real_count + rows_per_block - 1) / rows_per_block;
    const auto rows_of = [&](std::size_t b) {
        return std::pair{b * rows_per_block, std::min(real_count, (b + 1) * rows_per_block)};
    };
    // Per block: where its entries began, and where its kept entries end (in its own stretch).
    std::vector<std::size_t> block_begin(blocks), block_end(blocks);
    for (std::size_t b = 0; b < blocks; ++b) block_begin[b] = lists.offsets[rows_of(b).first];
    std::vector<SeparationCounts> block_counts(blocks);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t b = r.begin(); b != r.end(); ++b) {
            const auto [first_row, last_row] = rows_of(b);
            std::size_t out = block_begin[b], start = block_begin[b];
            for (std::size_t i = first_row; i < last_row; ++i) {
                const std::size_t end = lists.offsets[i + 1];  // read before this row's end is rewritten
                out = cut_row(lists, nodes, i, start, end, out, failed_pairs_separate, closing_speed, contact_direction,
                              influence_distance, block_counts[b]);
                lists.offsets[i + 1] = out;  // in the block's own stretch; moved with it below
                start = end;
            }
            block_end[b] = out;
        }
    });
    // The blocks moved down in order (each lands at or before where it is, so a forward copy is
    // safe), their rows' ends shifted with them.
    SeparationCounts counts;
    std::size_t out = blocks > 0 ? block_begin[0] : 0;
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::size_t shift = block_begin[b] - out;
        if (shift > 0) {
            std::copy(lists.indices.begin() + static_cast<std::ptrdiff_t>(block_begin[b]),
                      lists.indices.begin() + static_cast<std::ptrdiff_t>(block_end[b]),
                      lists.indices.begin() + static_cast<std::ptrdiff_t>(out));
            const auto [first_row, last_row] = rows_of(b);
            for (std::size_t i = first_row; i < last_row; ++i) lists.offsets[i + 1] -= shift;
        }
        out += block_end[b] - block_begin[b];
        counts.open += block_counts[b].open;
        counts.closed += block_counts[b].closed;
    }
    lists.indices.resize(out);
    return counts;
}

}  // namespace gpa
