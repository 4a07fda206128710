#include "gpa/engine/measure.hpp"

#include <algorithm>
#include <cmath>
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
    // The points sorted by cell, each cell's points in index order; the cells numbered in that order.
    std::vector<CellKey> key(n);
    for (std::size_t q = 0; q < n; ++q) {
        key[q].body = points[q].body;
        for (int c = 0; c < dim; ++c) key[q].c[c] = static_cast<long long>(std::floor(points[q].position[c] / radius));
    }
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key[a] < key[b] || (key[a] == key[b] && a < b); });
    std::vector<std::size_t> cell_begin;  // into `order`; one past the last cell: n
    std::unordered_map<CellKey, std::size_t, CellHash> cell_of;
    for (std::size_t k = 0; k < n; ++k) {
        if (k == 0 || !(key[order[k]] == key[order[k - 1]])) {
            cell_of.emplace(key[order[k]], cell_begin.size());
            cell_begin.push_back(k);
        }
    }
    const std::size_t cells = cell_begin.size();
    cell_begin.push_back(n);
    // mean_f(p) = sum_q w_q f_q / sum_q w_q, summed over the neighbour cells in a fixed order (x
    // slowest), each cell's points in index order: the same order for every field and thread count.
    std::vector<double> mean(n * nf, 0.0);
    const double r2 = radius * radius;
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
                        const auto it = cell_of.find(k);
                        if (it != cell_of.end()) near[static_cast<std::size_t>(near_count++)] = it->second;
                    }
                }
            }
            for (std::size_t kp = cell_begin[cell]; kp < cell_begin[cell + 1]; ++kp) {
                const std::size_t p = order[kp];
                double sw = 0.0;
                std::fill(swf.begin(), swf.end(), 0.0);
                for (int m = 0; m < near_count; ++m) {
                    const std::size_t other = near[static_cast<std::size_t>(m)];
                    for (std::size_t kq = cell_begin[other]; kq < cell_begin[other + 1]; ++kq) {
                        const std::size_t q = order[kq];
                        double d2 = 0.0;
                        for (int c = 0; c < dim; ++c) {
                            const double d = points[q].position[c] - points[p].position[c];
                            d2 += d * d;
                        }
                        if (d2 > r2) continue;
                        sw += points[q].weight;
                        for (std::size_t f = 0; f < nf; ++f) swf[f] += points[q].weight * fields[f][q];
                    }
                }
                for (std::size_t f = 0; f < nf; ++f) mean[f * n + p] = sw > 0.0 ? swf[f] / sw : fields[f][p];
            }
        }
    });
    for (std::size_t f = 0; f < nf; ++f) {
        const double* m = mean.data() + f * n;
        const std::span<const double> value = fields[f];
        std::size_t best = 0, best_raw = 0;
        for (std::size_t p = 1; p < n; ++p) {
            if (m[p] > m[best]) best = p;
            if (value[p] > value[best_raw]) best_raw = p;
        }
        out[f].value = m[best];
        out[f].position = points[best].position;
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
