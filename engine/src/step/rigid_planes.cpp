#include "rigid_planes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "reduce_grain.hpp"

namespace gpa {

void RigidPlanes::assign(std::vector<std::size_t> rigid, std::vector<std::array<double, 2>> friction) {
    ghost_plane_ = std::move(rigid);
    friction_ = std::move(friction);
    friction_.resize(ghost_plane_.size(), {0.0, 0.0});
    with_friction_ = std::any_of(friction_.begin(), friction_.end(), [](const auto& mu) { return mu[1] > 0.0 || mu[0] > 0.0; });
    reaction_.assign(ghost_plane_.size(), 0.0);
    impulse_.assign(ghost_plane_.size(), 0.0);
    friction_work_.assign(ghost_plane_.size(), 0.0);
    pressing_impulse_.assign(ghost_plane_.size(), 0.0);
}

void RigidPlanes::apply_friction(const GhostSet& ghosts, NodeStore& nodes, std::size_t real, double dt_avg) {
    friction_forces_.clear();
    if (!with_friction_ || ghosts.empty() || !(dt_avg > 0.0)) return;
    const int dim = nodes.dim();
    // The rigid plane of each ghost plane (or none).
    std::vector<int> rigid_of(ghosts.planes().size(), -1);
    for (std::size_t k = 0; k < ghost_plane_.size(); ++k) rigid_of[ghost_plane_[k]] = static_cast<int>(k);
    // In ghost order (one order on any thread count; a node has at most one ghost per plane).
    for (std::size_t g = 0; g < ghosts.count(); ++g) {
        const std::uint8_t mask = ghosts.planes_of(g);
        if (mask == 0 || (mask & (mask - 1)) != 0) continue;  // a corner ghost: no single plane's push
        std::size_t p = 0;
        while (((mask >> p) & 1u) == 0) ++p;
        const int k = rigid_of[p];
        if (k < 0) continue;
        const auto [mu_static, mu_dynamic] = friction_[static_cast<std::size_t>(k)];
        if (!(mu_static > 0.0 || mu_dynamic > 0.0)) continue;
        const GhostPlane& plane = ghosts.planes()[p];
        const NodeIndex i = ghosts.source(g);
        if (i >= real || nodes.velocity_region[i] != 0) continue;
        const double push = -plane.side * plane.coordinate_of(nodes.force, real + g);
        if (!(push > 0.0)) continue;
        pressing_impulse_[static_cast<std::size_t>(k)] += push * dt_avg;
        const double m = nodes.mass[i];
        // w: the tangential part of the velocity the update would give the node (its part along
        // the normal removed; for an aligned plane that component is skipped, exactly).
        std::array<double, 3> w{0, 0, 0};
        for (int c = 0; c < dim; ++c) {
            if (c == plane.axis) continue;
            w[c] = nodes.velocity[c][i] + dt_avg * nodes.force[c][i] / m;
        }
        if (plane.axis < 0) {
            const auto& n = plane.normal;
            const double along = n[0] * w[0] + n[1] * w[1] + n[2] * w[2];
            for (int c = 0; c < dim; ++c) w[c] -= along * n[c];
        }
        double w2 = 0.0;
        for (int c = 0; c < dim; ++c) w2 += w[c] * w[c];
        if (!(w2 > 0.0)) continue;
        const double speed = std::sqrt(w2);
        // Sticking needs M |w| / dt_avg; up to mu_s N the plane holds the node, beyond it the node slides.
        const double scale = m * speed / dt_avg <= mu_static * push ? m / dt_avg : mu_dynamic * push / speed;
        FrictionForce f{i, static_cast<std::size_t>(k), {0, 0, 0}, {0, 0, 0}};
        for (int c = 0; c < dim; ++c) {
            f.velocity[c] = nodes.velocity[c][i];
            if (c == plane.axis) continue;
            f.force[c] = -scale * w[c];
            nodes.force[c][i] += f.force[c];
        }
        friction_forces_.push_back(f);
    }
}

void RigidPlanes::book_friction(NodeStore& nodes, double dt_avg) {
    const int dim = nodes.dim();
    for (const FrictionForce& f : friction_forces_) {
        double power = 0.0;
        for (int c = 0; c < dim; ++c) power += f.force[c] * 0.5 * (f.velocity[c] + nodes.velocity[c][f.node]);
        const double heat = -power * dt_avg;
        nodes.internal_energy[f.node] += heat / nodes.mass[f.node];
        friction_work_[f.plane] += heat;
    }
    friction_forces_.clear();
}

const GhostPlane* RigidPlanes::first(const GhostSet& ghosts) const {
    return ghost_plane_.empty() ? nullptr : &ghosts.planes()[ghost_plane_.front()];
}

void RigidPlanes::take_reactions(const GhostSet& ghosts, const NodeStore& nodes, std::size_t real) {
    if (ghosts.empty()) return;
    const auto all = ghosts.normal_reactions(nodes, real);
    for (std::size_t k = 0; k < ghost_plane_.size(); ++k) reaction_[k] = all[ghost_plane_[k]];
}

void RigidPlanes::add_impulses(double dt_avg) {
    for (std::size_t k = 0; k < reaction_.size(); ++k) impulse_[k] += reaction_[k] * dt_avg;
}

void RigidPlanes::guard_penetration(const GhostSet& ghosts, NodeStore& nodes, std::size_t real, EnergyLedger& ledger) {
    for (std::size_t p = 0; p < ghosts.planes().size(); ++p) {
        const auto& plane = ghosts.planes()[p];
        // A symmetry plane of the scene is no wall: a node that crosses it is, in the whole body,
        // one of two mirror nodes passing each other, and its ghost takes its place on this side
        // (a half or quarter model stays the whole body's run). The axis of an axisymmetric scene
        // stays guarded: a ring cannot have a negative radius.
        if (plane.continues_body) continue;
        const auto rigid = std::find(ghost_plane_.begin(), ghost_plane_.end(), p);
        using WorkAndImpulse = std::array<double, 2>;
        const WorkAndImpulse lost = tbb::parallel_deterministic_reduce(
            tbb::blocked_range<std::size_t>(0, real, reduce_grain), WorkAndImpulse{0.0, 0.0},
            [&](const tbb::blocked_range<std::size_t>& r, WorkAndImpulse acc) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
                    if (plane.axis < 0) {  // an oblique plane: along its normal
                        const double gap = plane.distance_of(nodes.position, i);
                        if (gap > 0.0) continue;
                        const auto& n = plane.normal;
                        const double move = plane.side * (0.01 * nodes.initial_diameter[i] - gap);
                        for (int c = 0; c < nodes.dim(); ++c) nodes.position[c][i] += move * n[c];
                        const double v = plane.coordinate_of(nodes.velocity, i);
                        if (plane.side * v < 0.0) {
                            acc[0] += 0.5 * nodes.mass[i] * v * v;
                            acc[1] -= plane.side * nodes.mass[i] * v;
                            for (int c = 0; c < nodes.dim(); ++c) nodes.velocity[c][i] -= v * n[c];
                        }
                        continue;
                    }
                    double& x = nodes.position[plane.axis][i];
                    if (plane.distance(x) > 0.0) continue;
                    x = plane.position + plane.side * 0.01 * nodes.initial_diameter[i];
                    double& v = nodes.velocity[plane.axis][i];
                    if (plane.side * v < 0.0) {
                        acc[0] += 0.5 * nodes.mass[i] * v * v;
                        acc[1] -= plane.side * nodes.mass[i] * v;
                        v = 0.0;
                    }
                }
                return acc;
            },
            [](WorkAndImpulse x, const WorkAndImpulse& y) { return WorkAndImpulse{x[0] + y[0], x[1] + y[1]}; });
        ledger.add_boundary_work(lost[0]);
        if (rigid != ghost_plane_.end()) impulse_[static_cast<std::size_t>(rigid - ghost_plane_.begin())] += lost[1];
    }
}

void RigidPlanes::report(const GhostSet& ghosts, const std::vector<double>* element_reactions,
                         const std::vector<double>* element_impulses, std::vector<PlaneReport>& out) const {
    out.clear();
    for (std::size_t k = 0; k < ghost_plane_.size(); ++k) {
        const double element_reaction = element_reactions ? (*element_reactions)[k] : 0.0;
        const double element_impulse = element_impulses ? (*element_impulses)[k] : 0.0;
        out.push_back({ghosts.planes()[ghost_plane_[k]].name, reaction_[k] + element_reaction, impulse_[k] + element_impulse,
                       friction_[k][0] > 0.0 || friction_[k][1] > 0.0, friction_work_[k], pressing_impulse_[k]});
    }
}

template <class IO, class Self>
void RigidPlanes::state_fields(IO& io, Self& self) {
    for (auto* array : {&self.impulse_, &self.reaction_, &self.friction_work_, &self.pressing_impulse_}) {
        io.field(*array);
        if constexpr (IO::reading) {
            if (array->size() != self.ghost_plane_.size()) io.fail("its planes are not the scene's");
        }
    }
}

void RigidPlanes::write_state(StateWriter& out) const { state_fields(out, *this); }
void RigidPlanes::read_state(StateReader& in) { state_fields(in, *this); }

}  // namespace gpa
