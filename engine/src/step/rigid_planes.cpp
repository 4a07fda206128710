#include "rigid_planes.hpp"

#include <algorithm>
#include <array>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "reduce_grain.hpp"

namespace gpa {
namespace {


}  // namespace

void RigidPlanes::assign(std::vector<std::size_t> rigid) {
    ghost_plane_ = std::move(rigid);
    reaction_.assign(ghost_plane_.size(), 0.0);
    impulse_.assign(ghost_plane_.size(), 0.0);
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
        const auto rigid = std::find(ghost_plane_.begin(), ghost_plane_.end(), p);
        using WorkAndImpulse = std::array<double, 2>;
        const WorkAndImpulse lost = tbb::parallel_deterministic_reduce(
            tbb::blocked_range<std::size_t>(0, real, reduce_grain), WorkAndImpulse{0.0, 0.0},
            [&](const tbb::blocked_range<std::size_t>& r, WorkAndImpulse acc) {
                for (std::size_t i = r.begin(); i != r.end(); ++i) {
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
        out.push_back({ghosts.planes()[ghost_plane_[k]].name, reaction_[k] + element_reaction, impulse_[k] + element_impulse});
    }
}

void RigidPlanes::write_state(StateWriter& out) const {
    out.array(impulse_);
    out.array(reaction_);
}

void RigidPlanes::read_state(StateReader& in) {
    in.array(impulse_);
    in.array(reaction_);
    if (impulse_.size() != ghost_plane_.size() || reaction_.size() != ghost_plane_.size()) in.fail("its planes are not the scene's");
}

}  // namespace gpa
