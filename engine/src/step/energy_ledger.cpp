#include "step/energy_ledger.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/geometry.hpp"
#include "reduce_grain.hpp"

namespace gpa {

namespace {

double* zeroed(std::vector<double>& v, std::size_t count) {
    v.assign(count, 0.0);
    return v.data();
}
}  // namespace

EnergyLedger::EnergyLedger(const SolverOptions& solver)
    // The stress-difference form makes no pair forces, whose power the compatible update books:
    // its internal energy follows the point update's own energy equation.
    : compatible_(solver.energy_update == EnergyUpdate::Compatible && solver.force_form == ForceForm::Pairwise),
      bond_(solver.viscosity == ViscosityKind::Bond),
      bond_parameters_{solver.viscosity_linear, solver.viscosity_quadratic, solver.bond_viscosity_eps0},
      hourglass_(solver.hourglass_coefficient > 0.0 || solver.hourglass_stiffness > 0.0),
      stiffness_(solver.hourglass_stiffness > 0.0),
      damping_(solver.hourglass_coefficient > 0.0),
      quadratic_(solver.hourglass_fit == HourglassFitOrder::Quadratic),
      relaxing_(relaxing_stiffness(solver)) {}

double* EnergyLedger::bond_power(std::size_t count) { return zeroed(bond_power_, count); }
double* EnergyLedger::hourglass_power(std::size_t count) { return zeroed(hourglass_power_, count); }
double* EnergyLedger::stiffness_power(std::size_t count) { return stiffness_ ? zeroed(stiffness_power_, count) : nullptr; }

template <int D>
void EnergyLedger::keep_hourglass_fits(HourglassFields<D>& control, std::size_t count) {
    if (!compatible_) return;
    // Sized to the real nodes exactly (no slack: their number does not change during a run).
    const auto point = [count](std::array<std::vector<double>, 10>& store, typename HourglassFields<D>::KeptFit& kept) {
        for (int k = 0; k <= D * D; ++k) store[k].resize(count);
        kept.scale = store[0].data();
        for (int k = 0; k < D * D; ++k) kept.matrix[k] = store[k + 1].data();
    };
    if (damping_) point(damping_fit_, control.damping_fit);
    // The quadratic fits' Cfit (hourglass.hpp, KeptFit::curvature).
    const auto point_curvature = [count](std::array<std::vector<double>, 18>& store, typename HourglassFields<D>::KeptFit& kept) {
        for (int k = 0; k < D * curvature_terms<D>; ++k) {
            store[k].resize(count);
            kept.curvature[k] = store[k].data();
        }
    };
    if (damping_ && quadratic_) point_curvature(damping_curvature_, control.damping_fit);
    // Only relaxed centres fit the stiffness with second derivatives (fixed ones keep the lattice's affine fit).
    if (relaxing_ && quadratic_) point_curvature(stiffness_curvature_, control.stiffness_fit);
    if (stiffness_) point(stiffness_fit_, control.stiffness_fit);
}

void EnergyLedger::keep_half_step_velocities(const NodeStore& nodes) {
    if (!(compatible_ && (hourglass_ || bond_))) return;
    // Ghosts included (their mirrored velocities): the control pairs the ghosts that continue a body
    // across a symmetry plane (hourglass.hpp, ghost_continues), and the booking reads them too.
    for (int c = 0; c < nodes.dim(); ++c) half_velocity_[c].assign(nodes.velocity[c].begin(), nodes.velocity[c].end());
}

template <class G>
void EnergyLedger::compatible_powers(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& forces,
                                     std::optional<HourglassFields<G::dim>> control, double hourglass_coefficient,
                                     NodeStore& nodes, std::size_t real, double dt_avg, const HeldNodes& held,
                                     const std::vector<PrescribedVelocitySpec>& regions, GhostSet& ghosts) {
    // Spec section 5, "[spec] Compatible energy": the internal energy of a node changes by the work
    // its stress forces do in this velocity update, at the mean of the half-step velocities before
    // and after it, v_mean = v^{n+3/2} - dt_avg F / (2 M): exactly the kinetic energy those forces
    // add, so the spatial and the time discretisation conserve energy together. (The point update's
    // own energy equation uses the strain rate of the geometry one step earlier than the forces; the
    // difference is first order in dt wherever stress and strain rate are large at once: +3 % of the
    // energy within 0.4 us of a 4 km/s impact at C_cfl 0.4, +1.5 % at 0.2.)
    constexpr int D = G::dim;
    for (int c = 0; c < D; ++c) resize_with_slack(mean_velocity_[c], nodes.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real, costly_node_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < D; ++c) {
            const double* v = nodes.velocity[c].data();
            const double* f = nodes.force[c].data();
            double* mean = mean_velocity_[c].data();
            for (std::size_t i = r.begin(); i != r.end(); ++i) mean[i] = v[i] - 0.5 * dt_avg * f[i] / nodes.mass[i];
        }
    });
    const std::array<double*, 3> mean_out{mean_velocity_[0].data(), mean_velocity_[1].data(), D == 3 ? mean_velocity_[2].data() : nullptr};
    // Held components (prescribed.hpp) went from v^{n+1/2} to the prescribed v^{n+3/2}, not by
    // dt_avg F / M: their mean is that of the two, so that the regions' work (the reaction's, at the
    // same mean) and this booking together give their kinetic-energy change exactly.
    if (!held.empty()) {
        held.set_mean_velocity(regions, D, {nodes.velocity[0].data(), nodes.velocity[1].data(), D == 3 ? nodes.velocity[2].data() : nullptr},
                               mean_out);
    }
    if (!ghosts.empty()) ghosts.mirror_vector_field(mean_out, D, real);
    std::array<const double*, D> mean{};
    for (int c = 0; c < D; ++c) mean[c] = mean_velocity_[c].data();
    // The hourglass forces' power in the same pass (made from the half-step velocities, as in the
    // force pass, their power taken at the mean velocities: the kinetic energy they remove in this
    // update).
    if (control) {
        // The force pass's fits (keep_hourglass_fits), for the same forces without fitting again.
        keep_hourglass_fits<D>(*control, real);
        control->use_kept_fits = true;
        control->power = hourglass_power_.data();
        control->stiffness_power = stiffness_ ? stiffness_power_.data() : nullptr;
        for (int c = 0; c < D; ++c) {
            control->velocity[c] = half_velocity_[c].data();
            control->force[c] = nullptr;
            control->power_velocity[c] = mean[c];
        }
    }
    // The stress work and its nodal-viscosity share booked in the same pass (StressPowerOut), first of
    // the step's bookings as book() once did them: the same operations in the same order per node.
    StressPowerOut booking;
    booking.internal_energy = nodes.internal_energy.data();
    booking.viscous_work = nodes.viscous_work.data();
    booking.mass = nodes.mass.data();
    booking.dt = dt_avg;
    if (bond_) {
        // The bond-viscous forces' work at the mean velocities (their Q_ij from the half-step
        // velocities the force pass made them with), in place of the force pass's power at v^{n+1/2}:
        // exactly the kinetic energy they take out in this update.
        booking.bond = &bond_parameters_;
        for (int c = 0; c < D; ++c) booking.bond_velocity[c] = half_velocity_[c].data();
        booking.bond_power = bond_power_.data();
    }
    compute_stress_power<G>(lists, weight, forces, mean, real, booking, control ? &*control : nullptr, hourglass_coefficient);
}

void EnergyLedger::book(NodeStore& nodes, std::size_t real, double dt_avg) {
    // (The stress forces' work and its nodal-viscosity share are booked before this, by the
    // compatible pass itself: compatible_powers.)
    if (!bond_ && !hourglass_) return;
    using Sums = std::array<double, 2>;  // hourglass heat, stored hourglass energy
    const Sums sums = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), Sums{0.0, 0.0},
        [&](const tbb::blocked_range<std::size_t>& r, Sums acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double m = nodes.mass[i];
                double& e = nodes.internal_energy[i];
                double& viscous = nodes.viscous_work[i];
                if (bond_) {
                    // The work of the bond-viscous forces becomes heat of the centre (spec section 5).
                    const double heat = -bond_power_[i] * dt_avg / m;
                    e += heat;
                    viscous += heat;
                }
                if (hourglass_) {
                    // The power the hourglass-control forces dissipate becomes heat of their centre,
                    // the same booking as bond viscosity (kernels.hpp: it is <= 0 pair by pair).
                    const double heat = -hourglass_power_[i] * dt_avg;
                    e += heat / m;
                    viscous += heat / m;
                    acc[0] += heat;
                    if (stiffness_) {
                        // The stiffness forces store energy rather than dissipate it: their work is
                        // internal energy of the centre (kernels.hpp, hourglass_stiffness).
                        const double stored = -stiffness_power_[i] * dt_avg;
                        e += stored / m;
                        acc[1] += stored;
                    }
                }
            }
            return acc;
        },
        [](Sums x, const Sums& y) { return Sums{x[0] + y[0], x[1] + y[1]}; });
    if (hourglass_) hourglass_work_ += sums[0];
    if (stiffness_) hourglass_energy_ += sums[1];
}

void EnergyLedger::memory_use(MemoryUse& out) const {
    add_memory(out, "energy ledger: powers per node", allocated_bytes(bond_power_) + allocated_bytes(hourglass_power_) +
                                                          allocated_bytes(stiffness_power_));
    std::size_t velocities = 0;
    for (const auto& v : mean_velocity_) velocities += allocated_bytes(v);
    for (const auto& v : half_velocity_) velocities += allocated_bytes(v);
    add_memory(out, "energy ledger: mean and half-step velocities", velocities);
    std::size_t fits = 0;
    for (const auto& v : damping_fit_) fits += allocated_bytes(v);
    for (const auto& v : stiffness_fit_) fits += allocated_bytes(v);
    for (const auto& v : damping_curvature_) fits += allocated_bytes(v);
    for (const auto& v : stiffness_curvature_) fits += allocated_bytes(v);
    add_memory(out, "energy ledger: hourglass fits of the force pass", fits);
}

template <class IO, class Self>
void EnergyLedger::state_fields(IO& io, Self& self) {
    io.tag("ENRG");
    io.field(self.boundary_work_);
    io.field(self.hourglass_work_);
    io.field(self.hourglass_energy_);
    io.field(self.bond_power_);
}

void EnergyLedger::write_state(StateWriter& out) const { state_fields(out, *this); }
void EnergyLedger::read_state(StateReader& in) { state_fields(in, *this); }

template void EnergyLedger::compatible_powers<PlaneStrain>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                                           std::optional<HourglassFields<2>>, double, NodeStore&, std::size_t,
                                                           double, const HeldNodes&, const std::vector<PrescribedVelocitySpec>&,
                                                           GhostSet&);
template void EnergyLedger::compatible_powers<Axisymmetric>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                                            std::optional<HourglassFields<2>>, double, NodeStore&, std::size_t,
                                                            double, const HeldNodes&, const std::vector<PrescribedVelocitySpec>&,
                                                            GhostSet&);
template void EnergyLedger::compatible_powers<ThreeD>(const CompressedRows&, WeightKind, const ForceFields<3>&,
                                                      std::optional<HourglassFields<3>>, double, NodeStore&, std::size_t, double,
                                                      const HeldNodes&, const std::vector<PrescribedVelocitySpec>&, GhostSet&);

template void EnergyLedger::keep_hourglass_fits<2>(HourglassFields<2>&, std::size_t);
template void EnergyLedger::keep_hourglass_fits<3>(HourglassFields<3>&, std::size_t);

}  // namespace gpa
