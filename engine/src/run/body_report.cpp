#include "gpa/engine/body_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace gpa {

namespace {

struct AxisGeometry {
    const ImpactFrame& f;
    int dim;

    // s = -u . x: the coordinate along the axis towards the projectile.
    double level(const std::array<std::vector<double>, 3>& x, std::size_t i) const {
        double s = 0.0;
        for (int c = 0; c < dim; ++c) s -= f.direction[c] * x[c][i];
        return s;
    }
    // Distance from the impact axis.
    double radius(const std::array<std::vector<double>, 3>& x, std::size_t i) const {
        if (f.axisymmetric) return std::abs(x[0][i]);
        std::array<double, 3> r{0, 0, 0};
        double along = 0.0;
        for (int c = 0; c < dim; ++c) {
            r[c] = x[c][i] - f.point[c];
            along += r[c] * f.direction[c];
        }
        double sq = 0.0;
        for (int c = 0; c < dim; ++c) {
            const double p = r[c] - along * f.direction[c];
            sq += p * p;
        }
        return std::sqrt(sq);
    }
};

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

}  // namespace

ImpactFrame impact_frame(const NodeStore& nodes, std::size_t real_count,
                         const std::vector<std::array<double, 3>>& body_velocity, bool axisymmetric) {
    ImpactFrame f;
    f.axisymmetric = axisymmetric;
    const int d = nodes.dim();
    const std::size_t bodies = body_velocity.size();
    std::vector<double> mass(bodies, 0.0), speed2(bodies, 0.0);
    std::vector<std::array<double, 3>> momentum(bodies, {0, 0, 0}), moment(bodies, {0, 0, 0});
    for (std::size_t i = 0; i < real_count; ++i) {
        const auto b = static_cast<std::size_t>(nodes.body[i]);
        mass[b] += nodes.mass[i];
        for (int c = 0; c < d; ++c) {
            momentum[b][c] += nodes.mass[i] * body_velocity[b][c];
            moment[b][c] += nodes.mass[i] * nodes.initial_position[c][i];
        }
    }
    f.target.assign(bodies, 0);
    double fastest = 0.0;
    for (std::size_t b = 0; b < bodies; ++b) {
        if (!(mass[b] > 0.0)) continue;
        for (int c = 0; c < d; ++c) speed2[b] += (momentum[b][c] / mass[b]) * (momentum[b][c] / mass[b]);
        if (speed2[b] > fastest) {
            fastest = speed2[b];
            f.projectile = static_cast<int>(b);
        }
    }
    if (f.projectile < 0) return f;
    f.defined = true;
    const auto p = static_cast<std::size_t>(f.projectile);
    const double speed = std::sqrt(fastest);
    for (int c = 0; c < d; ++c) {
        f.direction[c] = momentum[p][c] / mass[p] / speed;
        f.point[c] = moment[p][c] / mass[p];
    }
    if (axisymmetric) {
        // The axis is x = 0 and the impact runs along it.
        f.direction = {0.0, f.direction[1] >= 0.0 ? 1.0 : -1.0, 0.0};
        f.point = {0.0, 0.0, 0.0};
    }
    const AxisGeometry axis{f, d};
    f.front_level.assign(bodies, -std::numeric_limits<double>::infinity());
    f.back_level.assign(bodies, std::numeric_limits<double>::infinity());
    for (std::size_t b = 0; b < bodies; ++b) f.target[b] = mass[b] > 0.0 && speed2[b] == 0.0;
    for (std::size_t i = 0; i < real_count; ++i) {
        const auto b = static_cast<std::size_t>(nodes.body[i]);
        if (!f.target[b]) continue;
        const double s = axis.level(nodes.initial_position, i), half = 0.5 * nodes.initial_diameter[i];
        f.front_level[b] = std::max(f.front_level[b], s + half);
        if (axis.radius(nodes.initial_position, i) <= nodes.initial_diameter[i]) f.back_level[b] = std::min(f.back_level[b], s - half);
    }
    return f;
}

void measure_bodies(const NodeStore& nodes, std::size_t real_count, const CompressedRows& lists, const ImpactFrame& frame,
                    std::vector<BodyTotals>& out) {
    const int d = nodes.dim();
    // Union-find over intact pairs of one body; roots are the smallest index of a piece, so the
    // pieces and their order do not depend on the order of the lists or the thread count.
    std::vector<std::size_t> parent(real_count);
    std::iota(parent.begin(), parent.end(), std::size_t{0});
    for (std::size_t i = 0; i < real_count; ++i) {
        if (nodes.failed[i]) continue;
        for (NodeIndex j : lists.row(i)) {
            if (j >= real_count || j <= i || nodes.failed[j] || nodes.body[j] != nodes.body[i]) continue;
            std::size_t a = find_root(parent, i), b = find_root(parent, j);
            if (a == b) continue;
            if (b < a) std::swap(a, b);
            parent[b] = a;
        }
    }
    std::vector<double> piece_mass(real_count, 0.0);
    for (std::size_t i = 0; i < real_count; ++i) {
        if (!nodes.failed[i]) piece_mass[find_root(parent, i)] += nodes.mass[i];
    }
    const std::size_t bodies = out.size();
    std::vector<std::size_t> main(bodies, real_count);
    for (auto& b : out) {
        b.pieces = 0;
        b.main_piece_mass = 0.0;
        b.residual_velocity = {0, 0, 0};
        b.measured = true;
    }
    for (std::size_t i = 0; i < real_count; ++i) {
        if (nodes.failed[i] || parent[i] != i) continue;
        const auto b = static_cast<std::size_t>(nodes.body[i]);
        ++out[b].pieces;
        if (piece_mass[i] > out[b].main_piece_mass) {  // ties keep the lower-numbered piece
            out[b].main_piece_mass = piece_mass[i];
            main[b] = i;
        }
    }
    std::vector<std::array<double, 3>> main_momentum(bodies, {0, 0, 0});
    const AxisGeometry axis{frame, d};
    std::vector<double> top_on_axis(bodies, -std::numeric_limits<double>::infinity());
    std::vector<double> innermost_at_front(bodies, std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < real_count; ++i) {
        if (nodes.failed[i]) continue;
        const auto b = static_cast<std::size_t>(nodes.body[i]);
        if (find_root(parent, i) != main[b]) continue;
        for (int c = 0; c < d; ++c) main_momentum[b][c] += nodes.mass[i] * nodes.velocity[c][i];
        if (!frame.defined || !frame.target[b]) continue;
        const double reach = axis.level(nodes.position, i) + 0.5 * nodes.diameter[i];
        const double rho = axis.radius(nodes.position, i);
        if (rho <= nodes.diameter[i]) top_on_axis[b] = std::max(top_on_axis[b], reach);
        if (reach >= frame.front_level[b] - 0.5 * nodes.diameter[i]) {
            innermost_at_front[b] = std::min(innermost_at_front[b], rho - 0.5 * nodes.diameter[i]);
        }
    }
    for (std::size_t b = 0; b < bodies; ++b) {
        auto& r = out[b];
        if (r.main_piece_mass > 0.0) {
            for (int c = 0; c < d; ++c) r.residual_velocity[c] = main_momentum[b][c] / r.main_piece_mass;
        }
        r.residual_speed_along_axis = 0.0;
        for (int c = 0; c < d; ++c) r.residual_speed_along_axis += r.residual_velocity[c] * frame.direction[c];
        r.target = frame.defined && frame.target[b];
        r.crater_depth = r.crater_diameter = 0.0;
        r.perforated = false;
        if (!r.target) continue;
        if (std::isfinite(top_on_axis[b])) {
            r.crater_depth = std::max(0.0, frame.front_level[b] - top_on_axis[b]);
        } else {
            r.perforated = true;
            r.crater_depth = frame.front_level[b] - frame.back_level[b];
        }
        if (std::isfinite(innermost_at_front[b])) r.crater_diameter = 2.0 * std::max(0.0, innermost_at_front[b]);
    }
}

}  // namespace gpa
