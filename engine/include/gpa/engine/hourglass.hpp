#pragma once
// Zero-energy-mode ("hourglass") control of fixed-connectivity centres (kernels.hpp,
// spec section 2): pair forces that damp the part of the lattice pairs' velocity differences no
// affine field explains. They conserve momentum (equal and opposite), vanish for every affine
// velocity field, and only dissipate; each centre's dissipated power is returned so that the
// integrator books it as the centre's heat.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <type_traits>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa {

template <int D>
struct HourglassFields {
    std::array<const double*, D> position{};
    std::array<const double*, D> velocity{};
    const double* size_weight = nullptr;  // W_j
    const double* mass = nullptr;
    const double* sound_speed = nullptr;
    const double* smallest_h = nullptr;   // h_i of the damping rate c_i / h_i
    const Connectivity* connectivity = nullptr;
    const std::int32_t* body = nullptr;
    // Set when the pairs of failed nodes separate (separation.hpp): a crack is no pair of the
    // control (its faces slide freely, spec section 2 "[spec] Sliding contact"); and when the
    // control acts on every node (SolverOptions::hourglass_nodes), whose failed nodes are debris.
    const std::uint8_t* failed = nullptr;
    // Per ghost (index j - real_count), 1 where the ghost continues the body across symmetry planes
    // (a half or quarter model): its pairs are controlled like those of the real node it mirrors, so
    // that a centre next to the plane is fitted over the neighbourhood it has in the whole body. The
    // forces such pairs put on a ghost belong to its source, mirrored (the caller folds them back:
    // GhostSet::fold_forces). Null, and for ghosts of a rigid plane or the axis: no part.
    const std::uint8_t* ghost_continues = nullptr;
    const double* plastic_strain = nullptr;
    // Variable-connectivity centres are controlled while their equivalent plastic strain is below
    // this (the lattice regime, where the mode lives: see apply_hourglass_control); fixed ones always.
    double lattice_plastic_strain = 0.0;
    // The fit with the second derivatives (SolverOptions::hourglass_fit; kernels.hpp,
    // QuadraticHourglassFit) for the damping and for the stiffness form on flowing centres; the
    // affine fit otherwise (and always for fixed centres' stiffness, against the lattice).
    bool quadratic = false;
    // The stiffness form (kernels.hpp, hourglass_stiffness): C_hs > 0 adds, on fixed centres, forces
    // against the non-affine part of the lattice pairs' displacement since t = 0 (pairs of two fixed
    // nodes of one body), from the initial positions and diameters.
    double stiffness = 0.0;  // C_hs; 0 = none
    std::array<const double*, D> initial_position{};
    const double* initial_diameter = nullptr;
    // Set with SolverOptions::hourglass_stiffness_relaxation: the stiffness form acts on the
    // controlled variable centres too, against the relaxing reference (NodeStore::reference_position):
    // the damping's fit (its pairs, weights and offsets) applied to the displacements since it.
    std::array<const double*, D> reference_position{};
    // outputs
    std::array<double*, D> force{};  // added to; all null: only the power is computed
    double* power = nullptr;         // per centre: the power of its damping forces (<= 0), W
    double* stiffness_power = nullptr;  // per centre: the power of its stiffness forces (either sign), W; set with stiffness
    // Optional: the power is that of the forces (made from `velocity`) at these velocities instead,
    // sum_j F_j . (w_j - w_i); the compatible energy update books the heat at the mean velocities of
    // the velocity update (docs/energy.md).
    std::array<const double*, D> power_velocity{};
    // The fits of the centres, kept from the force pass for the energy booking's pass, which then
    // makes the same forces without fitting again (same positions and velocities, same fit, the same
    // forces bit for bit): per centre, the force scale (kappa_i / sum_k w_k for the damping,
    // k_i / sum_k w_k for the stiffness form; 0 where the centre has no control or no fit) and the
    // fitted matrix (Lfit_i, Ffit_i; D * D entries, row-major).
    struct KeptFit {
        double* scale = nullptr;
        std::array<double*, D * D> matrix{};
        // The quadratic fit's Cfit (D * curvature_terms entries, row-major; zero where the affine fit
        // served): set with `quadratic` (for the stiffness form, read on flowing centres only).
        std::array<double*, D * curvature_terms<D>> curvature{};
    };
    KeptFit damping_fit, stiffness_fit;  // written when set and use_kept_fits is false
    bool use_kept_fits = false;          // read the kept fits instead of fitting (no forces are added then)
};

template <int D>
HourglassFields<D> hourglass_fields(NodeStore& nodes, double lattice_plastic_strain, double* power);

// The same with the stiffness form on (C_hs = stiffness > 0), its power per centre into stiffness_power.
template <int D>
HourglassFields<D> hourglass_fields(NodeStore& nodes, double lattice_plastic_strain, double* power, double stiffness,
                                    double* stiffness_power);

// Adds the control forces of the controlled centres in [0, real_count) over their pairs with real
// neighbours of their own body (ghosts and other bodies take no part) to f.force, by the colours
// of `plan` (a conflict-free plan of `lists`), and writes each centre's power (0 for the others).
// Controlled centres: every fixed-connectivity node, whose lattice stencil has the exact
// zero-energy mode, and every variable-connectivity node still in the lattice regime (plastic
// strain below f.lattice_plastic_strain), whose neighbourhood is still the regular lattice and
// carries the same mode nearly undamped (docs/connectivity.md). coefficient: C_hg >= 0 (0: the
// stiffness form alone, when f.stiffness > 0).
// The powers of one centre's control forces (W): the damping's (<= 0 at the velocities the forces
// are made from) and the stiffness form's (either sign).
struct HourglassPower {
    double damping = 0.0;
    double stiffness = 0.0;
};

// The control at one centre i with neighbour row `row` (the per-centre kernel of
// apply_hourglass_control): adds its forces to f.force when that is set (the caller keeps two
// centres that share a node from running at once) and returns their powers; zero powers for a
// centre that is not controlled. The energy booking's pass (drivers.hpp, compute_stress_power)
// takes the damping's power pair by pair in its own walk of the row (KeptDampingPower, below) and
// calls this, with no force, power_velocity set and coefficient 0, for the stiffness form's.
template <int D>
HourglassPower hourglass_centre(std::span<const NodeIndex> row, std::size_t i, const HourglassFields<D>& f,
                                std::size_t real_count, double coefficient);

// A pair (i, j) the control acts on: j of the centre's own body, real or a ghost that continues the
// body across a symmetry plane (ghosts of rigid planes and of the axis, and other bodies, take no
// part, nor do the pairs of a failed node when those separate).
template <int D>
inline bool controlled_hourglass_pair(const HourglassFields<D>& f, std::size_t i, std::size_t j, std::size_t real_count) {
    const bool continues = j < real_count || (f.ghost_continues && f.ghost_continues[j - real_count]);
    return continues && f.body[j] == f.body[i] && !(f.failed && (f.failed[i] || f.failed[j]));
}

// The power of one centre's damping forces made again from the force pass's kept fit
// (use_kept_fits), pair by pair (term), for a pass that walks the row for sums of its own (the energy
// booking's, compute_stress_power): F_j = -kappa w_j e_ij (kernels.hpp), its power
// F_j . (w_j - w_i) at power_velocity. The same numbers, in the same order, as hourglass_centre's
// own walk of the row, which uses it too. `Curved`: the fit may have second derivatives
// (HourglassFields::quadratic; kept zero where the affine fit served); the pass chooses it once, so
// that the affine walk carries neither the curvature's registers nor a branch per pair.
template <int D, bool Curved = false>
class KeptDampingPower {
public:
    KeptDampingPower() = default;
    // Inactive (every pair adds nothing) for a centre without damping: kept scale 0, i a ghost, or
    // no damping at all (coefficient 0).
    KeptDampingPower(const HourglassFields<D>& f, std::size_t i, std::size_t real_count, double coefficient) : i_(i) {
        if (i >= real_count || !(coefficient > 0.0) || !f.use_kept_fits) return;
        kappa_ = f.damping_fit.scale[i];
        if (kappa_ == 0.0) return;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < D; ++b) fitted_gradient_(a, b) = f.damping_fit.matrix[a * D + b][i];
        }
        if constexpr (Curved) {
            curved_.inverse_h = 1.0 / f.smallest_h[i];
            for (int a = 0; a < D; ++a) {
                for (int b = 0; b < curvature_terms<D>; ++b) {
                    curved_.curvature(a, b) = f.damping_fit.curvature[a * curvature_terms<D> + b][i];
                }
            }
        }
        other_velocity_ = f.power_velocity[0] != nullptr;
        for (int c = 0; c < D; ++c) {
            v_i_[c] = f.velocity[c][i];
            if (other_velocity_) w_i_[c] = f.power_velocity[c][i];
        }
    }
    bool active() const { return kappa_ != 0.0; }
    // The power of pair (i, j), r = x_j - x_i, for the caller to sum over the row in its order
    // (its sum in a local of the caller's loop, not in this object's memory); 0 for a pair the
    // control does not act on (a sum that starts at +0 is never -0, so adding +0 changes no bit).
    double term(const HourglassFields<D>& f, std::size_t j, const Vec<D>& r, std::size_t real_count) const {
        if (!controlled_hourglass_pair(f, i_, j, real_count)) return 0.0;
        // The velocity differences in scalars, component by component, with Eigen's own product for
        // L r and a dot product summed first to last, as in hourglass_centre (kernels.hpp,
        // hourglass_velocity_error): a 3D vector gathered into Eigen's packets here went through
        // the stack, where two 8-byte stores read back as one 16-byte load stall the loop (the
        // fused walk took twice the time of the two walks it replaced).
        const double w = hourglass_pair_weight(f.size_weight[j], r.squaredNorm());
        const double scale = -kappa_ * w;
        Vec<D> fitted = fitted_gradient_ * r;
        if constexpr (Curved) {
            // As quadratic_fitted_velocity sums them; a zero Cfit (the affine fit served) adds +0.
            fitted += curved_.curvature * curvature_basis<D>(r, curved_.inverse_h);
        }
        double power = 0.0;
        for (int a = 0; a < D; ++a) {
            const double dv = f.velocity[a][j] - v_i_[a];
            const double force_on_j = scale * (dv - fitted[a]);
            const double dw = other_velocity_ ? f.power_velocity[a][j] - w_i_[a] : dv;
            power = a == 0 ? force_on_j * dw : power + force_on_j * dw;
        }
        return power;
    }

private:
    struct CurvedPart {
        double inverse_h = 0.0;
        Eigen::Matrix<double, D, curvature_terms<D>> curvature = Eigen::Matrix<double, D, curvature_terms<D>>::Zero();
    };
    struct NoCurvature {};
    std::size_t i_ = 0;
    double kappa_ = 0.0;
    bool other_velocity_ = false;
    Mat<D> fitted_gradient_ = Mat<D>::Zero();
    Vec<D> v_i_ = Vec<D>::Zero(), w_i_ = Vec<D>::Zero();
    [[no_unique_address]] std::conditional_t<Curved, CurvedPart, NoCurvature> curved_;
};

template <int D>
void apply_hourglass_control(const CompressedRows& lists, const ScatterPlan& plan, const HourglassFields<D>& f,
                             std::size_t real_count, double coefficient);

}  // namespace gpa
