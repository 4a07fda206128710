#include "gpa/engine/lattice_check.hpp"

#include <array>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>

#include "gpa/engine/kernels.hpp"

namespace gpa {

namespace {

// The axis neighbours of fixed node i, found by their initial offsets: [axis][0] below, [axis][1]
// above, -1 for none.
template <int D>
std::array<std::array<std::int64_t, 2>, D> axis_neighbours(const NodeStore& n, std::size_t i) {
    std::array<std::array<std::int64_t, 2>, D> axis;
    for (auto& a : axis) a = {-1, -1};
    for (NodeIndex j : n.fixed_neighbours.row_or_empty(i)) {
        if (n.connectivity[j] != Connectivity::Fixed) continue;
        int along = -1, nonzero = 0;
        for (int c = 0; c < D; ++c) {
            if (std::abs(n.initial_position[c][j] - n.initial_position[c][i]) > 1e-3 * n.initial_diameter[i]) {
                along = c;
                ++nonzero;
            }
        }
        if (nonzero != 1) continue;
        // The nearest along the axis on each side (a stencil reaching beyond the box, a > 1,
        // also holds the nodes two spacings away).
        const double offset = n.initial_position[along][j] - n.initial_position[along][i];
        std::int64_t& slot = axis[along][offset > 0.0 ? 1 : 0];
        if (slot >= 0 && std::abs(n.initial_position[along][static_cast<std::size_t>(slot)] - n.initial_position[along][i]) <= std::abs(offset)) continue;
        slot = j;
    }
    return axis;
}

template <int D>
void ratios(const NodeStore& n, std::size_t real_count, bool axisymmetric, std::vector<double>& out, LatticeAxes* axes) {
    constexpr double none = std::numeric_limits<double>::infinity();
    if (axes && axes->known.size() != real_count) {
        axes->known.assign(real_count, 0);
        axes->neighbour.resize(real_count * 2 * D);
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real_count, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            out[i] = none;
            if (n.connectivity[i] != Connectivity::Fixed) continue;
            std::array<std::array<std::int64_t, 2>, D> axis;
            // The kept set while its nodes are all still fixed (LatticeAxes), else found again.
            bool kept = axes && axes->known[i];
            if (kept) {
                for (int a = 0; a < D; ++a) {
                    for (int side = 0; side < 2; ++side) {
                        const std::int64_t j = axes->neighbour[(i * D + static_cast<std::size_t>(a)) * 2 + static_cast<std::size_t>(side)];
                        axis[a][side] = j;
                        if (j >= 0 && n.connectivity[static_cast<std::size_t>(j)] != Connectivity::Fixed) kept = false;
                    }
                }
            }
            if (!kept) {
                axis = axis_neighbours<D>(n, i);
                if (axes) {
                    for (int a = 0; a < D; ++a) {
                        for (int side = 0; side < 2; ++side) {
                            axes->neighbour[(i * D + static_cast<std::size_t>(a)) * 2 + static_cast<std::size_t>(side)] =
                                static_cast<std::int32_t>(axis[a][side]);
                        }
                    }
                    axes->known[i] = 1;
                }
            }
            double smallest = none;
            // Every choice of one side per axis is a cell (2^D of them).
            for (int cell = 0; cell < (1 << D); ++cell) {
                Mat<D> now, then;
                bool complete = true;
                for (int a = 0; a < D && complete; ++a) {
                    const std::int64_t j = axis[a][(cell >> a) & 1];
                    if (j < 0) {
                        complete = false;
                        break;
                    }
                    for (int c = 0; c < D; ++c) {
                        now(c, a) = n.position[c][static_cast<std::size_t>(j)] - n.position[c][i];
                        then(c, a) = n.initial_position[c][static_cast<std::size_t>(j)] - n.initial_position[c][i];
                    }
                }
                if (!complete) continue;
                double ratio = lattice_cell_ratio<D>(now, then);
                if (axisymmetric) ratio *= n.position[0][i] / n.initial_position[0][i];
                // NaN (a non-finite position) counts as collapsed.
                if (!(ratio >= smallest)) smallest = std::isnan(ratio) ? -none : ratio;
            }
            out[i] = smallest;
        }
    });
}

}  // namespace

void smallest_lattice_cell_ratios(const NodeStore& nodes, std::size_t real_count, std::vector<double>& out, LatticeAxes* axes) {
    out.resize(real_count);
    if (nodes.dim() == 3) {
        ratios<3>(nodes, real_count, false, out, axes);
    } else {
        ratios<2>(nodes, real_count, nodes.geometry() == GeometryKind::Axisymmetric, out, axes);
    }
}

}  // namespace gpa
