#pragma once
// Drivers: apply the kernels of kernels.hpp over the neighbour lists, in parallel on oneTBB.
// Each has a serial twin (the Serial scatter plan, or a single-thread arena) and the results do
// not depend on the thread count.

#include <cstddef>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/hourglass.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

// Gather over the neighbours of every centre in [0, lists.rows()): geometry factors alpha,
// velocity gradient L, volumetric strain rate (with the hoop rate in axisymmetric geometry)
// and the smallest h_ij (spec section 3; Eq. 7-15, 42-53). A plain parallel loop: each centre
// writes only its own values.
// Throws InputError naming the node when a neighbourhood gives no geometry factor along some
// axis (an empty or flat neighbourhood) and NumericalError when two nodes coincide.
// centres: how many leading rows to process (the real nodes when ghost rows follow); the
// default processes every row.
template <class G>
void compute_velocity_gradient(const CompressedRows& lists, WeightKind weight,
                               const GradientFields<G::dim>& f, std::size_t centres = static_cast<std::size_t>(-1));

struct BondViscosityParameters {
    double linear = 0.2;     // C_L
    double quadratic = 4.0;  // C_Q
    double eps0 = 0.01;      // regularisation of mu_ij (Eq. 38)
};

// Pairwise forces (Eq. 21-24, 54-56), with bond viscosity (Eq. 37-38) when `bond` is given and
// the hoop term for axisymmetric centres (spec section 5). Zeroes f.force for every node the
// lists touch, then scatters by the colours of `plan`.
template <class G>
void compute_forces(const CompressedRows& lists, const ScatterPlan& plan, WeightKind weight,
                    const BondViscosityParameters* bond, const ForceFields<G::dim>& f,
                    std::size_t node_count);

// The power of each real centre's stress forces at the velocities v (spec section 5, "[spec]
// Compatible energy"): for centre i,
//   power_i = sum_j P(ij) . (v_j - v_i)  (+ P_x(ii) v_x,i, the hoop force, in axisymmetric geometry)
//           = - V_i sigma_i : L_i(v)   (Eq. 21-24 and the energy identity of section 5),
// with P(ij) the force of Eq. 21-22 from sigma_i = s_i - (P_i + Q_i) I (no bond viscosity), and
// viscous_power_i its -Q_i I part alone. Called with the mean of the half-step velocities on both
// sides of a velocity update, sum_i power_i dt is the kinetic energy the stress forces add in that
// update, to round-off, so booking -power_i dt as internal energy of i conserves energy exactly.
// `velocity` covers ghosts too (mirrored like the velocities themselves). No pair force is made:
// the pairs are gathered into the row's sum of velocity differences and contracted with
// sigma_i N_i once per centre (kernels.hpp, accumulate_velocity_difference).
// With `hourglass` set (its power_velocity the same velocities, no force), the same pass also
// writes each centre's hourglass-control powers (hourglass.hpp, hourglass_centre) to
// hourglass->power and hourglass->stiffness_power, while the centre's row is in cache: one visit
// of every row for all the work the energy update books.
template <class G>
void compute_stress_power(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& f,
                          const std::array<const double*, G::dim>& velocity, std::size_t real_count, double* power,
                          double* viscous_power, const HourglassFields<G::dim>* hourglass = nullptr,
                          double hourglass_coefficient = 0.0);

// Where the pass above puts each centre's two powers: in the arrays `power` and `viscous_power`,
// or, with `internal_energy` set, straight into the centre's specific energies as the energy
// ledger books them (EnergyLedger::book: e_i -= power_i dt / m_i, w_v,i -= viscous_power_i dt / m_i,
// the same operations on the same numbers), so that a run holds no array of either (16 bytes per
// node).
struct StressPowerOut {
    double* power = nullptr;
    double* viscous_power = nullptr;
    double* internal_energy = nullptr;
    double* viscous_work = nullptr;
    const double* mass = nullptr;
    double dt = 0.0;
    // Bond viscosity (Eq. 37-38), optional: each pair's Q_ij made again as the force pass made it,
    // from `bond_velocity` (the velocities of the force pass), and the power of its forces at the
    // pass's `velocity` into bond_power[i], per real centre (the compatible booking of the
    // bond-viscous work, spec section 5). Needs the force fields' mass and sound speed.
    const BondViscosityParameters* bond = nullptr;
    std::array<const double*, 3> bond_velocity{};
    double* bond_power = nullptr;
};
template <class G>
void compute_stress_power(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& f,
                          const std::array<const double*, G::dim>& velocity, std::size_t real_count, const StressPowerOut& out,
                          const HourglassFields<G::dim>* hourglass = nullptr, double hourglass_coefficient = 0.0);

}  // namespace gpa
