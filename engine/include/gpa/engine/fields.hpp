#pragma once
// Typed views of the node fields that each driver reads and writes. A driver's signature names
// its view, so its data dependencies are visible; the views are made from a NodeStore by the
// functions below, or by hand in an embedding program with its own storage.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "gpa/engine/kernels.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

// What the pair kernel reads: positions, diameters (for h_ij), connectivity and body (for the
// choice of R_ij, spec section 2 "Mixed pairs" and "Different bodies").
template <int D>
struct PairFields {
    std::array<const double*, D> position{};
    const double* diameter = nullptr;
    const Connectivity* connectivity = nullptr;
    const std::int32_t* body = nullptr;
    double influence_distance = 1.0;
    // v at which a lattice pair's weight stops falling (weights.hpp, lattice_weight_reach_for;
    // pair_fields sets it for the scene's influence distance and dimension).
    double lattice_reach = lattice_weight_reach;
    // Sliding contact (spec section 2, "[spec] Sliding contact"; docs/contact.md): with
    // `sliding_contact`, a pair between two bodies, or (with failed_pairs_separate) one with a failed
    // node, carries velocity differences and forces along one direction only (sliding_normal). Such a
    // pair that is still in the lists is a closed separable pair (separation.hpp removed the open ones).
    bool sliding_contact = false;
    bool failed_pairs_separate = false;
    const std::uint8_t* failed = nullptr;  // read with failed_pairs_separate
    // Per node (ghosts included), the outward direction of its body where it touches another
    // (separation.hpp); all null: every sliding pair acts along its line of centres.
    std::array<const double*, D> contact_direction{};

    Vec<D> x(std::size_t i) const {
        Vec<D> p;
        for (int c = 0; c < D; ++c) p[c] = position[c][i];
        return p;
    }

    // A closed separable pair under sliding contact (see above). Symmetric in i and j.
    bool sliding(std::size_t i, std::size_t j) const {
        return sliding_contact && (body[i] != body[j] || (failed_pairs_separate && (failed[i] || failed[j])));
    }

    // The one direction a sliding pair acts along (spec section 2, "[spec] Sliding contact"). Across
    // a contact between bodies: the normal of the contact surface, n = m_i - m_j normalised, m the
    // outward directions of the two bodies at either end (minus the weighted sum of unit vectors to a
    // node's own body's neighbours: on a flat face of a lattice exactly the face normal, whatever the
    // other body's nodes do), turned to point from i towards j. Where the two give no clear direction
    // (|m_i - m_j| < 1/4: nodes surrounded by their own bodies), and across cracks within a body:
    // the line of centres l. n_ji = -n_ij bit for bit, so both ends project alike.
    Vec<D> sliding_normal(std::size_t i, std::size_t j, const Vec<D>& l) const {
        if (!contact_direction[0] || body[i] == body[j]) return l;
        Vec<D> n;
        for (int c = 0; c < D; ++c) n[c] = contact_direction[c][i] - contact_direction[c][j];
        const double norm = n.norm();
        if (!(norm >= 0.25)) return l;
        n /= norm;
        return n.dot(l) < 0.0 ? Vec<D>(-n) : n;
    }

    // Two fixed-connectivity nodes of one body form a lattice pair (spec section 2).
    bool lattice_pair(std::size_t i, std::size_t j) const {
        return connectivity[i] == Connectivity::Fixed && connectivity[j] == Connectivity::Fixed && body[i] == body[j];
    }

    // Pair geometry of centre i and neighbour j. Every pair weighs R(r / h) (Eq. 1b or 62-65); a
    // lattice pair R(min(r / h, lattice_reach)), so that it is never lost however far its
    // nodes move apart (spec section 2, "[spec] Lattice weights"; the paper's Eq. 1a has R = 1).
    // r = 0 (coincident nodes) is returned as is; the drivers report it.
    template <class VariableWeight>
    PairGeometry<D> pair(std::size_t i, std::size_t j) const {
        PairGeometry<D> p;
        p.dx = offset(i, j);
        p.r = p.dx.norm();
        p.inv_r = 1.0 / p.r;
        p.l = p.dx * p.inv_r;
        p.h = pair_smoothing_length(influence_distance, diameter[i], diameter[j]);
        const double v = p.r / p.h;
        p.R = VariableWeight::value(lattice_pair(i, j) ? std::min(v, lattice_reach) : v);
        p.R_over_r2 = p.R * p.inv_r * p.inv_r;
        return p;
    }

    // pair<W>(i, js[k]) for k in [0, count), into out[k]: the same numbers bit for bit, with the
    // square roots and divisions of two pairs made at once (the two lanes of an SSE2 register; a
    // pair's geometry waits mostly on the divider, which takes two lanes in the time of one).
    template <class VariableWeight>
    void pairs(std::size_t i, const NodeIndex* js, std::size_t count, PairGeometry<D>* out) const {
        std::size_t k = 0;
        for (; k + 2 <= count; k += 2) two_pairs<VariableWeight>(i, js[k], js[k + 1], out + k);
        for (; k < count; ++k) out[k] = pair<VariableWeight>(i, js[k]);
    }

    // x_j - x_i.
    Vec<D> offset(std::size_t i, std::size_t j) const {
        Vec<D> dx;
        for (int c = 0; c < D; ++c) dx[c] = position[c][j] - position[c][i];
        return dx;
    }

    // The unit vector along an offset, the same numbers as pair()'s l: for a kept pair (which
    // has no l) where a kernel needs the direction itself (a sliding pair's normal).
    static Vec<D> direction(const Vec<D>& dx) { return dx * (1.0 / dx.norm()); }

    // The terms R_ij / r_ij^2 that this step's gradient sweep kept for the centres [0, kept_rows),
    // one per entry of the lists (NeighbourLists::keep_pairs; entry k of row i is
    // lists.offsets[i] + k). The sweeps after it in the same step (forces, stress power,
    // smoothing) read them instead of making the square root, the two divisions and the weight
    // again: positions, diameters, connectivity and bodies do not change between the gradient and
    // the last of these sweeps (the switching phase comes after them), so they are the same numbers
    // bit for bit.
    const double* kept_weight_over_r2 = nullptr;
    std::size_t kept_rows = 0;

    // pair<W>(i, j) of list entry `entry` of centre i, from the kept term where there is one. A
    // kept pair has only dx and R / r^2 (the rest NaN): a kernel that reads r calls pair(i, j), one
    // that needs h_ij makes it from the diameters (the bond viscosity, Eq. 38), and one that needs
    // l takes direction(dx).
    template <class VariableWeight>
    PairGeometry<D> pair(std::size_t i, std::size_t j, std::size_t entry) const {
        if (i >= kept_rows) return pair<VariableWeight>(i, j);
        PairGeometry<D> p;
        p.dx = offset(i, j);
        p.R_over_r2 = kept_weight_over_r2[entry];
        p.r = p.h = p.inv_r = p.R = std::numeric_limits<double>::quiet_NaN();
        p.l = Vec<D>::Constant(std::numeric_limits<double>::quiet_NaN());
        return p;
    }

    // pair() of (i, j0) and (i, j1) (r, l, h_ij of Eq. 2, R of Eq. 1b or 62-65) in the two lanes
    // of GCC vectors: each lane takes pair()'s operations in pair()'s order (Eigen's squared norm
    // sums the components first to last).
    template <class VariableWeight>
    void two_pairs(std::size_t i, std::size_t j0, std::size_t j1, PairGeometry<D>* out) const {
        using Lanes = double __attribute__((vector_size(16)));
        std::array<Lanes, D> dx;
        for (int c = 0; c < D; ++c) dx[c] = Lanes{position[c][j0], position[c][j1]} - position[c][i];
        Lanes r2 = dx[0] * dx[0];
        for (int c = 1; c < D; ++c) r2 += dx[c] * dx[c];
#if defined(__SSE2__)
        const Lanes r = reinterpret_cast<Lanes>(_mm_sqrt_pd(reinterpret_cast<__m128d>(r2)));
#else
        const Lanes r{std::sqrt(r2[0]), std::sqrt(r2[1])};
#endif
        const Lanes inv_r = 1.0 / r;
        const Lanes h = pair_smoothing_length(influence_distance, Lanes{diameter[i], diameter[i]}, Lanes{diameter[j0], diameter[j1]});
        Lanes v = r / h;
        if (lattice_pair(i, j0)) v[0] = std::min(v[0], lattice_reach);
        if (lattice_pair(i, j1)) v[1] = std::min(v[1], lattice_reach);
        const Lanes R = VariableWeight::value(v);
        const Lanes R_over_r2 = R * inv_r * inv_r;
        for (int lane = 0; lane < 2; ++lane) {
            PairGeometry<D>& p = out[lane];
            for (int c = 0; c < D; ++c) {
                p.dx[c] = dx[c][lane];
                p.l[c] = dx[c][lane] * inv_r[lane];
            }
            p.r = r[lane];
            p.inv_r = inv_r[lane];
            p.h = h[lane];
            p.R = R[lane];
            p.R_over_r2 = R_over_r2[lane];
        }
    }

    // The smoothing's pair weight (Eq. 66-67) of list entry `entry` of centre i: R_ij as
    // (R / r^2) r^2, from the kept term or made, the same numbers either way (and the same from
    // either end of the pair).
    template <class VariableWeight>
    double weight(std::size_t i, std::size_t j, std::size_t entry) const {
        if (i < kept_rows) return kept_weight_over_r2[entry] * offset(i, j).squaredNorm();
        const PairGeometry<D> p = pair<VariableWeight>(i, j);
        return p.R_over_r2 * p.dx.squaredNorm();
    }
};

template <int D>
struct GradientFields {
    PairFields<D> pairs;
    std::array<const double*, D> velocity{};
    const double* size_weight = nullptr;  // W_j
    // The paper's per-direction normalisation (false) or the full moment matrix (true, spec
    // section 7); with the full one, the off-diagonal entries of M^-1 go to alpha_shear.
    bool full_normalisation = false;
    // The paper's correction at free surfaces and interfaces (section 2.5; kernels.hpp,
    // OneSidedMoments): the normalisation halved normal to a one-sided neighbourhood.
    bool surface_correction = false;
    // outputs, one value per centre
    std::array<double*, D> alpha{};                 // the diagonal of the normalisation N
    std::array<double*, 3> alpha_shear{};           // off-diagonal N: 2D xz; 3D yz, xz, xy (full only)
    std::array<double*, D * D> velocity_gradient{};  // L_ab at [a * D + b]
    double* volumetric_strain_rate = nullptr;
    double* smallest_h = nullptr;
    double* stable_length = nullptr;  // optional (kernels.hpp: stable_length)
    double alpha_limit = 0.0;         // > 0: alpha_b <= alpha_limit / W_i
    // Optional, one per list entry of the centres swept: each pair's R_ij / r_ij^2, kept for the
    // sweeps after the gradient (PairFields::kept_weight_over_r2).
    double* keep_weight_over_r2 = nullptr;
    // false: a centre without neighbours, or whose neighbours give no geometry factor along some
    // axis, is an error (InputError naming it). true (in a run, where fracture and spall leave
    // fragments): its factor along that axis is 0, so it has no strain rate and exerts no force
    // along it; a node with no neighbours flies on with the hoop rate u/x alone.
    bool allow_degenerate = false;
};

template <int D>
struct ForceFields {
    PairFields<D> pairs;
    const double* volume = nullptr;       // V_i
    const double* size_weight = nullptr;  // W_j
    std::array<const double*, D> alpha{};
    bool full_normalisation = false;             // read alpha_shear too (spec section 7)
    std::array<const double*, 3> alpha_shear{};
    std::array<const double*, 6> deviatoric_stress{};
    const double* pressure = nullptr;
    const double* viscous_pressure = nullptr;  // nodal Q_i; nullptr when there is none
    // read by bond viscosity only
    std::array<const double*, D> velocity{};
    const double* mass = nullptr;
    const double* sound_speed = nullptr;
    // outputs
    std::array<double*, D> force{};
    double* bond_viscous_power = nullptr;  // per centre, optional: the power of its bond-viscous forces
    double* largest_bond_viscosity = nullptr;  // per centre, optional: its largest Q_ij (for the time step)
    std::size_t hoop_count = 0;            // centres [0, hoop_count) feel their hoop stress
    // The stress-difference form (Eq. 28, kernels.hpp stress_difference_term) instead of pair
    // forces: the real centres [0, hoop_count) gather their own forces; a ghost neighbour's term,
    // reversed, is written on the ghost, where the planes read their reactions.
    bool stress_difference = false;
};

// The normalisation N of node i (Eq. 14-15, 51-53: diag(alpha); spec section 7: M^-1 when the
// off-diagonal entries are given).
template <int D>
inline Mat<D> normalisation_of(const std::array<const double*, D>& alpha, const std::array<const double*, 3>& shear,
                               std::size_t i) {
    Mat<D> n = Mat<D>::Zero();
    for (int c = 0; c < D; ++c) n(c, c) = alpha[c][i];
    if (shear[0]) {
        if constexpr (D == 2) {
            n(0, 1) = n(1, 0) = shear[0][i];
        } else {
            n(1, 2) = n(2, 1) = shear[0][i];
            n(0, 2) = n(2, 0) = shear[1][i];
            n(0, 1) = n(1, 0) = shear[2][i];
        }
    }
    return n;
}

// Cauchy stress sigma = s - (P + Q) I of node i (spec section 4; Q the nodal viscosity of Eq. 36):
// the in-plane (or full 3D) part.
template <class G>
inline Mat<G::dim> cauchy_stress(const std::array<const double*, 6>& s, const double* pressure,
                                 const double* viscous_pressure, std::size_t i) {
    const double p = pressure[i] + (viscous_pressure ? viscous_pressure[i] : 0.0);
    Mat<G::dim> sigma;
    if constexpr (G::dim == 2) {
        sigma << s[0][i] - p, s[2][i], s[2][i], s[1][i] - p;
    } else {
        sigma << s[0][i] - p, s[5][i], s[4][i],  //
            s[5][i], s[1][i] - p, s[3][i],        //
            s[4][i], s[3][i], s[2][i] - p;
    }
    return sigma;
}

// The out-of-plane (hoop) Cauchy stress of a 2D node, sigma_theta = s_tt - (P + Q), used by the
// hoop term of Eq. 23 (spec section 5).
inline double out_of_plane_stress(const std::array<const double*, 6>& s, const double* pressure,
                                  const double* viscous_pressure, std::size_t i) {
    return s[3][i] - pressure[i] - (viscous_pressure ? viscous_pressure[i] : 0.0);
}

// The views of a NodeStore's arrays (valid until the store is resized). The double overloads
// check a's range on every call (weights.hpp, InfluenceDistance).
template <int D>
PairFields<D> pair_fields(const NodeStore& nodes, InfluenceDistance influence_distance);
template <int D>
GradientFields<D> gradient_fields(NodeStore& nodes, InfluenceDistance influence_distance);
template <int D>
ForceFields<D> force_fields(NodeStore& nodes, InfluenceDistance influence_distance);
template <int D>
PairFields<D> pair_fields(const NodeStore& nodes, double influence_distance) {
    return pair_fields<D>(nodes, InfluenceDistance(influence_distance));
}
template <int D>
GradientFields<D> gradient_fields(NodeStore& nodes, double influence_distance) {
    return gradient_fields<D>(nodes, InfluenceDistance(influence_distance));
}
template <int D>
ForceFields<D> force_fields(NodeStore& nodes, double influence_distance) {
    return force_fields<D>(nodes, InfluenceDistance(influence_distance));
}

}  // namespace gpa
