#pragma once
// A part of the time step (simulation.cpp): the energy ledger. Every booking of work and heat into
// the nodes' internal energy happens here, once per step, and the run's sums of work that the energy
// balance needs (docs/energy.md) are kept here:
//   * the stress forces' work at the mean velocities of the velocity update, with the compatible
//     energy update (spec section 5, "[spec] Compatible energy"), and its nodal-viscosity part;
//   * the bond-viscous forces' work (spec section 5) as heat of their centre;
//   * the hourglass control's dissipated power as heat of its centre, and the stiffness form's work
//     as stored internal energy (kernels.hpp);
//   * the boundary work the penetration guard takes out of the bodies.
// The force pass writes the powers it finds into the ledger's arrays (bond_power, hourglass_power,
// stiffness_power); the velocity update then asks for the compatible powers and books the step.
// Saves and restores its sums as its own checkpoint section.

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/hourglass.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/prescribed.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

class EnergyLedger {
public:
    explicit EnergyLedger(const SolverOptions& solver);

    bool compatible() const { return compatible_; }
    bool hourglass() const { return hourglass_; }

    // Per-centre powers of the force pass, W, sized and zeroed for `count` nodes (ghosts included).
    double* bond_power(std::size_t count);
    double* hourglass_power(std::size_t count);
    double* stiffness_power(std::size_t count);  // null without the stiffness form

    // For the force pass: keeps its hourglass fits of `count` centres (hourglass.hpp, KeptFit) in the
    // ledger's arrays, so that compatible_powers makes the same forces without fitting again. Only
    // with the compatible update (nothing else reads them).
    template <int D>
    void keep_hourglass_fits(HourglassFields<D>& control, std::size_t count);

    // Before the velocity update: v^{n+1/2} of the nodes, from which the force pass made the
    // hourglass and bond-viscous forces (their power is taken at the mean velocities later). Only
    // when needed.
    void keep_half_step_velocities(const NodeStore& nodes);

    // After the velocity update and the prescribed components (compatible update only): the work of
    // each centre's stress forces and, with bond viscosity or the hourglass control, of those forces
    // at the mean velocities v_mean = v^{n+3/2} - dt_avg F / (2 M) (held components: the mean of their two half
    // steps; ghosts mirrored), in one visit of every row (drivers.hpp, compute_stress_power). The
    // stress work and its nodal-viscosity share are booked into the nodes in that visit, the first
    // of the step's bookings (book() does the rest); the bond-viscous and the control's powers go to
    // the ledger's arrays, replacing the force pass's.
    // `forces` and `control` are the fields of the force pass (control: none without the control;
    // its velocities and outputs are set here: the kept half-step velocities, the ledger's arrays).
    template <class G>
    void compatible_powers(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& forces,
                           std::optional<HourglassFields<G::dim>> control, double hourglass_coefficient, NodeStore& nodes,
                           std::size_t real, double dt_avg, const HeldNodes& held,
                           const std::vector<PrescribedVelocitySpec>& regions, GhostSet& ghosts);

    // Books the step's work and heat into the real nodes (one pass, in a fixed order per node and a
    // fixed order of the sums, so that nothing depends on the thread count): bond-viscous heat,
    // hourglass heat and stored hourglass energy, after the compatible stress work (compatible_powers).
    void book(NodeStore& nodes, std::size_t real, double dt_avg);

    void add_boundary_work(double work) { boundary_work_ += work; }
    double boundary_work() const { return boundary_work_; }
    double hourglass_work() const { return hourglass_work_; }      // dissipated by the control since t = 0, J
    double hourglass_energy() const { return hourglass_energy_; }  // stored by the stiffness form since t = 0, J

    void memory_use(MemoryUse& out) const;

    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self);

    bool compatible_ = true;
    bool bond_ = false;
    BondViscosityParameters bond_parameters_;  // C_L, C_Q, eps0 of the scene (with bond_)
    bool hourglass_ = false;
    bool stiffness_ = false;
    bool damping_ = false;  // the hourglass control's damping form (C_hg > 0)
    bool quadratic_ = false;  // its quadratic fit (SolverOptions::hourglass_fit)
    bool relaxing_ = false;   // the stiffness on flowing nodes too (relaxing_stiffness)
    double boundary_work_ = 0.0;
    double hourglass_work_ = 0.0;
    double hourglass_energy_ = 0.0;
    std::vector<double> bond_power_, hourglass_power_, stiffness_power_;  // per node of the force pass
    std::array<std::vector<double>, 3> mean_velocity_;                    // per node, ghosts mirrored
    std::array<std::vector<double>, 3> half_velocity_;                    // per node, ghosts included
    // The force pass's hourglass fits per real node: the scale, then the D * D matrix entries.
    std::array<std::vector<double>, 10> damping_fit_, stiffness_fit_;
    // The quadratic fits' Cfit per real node, D * D (D + 1) / 2 entries (SolverOptions::hourglass_fit).
    std::array<std::vector<double>, 18> damping_curvature_, stiffness_curvature_;
};

}  // namespace gpa
