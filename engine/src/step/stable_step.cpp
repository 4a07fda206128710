#include "step/stable_step.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/memory_use.hpp"
#include "reduce_grain.hpp"

namespace gpa {

double* StableStep::bond_viscosity(std::size_t nodes) {
    largest_bond_q_.assign(nodes, 0.0);
    return largest_bond_q_.data();
}

double StableStep::next(const NodeStore& nodes, std::size_t real, const double* closing_speed, double element_limit, double time,
                        double dt_half) const {
    // Spec section 11, dt = C_cfl min_i h_i / (c_i + sqrt(Q_i / rho_i) + w_i), w_i the largest speed
    // at which a closed pair across an interface or crack closes on node i (separation.hpp; 0 in a
    // scene of one body without failure), with h_i the node's stable
    // length c / omega (kernels.hpp) in place of its smallest h_ij: h_ij ignores neighbours much
    // closer than h and neighbourhoods that have thinned out along one axis, and runs with it were
    // found unstable at any C_cfl above 0.1 once the impact face of a Taylor bar had spread.
    // Besides, no step may change a node's volume by more than solver.max_volume_change:
    // dt <= max_volume_change / |eps_v_dot_i| with the node's last rate, for compression, and for
    // expansion while its pressure is positive (a failed node expanding at zero pressure, debris,
    // does no work). The stable length sees the in-plane neighbours only; a failed node driven
    // towards the axis of an axisymmetric body (hoop rate u / x) or crushed between fragments
    // closing faster than sound was compressed 29 % in one step, and the pressure it then had a
    // step late gave back more work than its compression had booked: the kinetic energy of the
    // all-variable hypervelocity impact at 0.2 mm quadrupled in 20 steps, energy balance intact,
    // with the internal energy going negative.
    const double volume_limit = scene_->solver.max_volume_change > 0.0 ? scene_->solver.max_volume_change / scene_->solver.cfl : 0.0;
    const double limit = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, costly_node_grain), std::numeric_limits<double>::infinity(),
        [&](const tbb::blocked_range<std::size_t>& r, double best) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double q = std::max(nodes.viscous_pressure[i], largest_bond_q_.empty() ? 0.0 : largest_bond_q_[i]);
                double local = stable_time_step(nodes.stable_length[i], nodes.sound_speed[i], q, nodes.mass[i] / nodes.volume[i],
                                                closing_speed ? closing_speed[i] : 0.0);
                const double rate = nodes.volumetric_strain_rate[i];
                if (volume_limit > 0.0 && (rate < 0.0 || nodes.pressure[i] > 0.0) && std::abs(rate) > 0.0) {
                    local = std::min(local, volume_limit / std::abs(rate));
                }
                // NaN would drop out of a minimum: make it win, and report it below.
                best = std::isnan(local) ? local : std::min(best, local);
                if (std::isnan(best)) return best;
            }
            return best;
        },
        [](double x, double y) { return std::isnan(x) || std::isnan(y) ? std::nan("") : std::min(x, y); });
    if (std::isnan(limit)) {
        for (std::size_t i = 0; i < real; ++i) {
            const double local = nodes.stable_length[i] / nodes.sound_speed[i];
            if (std::isnan(local)) {
                throw NumericalError(fmt::format("{} at t = {:.6g} s: its stable time step is not "
                                                 "a number (stable length {}, sound speed {}, volume {})",
                                                 describe_node(nodes, i), time, nodes.stable_length[i], nodes.sound_speed[i], nodes.volume[i]),
                                     i, "stable time step");
            }
        }
        throw NumericalError(fmt::format("the stable time step is not a number at t = {} s", time));
    }
    double dt = scene_->solver.cfl * std::min(limit, element_limit);
    if (dt_half > 0.0) dt = std::min(dt, scene_->solver.time_step_growth * dt_half);
    dt = std::min(dt, scene_->solver.max_time_step);
    // Land on the end time instead of stepping past it (unless only a sliver would remain).
    const double end = scene_->stop.end_time;
    if (end > 0.0 && time < end) {
        const double left = end - time;
        if (dt > left) dt = left;
        else if (dt > 0.5 * left) dt = 0.5 * left;
    }
    if (!(dt > 0.0) || !std::isfinite(dt)) {
        throw NumericalError(fmt::format("the stable time step is {} s at t = {} s (a node has no size or no sound speed)", dt, time));
    }
    return dt;}

void StableStep::memory_use(MemoryUse& out) const {
    add_memory(out, "forces: largest bond viscosity", allocated_bytes(largest_bond_q_));
}

template <class IO, class Self>
void StableStep::state_fields(IO& io, Self& self) {
    io.field(self.largest_bond_q_);
}

void StableStep::write_state(StateWriter& out) const { state_fields(out, *this); }
void StableStep::read_state(StateReader& in) { state_fields(in, *this); }

}  // namespace gpa
