#include "gpa/engine/measure.hpp"

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
};
struct CellHash {
    std::size_t operator()(const CellKey& k) const {
        std::size_t h = static_cast<std::size_t>(k.body) * 0x9E3779B97F4A7C15ull;
        for (long long v : k.c) h = (h ^ static_cast<std::size_t>(v)) * 0x100000001B3ull;
        return h;
    }
};

}  // namespace

LocalPeak local_peak(std::span<const FieldPoint> points, double radius, int dim) {
    if (!(radius > 0.0) || !std::isfinite(radius)) {
        throw std::invalid_argument(fmt::format("local_peak: the neighbourhood radius {} must be positive", radius));
    }
    LocalPeak out;
    out.points = points.size();
    if (points.empty()) return out;
    const auto key_of = [&](const FieldPoint& p) {
        CellKey k;
        k.body = p.body;
        for (int c = 0; c < dim; ++c) k.c[c] = static_cast<long long>(std::floor(p.position[c] / radius));
        return k;
    };
    // Cells in index order of their points, so that the sums run in one fixed order.
    std::unordered_map<CellKey, std::vector<std::size_t>, CellHash> cells;
    for (std::size_t q = 0; q < points.size(); ++q) cells[key_of(points[q])].push_back(q);
    std::vector<double> mean(points.size(), 0.0);
    const double r2 = radius * radius;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t p = r.begin(); p != r.end(); ++p) {
            const CellKey home = key_of(points[p]);
            double sw = 0.0, swf = 0.0;
            const int span_y = dim == 3 ? 1 : 0;
            // Offsets in a fixed order (x slowest), each cell's points in index order.
            for (int ox = -1; ox <= 1; ++ox) {
                for (int oy = -1; oy <= 1; ++oy) {
                    for (int oz = -span_y; oz <= span_y; ++oz) {
                        CellKey k = home;
                        k.c[0] += ox;
                        k.c[1] += oy;
                        k.c[2] += oz;
                        const auto it = cells.find(k);
                        if (it == cells.end()) continue;
                        for (std::size_t q : it->second) {
                            double d2 = 0.0;
                            for (int c = 0; c < dim; ++c) {
                                const double d = points[q].position[c] - points[p].position[c];
                                d2 += d * d;
                            }
                            if (d2 > r2) continue;
                            sw += points[q].weight;
                            swf += points[q].weight * points[q].value;
                        }
                    }
                }
            }
            mean[p] = sw > 0.0 ? swf / sw : points[p].value;
        }
    });
    std::size_t best = 0, best_raw = 0;
    for (std::size_t p = 1; p < points.size(); ++p) {
        if (mean[p] > mean[best]) best = p;
        if (points[p].value > points[best_raw].value) best_raw = p;
    }
    out.value = mean[best];
    out.position = points[best].position;
    out.raw = points[best_raw].value;
    out.raw_position = points[best_raw].position;
    return out;
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
