#include "gpa/engine/measure.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gpa::measure {

namespace {

// A grid of cells one radius wide: a point's neighbourhood lies in the 3^dim cells around its own.
struct CellKey {
    std::array<long long, 3> c{0, 0, 0};
    int body = 0;
    bool operator==(const CellKey& o) const { return c == o.c && body == o.body; }
    bool operator<(const CellKey& o) const { return body != o.body ? body < o.body : c < o.c; }
};
struct CellHash {
    std::size_t operator()(const CellKey& k) const {
        std::size_t h = static_cast<std::size_t>(k.body) * 0x9E3779B97F4A7C15ull;
        for (long long v : k.c) h = (h ^ static_cast<std::size_t>(v)) * 0x100000001B3ull;
        return h;
    }
};

// The points grouped by cell: `order` holds the point indices sorted by (body, cell, index), and
// cell_begin[k] where the k-th occupied cell starts in it (one past the last: the point count).
// Where the cells of the points' bounding box are few (at most four per point), a counting sort
// over the box's cells numbered body first, then x, y, z, and a table from box cell to occupied
// cell: the order std::sort and a hash map gave, without their comparisons and look-ups (this runs
// at every history row). Elsewhere (a fragment flown far from its body), the sort and the hash
// map.
struct CellGrid {
    static constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    std::vector<std::size_t> order, cell_begin;

    static CellGrid of(const std::vector<CellKey>& key) {
        CellGrid g;
        const std::size_t n = key.size();
        g.order.resize(n);
        if (g.box(key)) {
            std::vector<std::size_t> start(g.box_cells_ + 1, 0);
            for (const CellKey& k : key) ++start[g.box_index(k) + 1];
            g.box_cell_.assign(g.box_cells_, none);
            for (std::size_t b = 0; b < g.box_cells_; ++b) {
                if (start[b + 1] > 0) {
                    g.box_cell_[b] = g.cell_begin.size();
                    g.cell_begin.push_back(start[b]);
                }
                start[b + 1] += start[b];
            }
            for (std::size_t q = 0; q < n; ++q) g.order[start[g.box_index(key[q])]++] = q;
        } else {
            std::iota(g.order.begin(), g.order.end(), std::size_t{0});
            std::sort(g.order.begin(), g.order.end(),
                      [&](std::size_t a, std::size_t b) { return key[a] < key[b] || (key[a] == key[b] && a < b); });
            for (std::size_t k = 0; k < n; ++k) {
                if (k == 0 || !(key[g.order[k]] == key[g.order[k - 1]])) {
                    g.cell_of_.emplace(key[g.order[k]], g.cell_begin.size());
                    g.cell_begin.push_back(k);
                }
            }
        }
        g.cell_begin.push_back(n);
        return g;
    }

    // The occupied cell numbered as in cell_begin, or none.
    std::size_t find(const CellKey& k) const {
        if (!boxed_) {
            const auto it = cell_of_.find(k);
            return it == cell_of_.end() ? none : it->second;
        }
        if (k.body < lo_.body || k.body > hi_.body) return none;
        for (int c = 0; c < 3; ++c) {
            if (k.c[c] < lo_.c[c] || k.c[c] > hi_.c[c]) return none;
        }
        return box_cell_[box_index(k)];
    }

private:
    bool boxed_ = false;
    CellKey lo_, hi_;
    std::array<std::size_t, 4> span_{1, 1, 1, 1};  // body, x, y, z
    std::size_t box_cells_ = 0;
    std::vector<std::size_t> box_cell_;  // box cell -> occupied cell, or none
    std::unordered_map<CellKey, std::size_t, CellHash> cell_of_;

    // The box's index of a key inside it: body slowest, then x, y, z.
    std::size_t box_index(const CellKey& k) const {
        std::size_t b = static_cast<std::size_t>(k.body - lo_.body);
        for (int c = 0; c < 3; ++c) b = b * span_[c + 1] + static_cast<std::size_t>(k.c[c] - lo_.c[c]);
        return b;
    }

    // The bounding box of the keys; false where it has more than four cells per point (or at
    // least 2^40, measured in doubles so that no product overflows).
    bool box(const std::vector<CellKey>& key) {
        if (key.empty()) return false;
        lo_ = hi_ = key[0];
        for (const CellKey& k : key) {
            lo_.body = std::min(lo_.body, k.body);
            hi_.body = std::max(hi_.body, k.body);
            for (int c = 0; c < 3; ++c) {
                lo_.c[c] = std::min(lo_.c[c], k.c[c]);
                hi_.c[c] = std::max(hi_.c[c], k.c[c]);
            }
        }
        double cells = static_cast<double>(hi_.body) - static_cast<double>(lo_.body) + 1.0;
        for (int c = 0; c < 3; ++c) cells *= static_cast<double>(hi_.c[c]) - static_cast<double>(lo_.c[c]) + 1.0;
        if (!(cells <= 4.0 * static_cast<double>(key.size()) + 64.0) || cells >= 0x1p40) return false;
        span_[0] = static_cast<std::size_t>(hi_.body - lo_.body) + 1;
        for (int c = 0; c < 3; ++c) span_[c + 1] = static_cast<std::size_t>(hi_.c[c] - lo_.c[c]) + 1;
        box_cells_ = static_cast<std::size_t>(cells);
        boxed_ = true;
        return true;
    }
};

}  // namespace

std::vector<LocalPeak> local_peaks(std::span<const FieldPoint> points, std::span<const std::span<const double>> fields,
                                   double radius, int dim) {
    if (!(radius > 0.0) || !std::isfinite(radius)) {
        throw std::invalid_argument(fmt::format("local_peak: the neighbourhood radius {} must be positive", radius));
    }
    for (const auto& f : fields) {
        if (f.size() != points.size()) {
            throw std::invalid_argument(fmt::format("local_peaks: a field of {} values for {} points", f.size(), points.size()));
        }
    }
    std::vector<LocalPeak> out(fields.size());
    for (LocalPeak& o : out) o.points = points.size();
    if (points.empty() || fields.empty()) return out;
    const std::size_t n = points.size(), nf = fields.size();
    std::vector<CellKey> key(n);
    for (std::size_t q = 0; q < n; ++q) {
        key[q].body = points[q].body;
        for (int c = 0; c < dim; ++c) key[q].c[c] = static_cast<long long>(std::floor(points[q].position[c] / radius));
    }
    // The points sorted by cell, each cell's points in index order; the cells numbered in that order.
    const CellGrid grid = CellGrid::of(key);
    const std::vector<std::size_t>& order = grid.order;
    const std::vector<std::size_t>& cell_begin = grid.cell_begin;
    const std::size_t cells = cell_begin.size() - 1;
    // mean_f(p) = sum_q w_q f_q / sum_q w_q, summed over the neighbour cells in a fixed order (x
    // slowest), each cell's points in index order: the same order for every field and thread count.
    std::vector<double> mean(n * nf, 0.0);
    std::vector<std::uint8_t> alone(n, 0);  // no other point of the body within the radius
    const double r2 = radius * radius;
    // The points' coordinates, weights and values copied in `order`, so that a cell's points are
    // read as contiguous runs.
    std::array<std::vector<double>, 3> x;
    for (int c = 0; c < dim; ++c) x[static_cast<std::size_t>(c)].resize(n);
    std::vector<double> weight(n), ordered_value(n * nf);
    for (std::size_t k = 0; k < n; ++k) {
        const FieldPoint& q = points[order[k]];
        for (int c = 0; c < dim; ++c) x[static_cast<std::size_t>(c)][k] = q.position[static_cast<std::size_t>(c)];
        weight[k] = q.weight;
        for (std::size_t f = 0; f < nf; ++f) ordered_value[f * n + k] = fields[f][order[k]];
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<double> swf(nf);
        for (std::size_t cell = r.begin(); cell != r.end(); ++cell) {
            const CellKey home = key[order[cell_begin[cell]]];
            std::array<std::size_t, 27> near{};
            int near_count = 0;
            const int span_y = dim == 3 ? 1 : 0;
            for (int ox = -1; ox <= 1; ++ox) {
                for (int oy = -1; oy <= 1; ++oy) {
                    for (int oz = -span_y; oz <= span_y; ++oz) {
                        CellKey k = home;
                        k.c[0] += ox;
                        k.c[1] += oy;
                        k.c[2] += oz;
                        if (const std::size_t found = grid.find(k); found != CellGrid::none) {
                            near[static_cast<std::size_t>(near_count++)] = found;
                        }
                    }
                }
            }
            for (std::size_t kp = cell_begin[cell]; kp < cell_begin[cell + 1]; ++kp) {
                const std::size_t p = order[kp];
                double sw = 0.0;
                std::size_t inside_count = 0;  // the point itself included
                std::fill(swf.begin(), swf.end(), 0.0);
                for (int m = 0; m < near_count; ++m) {
                    const std::size_t other = near[static_cast<std::size_t>(m)];
                    for (std::size_t kq = cell_begin[other]; kq < cell_begin[other + 1]; ++kq) {
                        double d2 = 0.0;
                        for (int c = 0; c < dim; ++c) {
                            const double d = x[static_cast<std::size_t>(c)][kq] - x[static_cast<std::size_t>(c)][kp];
                            d2 += d * d;
                        }
                        // Without a branch on the distance, which no predictor guesses (about two
                        // thirds of the points of the 3^dim cells lie outside the radius): a point
                        // outside adds -0.0, which leaves every sum as it was, signed zeros too.
                        const bool inside = !(d2 > r2);
                        const double w = weight[kq];
                        sw += inside ? w : -0.0;
                        inside_count += inside;
                        for (std::size_t f = 0; f < nf; ++f) swf[f] += inside ? w * ordered_value[f * n + kq] : -0.0;
                    }
                }
                for (std::size_t f = 0; f < nf; ++f) mean[f * n + p] = sw > 0.0 ? swf[f] / sw : fields[f][p];
                alone[p] = inside_count <= 1;
            }
        }
    });
    // The peak over the points that have a neighbourhood (a lone point's "mean" is its own value,
    // the quantity `raw` already reports); the largest single value over every point.
    const std::size_t lone = static_cast<std::size_t>(std::count(alone.begin(), alone.end(), std::uint8_t{1}));
    constexpr std::size_t none = std::numeric_limits<std::size_t>::max();
    for (std::size_t f = 0; f < nf; ++f) {
        const double* m = mean.data() + f * n;
        const std::span<const double> value = fields[f];
        std::size_t best = none, best_raw = 0;
        for (std::size_t p = 0; p < n; ++p) {
            if (!alone[p] && (best == none || m[p] > m[best])) best = p;
            if (value[p] > value[best_raw]) best_raw = p;
        }
        out[f].alone = lone;
        if (best != none) {
            out[f].value = m[best];
            out[f].position = points[best].position;
        } else {
            out[f].value = std::numeric_limits<double>::quiet_NaN();
            out[f].position.fill(std::numeric_limits<double>::quiet_NaN());
        }
        out[f].raw = value[best_raw];
        out[f].raw_position = points[best_raw].position;
    }
    return out;
}

LocalPeak local_peak(std::span<const FieldPoint> points, double radius, int dim) {
    std::vector<double> value(points.size());
    for (std::size_t q = 0; q < points.size(); ++q) value[q] = points[q].value;
    const std::span<const double> field(value);
    return local_peaks(points, std::span<const std::span<const double>>(&field, 1), radius, dim).front();
}

double face_roughness(std::span<const double> across, std::span<const double> value) {
    if (across.size() != value.size()) throw std::invalid_argument("face_roughness: as many positions as values are needed");
    if (value.size() < 3) return 0.0;
    std::vector<std::size_t> order(value.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return across[a] < across[b]; });
    double sum = 0.0;
    for (std::size_t k = 1; k + 1 < order.size(); ++k) {
        sum += std::abs(value[order[k]] - 0.5 * (value[order[k - 1]] + value[order[k + 1]]));
    }
    return sum / double(order.size() - 2);
}

}  // namespace gpa::measure
