#include "gpa/engine/prescribed.hpp"

#include <algorithm>
#include <cmath>

namespace gpa {

std::array<double, 2> body_axis(const Scene& scene, std::size_t body) {
    const BodySpec& b = scene.bodies.at(body);
    if (scene.geometry == GeometryKind::Axisymmetric) return {0.0, 0.0};
    if (is_round(b.shape)) return {b.origin[0], b.origin[1]};
    if (b.shape == ShapeKind::Surface && b.surface) {  // the centre line of its box
        return {b.origin[0] + 0.5 * (b.surface->lower()[0] + b.surface->upper()[0]),
                b.origin[1] + 0.5 * (b.surface->lower()[1] + b.surface->upper()[1])};
    }
    if (b.shape == ShapeKind::Nodes && b.node_set) {  // the centre line of its nodes' box
        return {b.origin[0] + 0.5 * (b.node_set->lower()[0] + b.node_set->upper()[0]),
                scene.geometry == GeometryKind::ThreeD ? b.origin[1] + 0.5 * (b.node_set->lower()[1] + b.node_set->upper()[1]) : 0.0};
    }
    return {b.origin[0] + 0.5 * b.size[0], scene.geometry == GeometryKind::ThreeD ? b.origin[1] + 0.5 * b.size[1] : 0.0};
}

bool in_region(const PrescribedVelocitySpec& region, GeometryKind geometry, const std::array<double, 2>& axis,
               const std::array<double, 3>& p) {
    const int dim = dimension_of(geometry);
    for (int c = 0; c < dim; ++c) {
        if (!(p[c] >= region.lower[c] && p[c] <= region.upper[c])) return false;
    }
    double radius = 0.0;
    if (geometry == GeometryKind::Axisymmetric) {
        radius = p[0];
    } else if (geometry == GeometryKind::PlaneStrain) {
        radius = std::abs(p[0] - axis[0]);
    } else {
        radius = std::hypot(p[0] - axis[0], p[1] - axis[1]);
    }
    return radius >= region.radius_min && radius <= region.radius_max;
}

std::uint8_t held_components(const PrescribedVelocitySpec& region) {
    std::uint8_t bits = 0;
    for (int c = 0; c < 3; ++c) {
        if (region.velocity[c]) bits |= static_cast<std::uint8_t>(1u << c);
    }
    return bits;
}

double prescribed_velocity(const PrescribedVelocitySpec& region, int c, double t) {
    const double value = region.velocity[static_cast<std::size_t>(c)].value_or(0.0);
    if (region.ramp > 0.0 && t < region.ramp) return value * (t / region.ramp);
    return value;
}

void HeldNodes::index(const std::uint8_t* region_of, std::size_t count, std::size_t regions) {
    std::vector<std::size_t> size(regions + 1, 0);
    for (std::size_t i = 0; i < count; ++i) {
        if (region_of[i] != 0 && region_of[i] <= regions) ++size[region_of[i]];
    }
    nodes_.offsets.assign(regions + 1, 0);
    for (std::size_t k = 0; k < regions; ++k) nodes_.offsets[k + 1] = nodes_.offsets[k] + size[k + 1];
    nodes_.indices.assign(nodes_.offsets.back(), 0);
    std::vector<std::size_t> next(nodes_.offsets.begin(), nodes_.offsets.end() - 1);
    for (std::size_t i = 0; i < count; ++i) {
        if (region_of[i] != 0 && region_of[i] <= regions) nodes_.indices[next[region_of[i] - 1u]++] = static_cast<NodeIndex>(i);
    }
}

void HeldNodes::capture(const std::array<const double*, 3>& velocity, int dim) {
    before_.resize(nodes_.entries() * static_cast<std::size_t>(dim));
    for (std::size_t e = 0; e < nodes_.entries(); ++e) {
        for (int c = 0; c < dim; ++c) before_[e * dim + c] = velocity[c][nodes_.indices[e]];
    }
}

std::vector<RegionStep> HeldNodes::impose(const std::vector<PrescribedVelocitySpec>& regions, int dim, double time,
                                          double dt_avg, const std::array<double*, 3>& velocity, const double* mass) const {
    std::vector<RegionStep> out(regions.size());
    for (std::size_t k = 0; k < regions.size() && k < nodes_.rows(); ++k) {
        std::array<double, 3> target{0, 0, 0};
        for (int c = 0; c < dim; ++c) {
            if (regions[k].velocity[c]) target[c] = prescribed_velocity(regions[k], c, time);
        }
        RegionStep& step = out[k];
        step.velocity = target;
        for (std::size_t e = nodes_.offsets[k]; e < nodes_.offsets[k + 1]; ++e) {
            const NodeIndex i = nodes_.indices[e];
            for (int c = 0; c < dim; ++c) {
                if (!regions[k].velocity[c]) continue;
                // The impulse R dt_avg = M (v^{n+3/2} - v_int) and its work with the mean velocity.
                const double impulse = mass[i] * (target[c] - velocity[c][i]);
                step.reaction[c] += impulse / dt_avg;
                step.work += impulse * 0.5 * (before_[e * dim + c] + target[c]);
                velocity[c][i] = target[c];
            }
        }
    }
    return out;
}

void HeldNodes::set_mean_velocity(const std::vector<PrescribedVelocitySpec>& regions, int dim,
                                  const std::array<const double*, 3>& velocity, const std::array<double*, 3>& mean) const {
    for (std::size_t k = 0; k < regions.size() && k < nodes_.rows(); ++k) {
        for (std::size_t e = nodes_.offsets[k]; e < nodes_.offsets[k + 1]; ++e) {
            const NodeIndex i = nodes_.indices[e];
            for (int c = 0; c < dim; ++c) {
                if (regions[k].velocity[c]) mean[c][i] = 0.5 * (before_[e * dim + c] + velocity[c][i]);
            }
        }
    }
}

}  // namespace gpa
