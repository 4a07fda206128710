#include "gpa/engine/node_set.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

namespace {

std::string node_name(const NodeSet& set, std::size_t k) {
    if (k < set.origins.size() && !set.origins[k].empty()) return set.origins[k];
    return fmt::format("node {}", k);
}

// d0 = V^(1/3) or A^(1/2). In 3D the cube root as the one of cbrt's result and its two neighbours
// whose cube (d d) d, computed as a lattice computes its cell's volume, is nearest V: cbrt is not
// correctly rounded, and a lattice's nodes exported with their cells' volumes then come back with
// the lattice's own diameter, dx, exactly (its weights, and which pairs fall inside the support of
// radius 2 a d0, depend on it to the last bit). The square root is correctly rounded already.
double diameter_of(double size, int dim) {
    if (dim != 3) return std::sqrt(size);
    double best = std::cbrt(size);
    double error = std::abs(best * best * best - size);
    for (const double candidate : {std::nextafter(best, 0.0), std::nextafter(best, std::numeric_limits<double>::infinity())}) {
        const double e = std::abs(candidate * candidate * candidate - size);
        if (e < error) {
            best = candidate;
            error = e;
        }
    }
    return best;
}

}  // namespace

std::size_t NodeSetShape::CellHash::operator()(const Cell& c) const noexcept {
    std::uint64_t h = 1469598103934665603ull;
    for (const std::int64_t v : c) h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ull;
    return static_cast<std::size_t>(h ^ (h >> 29));
}

NodeSetShape::Cell NodeSetShape::cell_of(const std::array<double, 3>& p) const {
    Cell c{0, 0, 0};
    for (int k = 0; k < dim_; ++k) c[k] = static_cast<std::int64_t>(std::floor((p[k] - lower_[k]) / bucket_));
    return c;
}

NodeSetShape::NodeSetShape(std::shared_ptr<const NodeSet> set, int dim) : set_(std::move(set)), dim_(dim) {
    const std::size_t n = set_->positions.size();
    if (n == 0 || set_->sizes.size() != n || n > max_imported_nodes) {
        throw InputError(fmt::format("a node set of {} positions and {} sizes: check it with check_node_set first", n,
                                     set_->sizes.size()));
    }
    diameters_.resize(n);
    lower_ = {0, 0, 0};
    upper_ = {0, 0, 0};
    for (int c = 0; c < dim_; ++c) {
        lower_[c] = std::numeric_limits<double>::infinity();
        upper_[c] = -std::numeric_limits<double>::infinity();
    }
    double largest = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        const double d = diameter_of(set_->sizes[k], dim_);
        diameters_[k] = d;
        largest = std::max(largest, d);
        for (int c = 0; c < dim_; ++c) {
            lower_[c] = std::min(lower_[c], set_->positions[k][c] - 0.5 * d);
            upper_[c] = std::max(upper_[c], set_->positions[k][c] + 0.5 * d);
        }
    }
    std::vector<double> sorted = diameters_;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
    typical_ = sorted[n / 2];
    // Buckets as large as the largest node: a point covered by node k, and a node closer to k than
    // k's diameter, lie in k's bucket or in one of its neighbours. And no more than 2^20 of them
    // across the box, so that a bucket's index stays a small integer whatever the sizes.
    double span = 0.0;
    for (int c = 0; c < dim_; ++c) span = std::max(span, upper_[c] - lower_[c]);
    bucket_ = std::max(largest, std::ldexp(span, -20));
    std::vector<Cell> cells(n);
    for (std::size_t k = 0; k < n; ++k) cells[k] = cell_of(set_->positions[k]);
    order_.resize(n);
    std::iota(order_.begin(), order_.end(), 0u);
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t a, std::uint32_t b) { return cells[a] < cells[b]; });
    buckets_.reserve(n);
    for (std::size_t begin = 0; begin < n;) {
        std::size_t end = begin + 1;
        while (end < n && cells[order_[end]] == cells[order_[begin]]) ++end;
        buckets_.emplace(cells[order_[begin]], std::pair{static_cast<std::uint32_t>(begin), static_cast<std::uint32_t>(end)});
        begin = end;
    }
}

bool NodeSetShape::covers(const std::array<double, 3>& p) const {
    for (int c = 0; c < dim_; ++c) {
        if (!(p[c] > lower_[c] && p[c] < upper_[c])) return false;
    }
    return any_near(p, [&](std::size_t k) {
        const auto& x = set_->positions[k];
        for (int c = 0; c < dim_; ++c) {
            if (!(std::abs(p[c] - x[c]) < 0.5 * diameters_[k])) return false;
        }
        return true;
    });
}

void check_node_set(const NodeSet& set, int dim, bool axisymmetric, const std::string& what) {
    const std::size_t n = set.positions.size();
    if (n == 0) throw InputError(fmt::format("{}: holds no node", what));
    if (set.sizes.size() != n) {
        throw InputError(fmt::format("{}: {} positions but {} sizes (volumes or areas)", what, n, set.sizes.size()));
    }
    if (n > max_imported_nodes) {
        throw InputError(fmt::format("{}: {} nodes, more than the {} one body may import", what, n, max_imported_nodes));
    }
    const char* letters = dim == 2 ? "xz" : "xyz";
    const char* measure = dim == 3 ? "volume" : "area";
    for (std::size_t k = 0; k < n; ++k) {
        const auto& p = set.positions[k];
        for (int c = 0; c < 3; ++c) {
            if (!std::isfinite(p[c])) {
                throw InputError(fmt::format("{}: {}: its {} is not a finite number", what, node_name(set, k),
                                             c < dim ? std::string(1, letters[c]) : "third coordinate"));
            }
        }
        for (int c = 0; c < dim; ++c) {
            if (std::abs(p[c]) > max_node_coordinate) {
                throw InputError(fmt::format("{}: {}: its {} is {} m, beyond the {:g} m from the origin a scene may reach", what,
                                             node_name(set, k), letters[c], p[c], max_node_coordinate));
            }
        }
        if (dim == 2 && p[2] != 0.0) {
            throw InputError(fmt::format("{}: {}: a 2D scene's node lies in the x-z plane, but its third coordinate is {} "
                                         "(not 0)", what, node_name(set, k), p[2]));
        }
        if (axisymmetric && !(p[0] > 0.0)) {
            throw InputError(fmt::format("{}: {}: at x = {} m; in axisymmetric geometry x is the radius and a node must lie "
                                         "at x > 0", what, node_name(set, k), p[0]));
        }
        if (!(set.sizes[k] > 0.0) || !std::isfinite(set.sizes[k])) {
            throw InputError(fmt::format("{}: {}: its {} is {}; it must be positive and finite", what, node_name(set, k),
                                         measure, set.sizes[k]));
        }
        // A node smaller than its coordinates resolve (its position has some 16 digits).
        double distance = 0.0;
        for (int c = 0; c < dim; ++c) distance = std::max(distance, std::abs(p[c]));
        if (diameter_of(set.sizes[k], dim) < 1e-12 * distance) {
            throw InputError(fmt::format("{}: {}: its {} {} gives a diameter of {:.3g} m, below a 10^12th of its distance from the "
                                         "origin ({:.3g} m), which its coordinates cannot resolve",
                                         what, node_name(set, k), measure, set.sizes[k], diameter_of(set.sizes[k], dim), distance));
        }
    }
    // Two nodes closer than a quarter of their mean diameter: on a lattice neighbours are a whole
    // diameter apart, so this is a node listed twice or two sets that overlap.
    const NodeSetShape shape(std::shared_ptr<const NodeSet>(&set, [](const NodeSet*) {}), dim);  // not owned: no copy
    for (std::size_t k = 0; k < n; ++k) {
        const auto& x = set.positions[k];
        const double dk = shape.diameter(k);
        // Such a pair is closer than a quarter of the largest diameter: in neighbouring buckets.
        shape.any_near(x, [&](std::size_t j) {
            if (j <= k) return false;
            double r2 = 0.0;
            for (int c = 0; c < dim; ++c) r2 += (set.positions[j][c] - x[c]) * (set.positions[j][c] - x[c]);
            const double limit = 0.25 * 0.5 * (dk + shape.diameter(j));
            if (r2 < limit * limit) {
                throw InputError(fmt::format("{}: {} and {} are {:.4g} m apart, less than a quarter of their mean diameter "
                                             "({:.4g} m): a node listed twice, or two sets that overlap",
                                             what, node_name(set, k), node_name(set, j), std::sqrt(r2), 4.0 * limit));
            }
            return false;
        });
    }
}

}  // namespace gpa
