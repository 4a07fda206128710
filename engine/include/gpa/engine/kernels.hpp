#pragma once
// The pairwise and per-node kernels of the Generalized Particle Algorithm as small pure
// functions. They see neither threads nor storage: the drivers in drivers.hpp apply them over
// the neighbour lists. Equation numbers are those of Johnson, Beissel and Stryk
// (Comput. Mech. 25, 2000), restated in shared/spec/gpa-method.md.

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

#include "gpa/engine/geometry.hpp"

namespace gpa {

template <int D>
using Vec = Eigen::Matrix<double, D, 1>;
template <int D>
using Mat = Eigen::Matrix<double, D, D>;

// What one pair (centre i, neighbour j) contributes to both the gradient and the force
// kernels. Computed by one function so that both use the same numbers.
template <int D>
struct PairGeometry {
    Vec<D> l;      // unit vector from i to j
    double r;      // |x_j - x_i|
    double inv_r;  // 1 / r (once per pair: the kernels multiply by it instead of dividing)
    double h;      // h_ij (Eq. 2)
    double R;      // distance weight R_ij (Eq. 1a, 1b, or 62-65)
    Vec<D> dx;     // x_j - x_i = r l
    // R / r^2: the force and the energy booking use R / r and l together, (R / r) l = (R / r^2) dx,
    // so this one number per pair is all they need besides the positions (the term the gradient
    // sweep keeps for them, fields.hpp).
    double R_over_r2;
};

// Running sums of the gradient gather for one centre node.
template <int D>
struct GradientSums {
    Vec<D> moment = Vec<D>::Zero();        // sum_j R W l_b^2, the inverse of alpha_b (Eq. 14, 15, 51-53)
    Mat<D> moment_matrix = Mat<D>::Zero(); // sum_j R W l l^T: the full moment matrix (spec section 7)
    Mat<D> difference = Mat<D>::Zero();    // sum_j R W (v_a(j) - v_a(i)) l_b / r
    Mat<D> stiffness = Mat<D>::Zero();     // sum_j u u^T, u = R W l / r, for the stable time step
    double smallest_h = INFINITY;
};

// Eq. 7-8, 10-11, 14-15, 42-53: one neighbour's contribution to the geometry factors and to
// the velocity gradient L_ab = alpha_b sum_j R W (v_a(j) - v_a(i)) l_b / r. With the full
// normalisation (spec section 7, Randles and Libersky) the whole moment matrix is summed instead.
template <int D, bool full_normalisation = false>
inline void accumulate_gradient(const PairGeometry<D>& p, double size_weight_j, const Vec<D>& dv,
                                GradientSums<D>& sums) {
    const double rw = p.R * size_weight_j;
    if constexpr (full_normalisation) {
        sums.moment_matrix.noalias() += rw * p.l * p.l.transpose();
    } else {
        sums.moment += rw * p.l.cwiseProduct(p.l);
    }
    const double rw_over_r = rw * p.inv_r;
    sums.difference.noalias() += rw_over_r * dv * p.l.transpose();
    if (p.h < sums.smallest_h) sums.smallest_h = p.h;  // (a NaN h is skipped, as fmin would)
    const Vec<D> u = rw_over_r * p.l;
    sums.stiffness.noalias() += u * u.transpose();
}

// The correction of the paper's section 2.5 at free surfaces and interfaces (spec section 7;
// docs/surfaces.md): a node whose neighbours lie on one side of it along some direction gets a
// geometry factor there about twice the interior one (1.26 / 0.63 at a flat lattice face), and its
// own stress pushes the nodes behind it twice as hard as an interior node's does; the paper halves
// that factor. Along a direction, with p and n the parts of the moment from the neighbours on its
// two sides, the moment gains one_sided_gain(p, n): nothing while the neighbourhood is near even,
// the moment itself (the factor halved) when one side is empty, linear in between, so that no
// node's factor jumps from one step to the next.
//  * per-direction normalisation: along each axis b, S_b = sum_j R W l_b^2 with p (n) over the
//    neighbours with l_b > 0 (< 0). A flat face normal to b gets half its alpha_b (the paper's
//    correction), a corner half along both of its axes.
//  * moment matrix: along the neighbourhood's own normal n, the direction of the first moment
//    sum_j R W l (frame-invariant: it turns with the neighbourhood), M' = M + gain n n^T with p and
//    n the parts of sum_j R W (l.n)^2 over l.n > 0 and < 0. On a face normal to an axis both rules
//    give the paper's halving; at a corner this one corrects along the diagonal only.
// The forces read the same corrected factors as the strain rates, so the energy identity of spec
// section 5 holds, and the pair forces stay equal and opposite (momentum). What it gives up: the
// strain rate of an affine field normal to a face comes out halved there.
//
// How even is "near even": one side at least a third of the other (|p - n| <= (p + n) / 2). With
// no threshold (every uneven neighbourhood corrected in proportion), the interior nodes of an
// impact, whose neighbourhoods the flow makes uneven, were softened too, and the Armco cylinder at
// 20 nodes across took 2.8 times the steps (docs/surfaces.md).
constexpr double one_sided_threshold = 0.5;

template <int D>
struct OneSidedMoments {
    Vec<D> positive = Vec<D>::Zero();  // sum over the neighbours with l_b > 0 of R W l_b^2
    Vec<D> negative = Vec<D>::Zero();  // the same over the others (l_b = 0 adds nothing)
};

// One neighbour's share of the per-axis one-sided moments.
template <int D>
inline void accumulate_one_sided_moments(const PairGeometry<D>& p, double size_weight_j, OneSidedMoments<D>& m) {
    const double rw = p.R * size_weight_j;
    for (int b = 0; b < D; ++b) {
        const double part = rw * p.l[b] * p.l[b];
        if (p.l[b] > 0.0) {
            m.positive[b] += part;
        } else {
            m.negative[b] += part;
        }
    }
}

// What a direction's moment gains from its two one-sided parts p and n (rules above): nothing
// while |p - n| <= t (p + n), and from there linearly up to p + n, the moment doubled, when one
// side is empty: max(0, |p - n| - t (p + n)) / (1 - t), t = one_sided_threshold.
inline double one_sided_gain(double positive, double negative, double threshold) {
    const double excess = std::abs(positive - negative) - threshold * (positive + negative);
    return excess > 0.0 ? excess / (1.0 - threshold) : 0.0;
}

// The per-axis rule above: the corrected moments S_b + gain_b.
template <int D>
inline Vec<D> surface_corrected_moment(const Vec<D>& moment, const OneSidedMoments<D>& sides, double threshold) {
    Vec<D> corrected = moment;
    for (int b = 0; b < D; ++b) corrected[b] += one_sided_gain(sides.positive[b], sides.negative[b], threshold);
    return corrected;
}

// The moment-matrix rule above, given the unit normal n (the direction of the first moment
// sum_j R W l) and the one-sided parts of sum_j R W (l.n)^2 along it.
template <int D>
inline Mat<D> surface_corrected_moment_matrix(const Mat<D>& moment_matrix, const Vec<D>& normal, double positive,
                                              double negative, double threshold) {
    return moment_matrix + one_sided_gain(positive, negative, threshold) * normal * normal.transpose();
}

// The length that sets node i's stable time step (spec section 11, made to see degenerate
// neighbourhoods): a velocity difference to a neighbour changes the node's strain rate by
// N R W l / r (N the normalisation: diag(alpha), or M^-1), so its highest frequency is about
// c sqrt(sum_j |N u_j|^2) = c sqrt(trace(N S N)), S = sum_j u_j u_j^T. This returns c / omega;
// on a regular 2D lattice with a = 1 it is 1.46 times the spacing, and it shrinks where
// neighbours crowd together or alpha grows.
template <int D>
inline double stable_length(const GradientSums<D>& sums, const Mat<D>& normalisation) {
    return 1.0 / std::sqrt((normalisation * sums.stiffness * normalisation).trace());
}

// The velocity gradient L = difference * N: with N = diag(alpha) the paper's per-direction
// normalisation (Eq. 14-15, 51-53: alpha_b = 1 / sum_j R W l_b^2), with N = M^-1 the full one
// (spec section 7), exact for every affine field.
template <int D>
inline Mat<D> velocity_gradient(const GradientSums<D>& sums, const Mat<D>& normalisation) {
    return sums.difference * normalisation;
}

// Eq. 4: the size weight of an axisymmetric node, its section A = V / (2 pi x) (the volume of its
// ring over the ring's length). In plane strain and 3D the size weight is the volume itself.
inline double ring_section(double volume, double radius) { return volume / (2.0 * std::numbers::pi * radius); }

// Eq. 9: the hoop strain rate of an axisymmetric node, D_thetatheta = u / x (radial velocity over
// radius).
inline double hoop_strain_rate(double radial_velocity, double radius) { return radial_velocity / radius; }

// Eq. 14-15, 51-53: the geometry factor alpha_b = 1 / sum_j R W l_b^2 of one direction, from that
// sum (the moment); 0 where the neighbourhood gives no moment in that direction (the caller decides
// whether that is allowed).
inline double geometry_factor(double moment) { return moment > 0.0 ? 1.0 / moment : 0.0; }

// Eq. 12: eps_v_dot = D_xx + D_zz (+ u/x in axisymmetric geometry, Eq. 9) or the trace in 3D.
template <class G>
inline double volumetric_strain_rate(const Mat<G::dim>& L, double radial_velocity, double radius) {
    double rate = L.trace();
    if constexpr (G::axisymmetric) rate += hoop_strain_rate(radial_velocity, radius);
    return rate;
}

// Eq. 21-22, 54-56: the force that centre i's stress exerts on neighbour j,
//   P_a(ij) = - R V_i W_j / r * sum_b alpha_b(i) (sigma_ab(i) - Q_ij delta_ab) l_b
//           = - (R / r^2) V_i W_j * sum_b alpha_b(i) (sigma_ab(i) - Q_ij delta_ab) dx_b,
// given the normalised offset n = N_i dx (alpha o dx, or M_i^-1 dx with the full normalisation
// of spec section 7; dx = r l). sigma is the in-plane Cauchy stress of i including its nodal
// viscosity; Q_ij is the bond viscosity (0 without it). The reaction -P(ij) acts on i (Eq. 23-24).
template <int D>
inline Vec<D> pair_force(const PairGeometry<D>& p, double volume_i, double size_weight_j,
                         const Vec<D>& normalised_dx, const Mat<D>& sigma_i, double bond_q) {
    return (-p.R_over_r2 * volume_i * size_weight_j) * (sigma_i * normalised_dx - bond_q * normalised_dx);
}

// Spec section 5, "[spec] Compatible energy": the work rate of centre i's stress forces at some
// velocities v, sum_j P(ij) . (v_j - v_i), gathered without making a single pair force. With P(ij) of
// Eq. 21-22 (no bond viscosity), P(ij) . dv = -V_i (R W_j / r) dv^T sigma_i N_i l, so the sum is
// -V_i (sigma_i N_i) : B_i with B_i = sum_j (R W_j / r) dv_j l_j^T, the row's sum of velocity
// differences (D x D; GradientSums::difference, the velocity gradient of Eq. 7-11 before its
// normalisation, here at v); the nodal viscosity's part -Q_i I of sigma_i gives Q_i V_i N_i : B_i.
// One pair's share of B_i, (R W_j / r) dv l^T = (R / r^2) W_j dv dx^T (the form of pair_force):
template <int D>
inline void accumulate_velocity_difference(const PairGeometry<D>& p, double size_weight_j, const Vec<D>& dv,
                                           Mat<D>& difference) {
    difference.noalias() += (p.R_over_r2 * size_weight_j) * dv * p.dx.transpose();
}

// Spec section 2, "[spec] Sliding contact": a pair across a contact or a crack (a closed separable
// pair) carries only the part of a velocity difference or a force along one unit direction n (the
// contact normal, PairFields::sliding_normal), so the surfaces slide past each other without
// friction (the failed material of a crack carries no shear either). The same projection in the
// gradient and in the force keeps the energy identity of section 5: (P . n)(dv . n) on both sides.
template <int D>
inline Vec<D> along_pair(const Vec<D>& n, const Vec<D>& v) {
    return n.dot(v) * n;
}

// Eq. 23 (with Eq. 32 read as "+ P_hoop", see spec section 5): the hoop stress of an
// axisymmetric ring pulls it towards the axis, P_x(ii) += - sigma_theta V_i / x_i.
inline double hoop_force(double sigma_theta, double volume, double radius) {
    return -sigma_theta * volume / radius;
}

// The stress-difference form (the paper's Eq. 28; docs/surfaces.md): node i's force is V_i times
// the divergence of the stress at i, estimated with the operator of its strain rates,
//   F_i = V_i sum_j (R W_j / r) (sigma_j - kept sigma_i) N_i l = V_i sum_j (R / r^2) W_j (...) N_i dx,
// one term per neighbour j, kept = 1 - g. g is the one-sidedness of i's neighbourhood
// (one_sidedness): 0 inside a body, where the form is Eq. 28 and a uniform stress gives no force on
// any neighbourhood; 1 at a free surface, where the missing side's zero stress completes it into the
// sum form V_i sum_j (R W_j / r) sigma_j N_i l (a face node of a bar under uniform sigma then
// feels -A sigma, the traction-free face; Eq. 28 alone would give it nothing).
template <int D>
inline Vec<D> stress_difference_term(const PairGeometry<D>& p, double volume_i, double size_weight_j, const Vec<D>& normalised_dx,
                                     const Mat<D>& sigma_j, const Mat<D>& kept_sigma_i) {
    return (p.R_over_r2 * volume_i * size_weight_j) * ((sigma_j - kept_sigma_i) * normalised_dx);
}

// How one-sided a neighbourhood is: along its first moment's direction d (sum_j R W_j l), with p and
// n the parts of sum_j R W_j (l . d)^2 from the neighbours ahead of and behind the node,
// one_sided_gain(p, n, one_sided_threshold) / (p + n): 0 while the sides weigh within a factor of
// three, 1 when one side is empty, linear in between (the surface correction's moment-matrix rule,
// as a fraction of the moment).
template <int D>
struct OneSidedness {
    Vec<D> first_moment = Vec<D>::Zero();
    void add_first(const PairGeometry<D>& p, double size_weight_j) { first_moment += (p.R * size_weight_j) * p.l; }
    double ahead = 0.0, behind = 0.0;
    void add_sides(const PairGeometry<D>& p, double size_weight_j) {
        const double length = first_moment.norm();
        if (!(length > 0.0)) return;
        const double along = p.l.dot(first_moment) / length;
        (along > 0.0 ? ahead : behind) += p.R * size_weight_j * along * along;
    }
    double gain() const {
        const double total = ahead + behind;
        return total > 0.0 ? std::min(1.0, one_sided_gain(ahead, behind, one_sided_threshold) / total) : 1.0;
    }
};

// The terms of the divergence of the stress in cylindrical coordinates that the section's gradient
// does not give (axisymmetric geometry, Eq. 28's analogue of the hoop force): times V_i,
// (sigma_xx - sigma_theta) / x along x and sigma_xz / x along z.
inline std::array<double, 2> cylindrical_divergence_terms(double sigma_xx, double sigma_xz, double sigma_theta, double volume,
                                                          double radius) {
    return {volume * (sigma_xx - sigma_theta) / radius, volume * sigma_xz / radius};
}

// Eq. 38: mu_ij = h_ij (v_i - v_j).(x_i - x_j) / (r^2 + eps0 h_ij^2), as the paper writes it, from
// dx = x_j - x_i and dv = v_j - v_i (whose product is (v_i - v_j).(x_i - x_j)): no square root, so
// that the force pass and the energy booking make it from a kept pair (fields.hpp) and h_ij alone.
template <int D>
inline double bond_compression_rate(double h, const Vec<D>& dx, const Vec<D>& dv, double eps0) {
    return h * dv.dot(dx) / (dx.squaredNorm() + eps0 * h * h);
}

// Eq. 37: Q_ij = C_L rho_i c_i |mu| + C_Q rho_i mu^2 for mu < 0, otherwise 0.
inline double bond_viscosity(double mu, double density_i, double sound_speed_i, double c_linear,
                             double c_quadratic) {
    if (!(mu < 0.0)) return 0.0;
    return density_i * (c_linear * sound_speed_i * (-mu) + c_quadratic * mu * mu);
}

// Eq. 36: Q_i = C_L rho c h |eps_v_dot| + C_Q rho h^2 eps_v_dot^2 for eps_v_dot < 0, else 0.
inline double nodal_viscosity(double volumetric_strain_rate, double density, double sound_speed,
                              double smallest_h, double c_linear, double c_quadratic) {
    if (!(volumetric_strain_rate < 0.0)) return 0.0;
    const double hr = smallest_h * volumetric_strain_rate;
    return density * (c_linear * sound_speed * (-hr) + c_quadratic * hr * hr);
}

// Eq. 36 limited to what its explicit update can carry (spec section 6; docs/energy.md, "[spec] The
// nodal viscosity a step can carry"). About the node's rate the viscosity is a bulk viscosity of
// kinematic size nu = dQ / d|eps_v_dot| / rho = C_L c h + 2 C_Q h^2 |eps_v_dot|, which damps the
// node's stiffest mode (frequency about c / l, l its stable length) at a rate of about nu / l^2.
// The stress phase applies this step's Q over the step dt, so once dt nu / l^2 passes about 2 each
// step overshoots by more than the last and the viscosity pumps the mode instead of damping it
// (measured: two nodes of a 3D impact face 1.3 um apart, l = 30 um against h = 0.44 mm, their
// amplitude doubling every three steps; a debris node 0.88 mm across 2.4 um from a neighbour,
// dt nu / l^2 near 100, giving back 3.8 J of the 4.2 J of viscous work of a 4 km/s impact in one step).
// The paper's step l / (c + sqrt(Q / rho)) does not see this where l << h. The factor below scales
// Q so that dt nu / l^2 <= 1: half the limit, the node's mode damped within the step without being
// reversed. A node whose neighbours resolve h (l >= h: every node of an undisturbed lattice) takes
// the step dt <= C_cfl l / (c + sqrt(Q / rho)), so that dt nu / l^2 <= C_cfl (C_L + 2 sqrt(C_Q) s) /
// (1 + s) with s = sqrt(Q / rho) / c: with the paper's C_L = 0.2, C_Q = 4 at C_cfl 0.4, 0.08 where
// sound sets the step, 0.84 at s = 1, and 1 only once the viscosity's own signal speed passes 1.5 c.
// So Eq. 36 stands on such nodes, and the factor acts on nodes run together and on debris grown
// many times its neighbours' size. dt: the step the stress update advances.
inline double nodal_viscosity_diffusivity(double volumetric_strain_rate, double sound_speed, double smallest_h, double c_linear,
                                          double c_quadratic) {
    return c_linear * sound_speed * smallest_h + 2.0 * c_quadratic * smallest_h * smallest_h * std::abs(volumetric_strain_rate);
}
inline constexpr double nodal_viscosity_step_limit = 1.0;  // the bound on dt nu / l^2 above
inline double carried_viscosity_fraction(double diffusivity, double stable_length, double dt) {
    const double carried = nodal_viscosity_step_limit * stable_length * stable_length;
    return dt * diffusivity > carried ? carried / (dt * diffusivity) : 1.0;
}

// Spec section 11, step 7: a node's stable time step h / (c + sqrt(Q / rho) + w), with h its
// smallest h_ij (its stable length), c its longitudinal sound speed, Q its viscous pressure (the
// larger of the nodal and its largest bond viscosity; negative taken as 0) and w the closing speed
// of a contact it takes part in (0 without one). The step is C_cfl times the smallest over nodes.
inline double stable_time_step(double stable_length, double sound_speed, double viscous_pressure, double density,
                               double closing_speed) {
    return stable_length / (sound_speed + std::sqrt(std::max(viscous_pressure, 0.0) / density) + closing_speed);
}

// Spec section 11, steps 3 and 4, the leapfrog: v^{n+1/2} = v^{n-1/2} + dt_avg F^n / M, one
// component, with dt_avg the mean of the two half steps around t^n ...
inline double leapfrog_velocity(double velocity, double force, double mass, double dt_avg) {
    return velocity + dt_avg * force / mass;
}

// ... and x^{n+1} = x^n + dt^{n+1/2} v^{n+1/2}.
inline double leapfrog_position(double position, double velocity, double dt) { return position + dt * velocity; }

// Eq. 67: the velocity change velocity smoothing makes at a centre, dv_i = C (vbar_i - v_i), one
// component, with vbar_i = sum_j R_ij v_j / sum_j R_ij (Eq. 66) given as its two sums.
inline double smoothing_change(double coefficient, double weighted_velocity, double weight_sum, double velocity) {
    return coefficient * (weighted_velocity / weight_sum - velocity);
}

// Eq. 69-72: neighbour j of a smoothed centre i receives - M_i R_ij dv_i / sum_k R_ik M_k, so that
// momentum is kept; this is the factor M_i / sum_k R_ik M_k that multiplies - R_ij dv_i.
inline double smoothing_share(double mass, double weighted_mass) { return mass / weighted_mass; }

// Eq. 73: the kinetic energy smoothing takes from a node, dE_i = M_i (|v_i|^2 - |v_i + dV_i|^2) / 2,
// from the squared speeds before and after; it becomes the node's internal energy.
inline double smoothing_heat(double mass, double speed_squared_before, double speed_squared_after) {
    return 0.5 * mass * (speed_squared_before - speed_squared_after);
}

// Eq. 13: eps_v(t + dt) = eps_v(t) + eps_v_dot dt (1 + eps_v(t)), integrated in the initial
// configuration; the volume follows as V = V0 (1 + eps_v).
inline double advance_volumetric_strain(double eps_v, double rate, double dt) {
    return eps_v + rate * dt * (1.0 + eps_v);
}

// Zero-energy-mode (hourglass) control of the nodes in the lattice regime (spec section 2,
// "[spec] Hourglass control"; docs/connectivity.md). On a lattice stencil a velocity field that
// alternates from row to row (v_j equal for the neighbours on both sides of i) gives
// sum_j R W (v_j - v_i) l_b / r = 0 in Eq. 7-8: no strain rate, no stress, no restoring force.
// The control measures, for each pair, how far the velocity difference departs from the best
// affine fit around the centre,
//   e_ij = (v_j - v_i) - Lfit_i (x_j - x_i),   Lfit_i = [sum_j w_j dv_j r_j^T] [sum_j w_j r_j r_j^T]^-1,
// with w_j = W_j / r_ij^2, and damps it with equal and opposite pair forces
//   F_j = - kappa_i w_j e_ij / sum_k w_k,   F_i = - sum_j F_j,   kappa_i = C_hg M_i c_i / h_i.
// e_ij = 0 for every affine velocity field, on any neighbourhood (so rigid motion, uniform strain
// and rotation feel nothing), and because Lfit is the weighted least-squares fit,
// sum_j w_j e_ij r_j^T = 0, so the power of the forces is
//   sum_j F_j . (v_j - v_i) = - kappa_i sum_j w_j |e_ij|^2 / sum_k w_k <= 0:
// they only dissipate, and that power is booked as heat of the centre.
template <int D>
struct HourglassFit {
    Mat<D> moment = Mat<D>::Zero();      // sum_j w_j r_j r_j^T
    Mat<D> difference = Mat<D>::Zero();  // sum_j w_j (v_j - v_i) r_j^T
    double weight = 0.0;                 // sum_j w_j
};

// One lattice neighbour's contribution to the fit: r = x_j - x_i, dv = v_j - v_i, w = W_j / r^2.
template <int D>
inline void accumulate_hourglass_fit(const Vec<D>& r, const Vec<D>& dv, double w, HourglassFit<D>& fit) {
    fit.moment.noalias() += w * r * r.transpose();
    fit.difference.noalias() += w * dv * r.transpose();
    fit.weight += w;
}

// The quadratic fit of the damping (SolverOptions::hourglass_fit = quadratic; spec section 2,
// "[spec] Hourglass control"): the velocity around the centre fitted with its second derivatives
// too,
//   dv_j ~ Lfit_i r_j + Cfit_i q(r_j),   q(r) = (r_a r_b / h_i, a <= b),
// (D (D + 1) / 2 terms, divided by h_i so that they have the units of r), by the same weighted
// least squares over the same pairs. e_ij = dv_j - Lfit r_j - Cfit q(r_j) is then zero for every
// velocity field with constant second derivatives over the support: a flow that bends smoothly
// (a Taylor bar's mushrooming head) is left alone where the affine fit damps it, while an
// odd-even or pairing pattern, which no quadratic follows, is not. The normal equations give
// sum_j w_j e_ij r_j^T = 0 and sum_j w_j e_ij q_j^T = 0, so the forces F_j = -kappa w_j e_ij /
// sum_k w_k conserve linear and angular momentum and only dissipate, as for the affine fit.
template <int D>
inline constexpr int curvature_terms = D * (D + 1) / 2;

template <int D>
using CurvatureVec = Eigen::Matrix<double, curvature_terms<D>, 1>;

template <int D>
inline CurvatureVec<D> curvature_basis(const Vec<D>& r, double inverse_h) {
    CurvatureVec<D> q;
    int k = 0;
    for (int a = 0; a < D; ++a) {
        for (int b = a; b < D; ++b) q[k++] = r[a] * r[b] * inverse_h;
    }
    return q;
}

// The fitted velocity difference Lfit r + Cfit q(r) of a pair: the force pass and the energy
// booking's walk (KeptDampingPower) both make it with this, so that both get the same bits.
template <int D>
inline Vec<D> quadratic_fitted_velocity(const Mat<D>& gradient, const Eigen::Matrix<double, D, curvature_terms<D>>& curvature,
                                        const Vec<D>& r, double inverse_h) {
    return gradient * r + curvature * curvature_basis<D>(r, inverse_h);
}

// The quadratic fit's normal equations over the pairs: the moment of phi = (r, q(r)) and
// sum_j w_j dv_j phi_j^T (hourglass.cpp sums them, QuadraticSums).
template <int D>
struct QuadraticHourglassFit {
    static constexpr int terms = D + curvature_terms<D>;
    Eigen::Matrix<double, terms, terms> moment = Eigen::Matrix<double, terms, terms>::Zero();
    Eigen::Matrix<double, D, terms> difference = Eigen::Matrix<double, D, terms>::Zero();
    double weight = 0.0;
    // The affine fit's sums, which are part of these (where the second derivatives are not fixed).
    HourglassFit<D> affine_part() const {
        HourglassFit<D> fit;
        fit.moment = moment.template topLeftCorner<D, D>();
        fit.difference = difference.template leftCols<D>();
        fit.weight = weight;
        return fit;
    }
};

// The weight of a lattice pair in the fit and the force: w = W_j / r^2.
inline double hourglass_pair_weight(double size_weight_j, double r_squared) { return size_weight_j / r_squared; }

// kappa_i = C_hg M_i c_i / h_i: a damping rate c_i / h_i (the inverse of the time sound takes to
// cross the node) times the node's mass.
inline double hourglass_damping(double coefficient, double mass, double sound_speed, double h) {
    return coefficient * mass * sound_speed / h;
}

// e_ij = (v_j - v_i) - Lfit_i r_j: the part of a lattice pair's velocity difference that no
// affine field around the centre explains; for the stiffness form below on fixed centres, with dX
// for r and dx for dv, e_ij = dx_j - Ffit_i dX_j (on relaxed ones, du for dv).
template <int D>
inline Vec<D> hourglass_velocity_error(const Mat<D>& fitted_gradient, const Vec<D>& r, const Vec<D>& dv) {
    return dv - fitted_gradient * r;
}

// Hourglass stiffness of fixed-connectivity centres (spec section 2, "[spec] Hourglass control",
// its stiffness form; docs/tension.md). The damping above only slows the lattice's odd-even mode;
// under tension the pair forces of Eq. 21-22, which scale with 1 / r_ij, pull the nearer of two
// neighbours harder than the farther, a negative stiffness of order sigma / r^2 per unit mass that
// makes the mode grow while the strain rates (Eq. 7-8) still do not see it. The stiffness resists
// the part of the lattice pairs' *displacement* that no affine map of the initial lattice explains:
//   e_ij = (x_j - x_i) - Ffit_i (X_j - X_i),   Ffit_i = [sum_j w_j dx_j dX_j^T] [sum_j w_j dX_j dX_j^T]^-1,
// w_j = 1 / |X_j - X_i|^2 from the initial positions X, with the pair forces
//   F_j = - k_i w_j e_ij / sum_k w_k,   F_i = - sum_j F_j,   k_i = C_hs M_i c_i^2 / d0_i^2.
// They are the gradient of U_i = k_i sum_j w_j |e_ij|^2 / (2 sum_k w_k) (Ffit minimises it, so its
// own change contributes nothing), equal and opposite, and zero for every affine map of the lattice:
// rigid motion, rotation and uniform stretch of any size feel nothing. k_i / M_i = C_hs (c_i / d0_i)^2,
// against the mode's negative stiffness of about 4 sigma / (rho d0^2): C_hs = 0.05 holds it up to a
// tensile stress of about 1 % of rho c^2 (3 GPa in steel). The fit reuses accumulate_hourglass_fit
// with r = dX, dv = dx.
// On flowing (variable) centres (SolverOptions::hourglass_stiffness_relaxation) the reference is
// X_r, which relaxes towards the positions, X_r += (x - X_r)(1 - e^(-dt / tau)) each step, one
// rate for every node (an affine motion then leaves the reference an affine image of the
// positions). There the fit is the damping's, over the same pairs, weights w_j = W_j / r^2 and
// basis (the current offsets r_j, with q(r_j) for the quadratic fit), applied to the displacements
// since the reference, du_j = r_j - (X_r,j - X_r,i), in place of dv_j: e_ij = du_j - Ufit r_j
// (- Cfit q(r_j)), so that one moment serves both and any displacement field that is affine
// (quadratic) in the current positions stores nothing. Flow older than tau is forgotten; a
// pattern that grows faster than 1 / tau meets a spring (the forces are no longer a potential's
// gradient, and their work is booked as the centre's internal energy all the same).
inline double hourglass_stiffness(double coefficient, double mass, double sound_speed, double initial_diameter) {
    return coefficient * mass * sound_speed * sound_speed / (initial_diameter * initial_diameter);
}

// The volume ratio of a lattice cell of a fixed-connectivity node (spec section 2, "[spec] Lattice
// cells"): the cell spanned by the edges from the node to D of its axis neighbours (one per axis),
// its signed area (2D) or volume (3D) now over that on the initial lattice. In axisymmetric
// geometry the cell is a ring, so its area ratio is scaled by x / x0 of the node. The ratio is the
// cell's J = V / V0: near the node's own V / V0 while the lattice deforms smoothly; at or below 0
// the cell has inverted, and no solid is crushed to a small fraction of its volume.
template <int D>
inline double lattice_cell_ratio(const Mat<D>& current_edges, const Mat<D>& initial_edges) {
    return current_edges.determinant() / initial_edges.determinant();
}

// The 3x3 matrix of a symmetric tensor stored in the stress order (xx, yy, zz, yz, xz, xy).
inline Mat<3> symmetric_matrix(const std::array<double, 6>& b) {
    Mat<3> m;
    m << b[0], b[5], b[4], b[5], b[1], b[3], b[4], b[3], b[2];
    return m;
}

// The left Cauchy-Green tensor B = F F^T of a node (3D), carried from step to step for the
// stretch rule of the node diameter below. The deformation gradient obeys dF/dt = L F; over a step
// with the velocity gradient L of the gradient phase, F^{n+1} = (I + dt L) F^n, so
//   B^{n+1} = (I + dt L) B^n (I + dt L)^T,
// first order in dt like the volumetric strain of Eq. 13, and symmetric positive definite for any
// step with det(I + dt L) != 0 (a congruence of B^n). Components in the stress order of geometry.hpp
// (xx, yy, zz, yz, xz, xy).
inline void advance_left_cauchy_green(std::array<double, 6>& b, const Mat<3>& L, double dt) {
    const Mat<3> step = Mat<3>::Identity() + dt * L;
    const Mat<3> m = step * symmetric_matrix(b) * step.transpose();
    b = {m(0, 0), m(1, 1), m(2, 2), 0.5 * (m(1, 2) + m(2, 1)), 0.5 * (m(0, 2) + m(2, 0)), 0.5 * (m(0, 1) + m(1, 0))};
}

// The largest principal stretch of B's volume-preserving part, lambda = sqrt(mu_max / det(B)^(1/3))
// with mu_max B's largest eigenvalue: 1 for a pure change of volume, >= 1 always (the isochoric
// stretches multiply to 1). A face spread radially and around the hoop by l and thinned axially by
// 1 / l^2 has lambda = l.
double largest_isochoric_stretch(const std::array<double, 6>& b);

// Eq. 3 and its plane-strain and 3D analogues (spec section 2):
//   axisymmetric d = d0 sqrt((1 + eps_v) x0 / x), plane strain d = d0 sqrt(1 + eps_v),
//   3D d = d0 (1 + eps_v)^(1/3).
// With `section` false (NodeDiameter::Volume, the [spec] entry of issue 13) the axisymmetric
// diameter leaves out x0 / x and follows the node's volume like the other geometries:
// d = d0 sqrt(1 + eps_v). A ring that spreads radially at an impact face (x / x0 = lambda) is
// stretched radially and around the hoop and thinned axially; Eq. 3 shrinks its d by
// 1 / sqrt(lambda) while its radial neighbours move lambda times further away, so that they leave
// the radius of influence (at lambda = 1.4 a radial neighbour already weighs R = 0.1 instead of 0.5).
// rule: 0 Eq. 3 (section), 1 volume, 2 hoop (max(x / x0, x0 / x) in place of x0 / x), 3 stretch
// (3D: d = d0 (1 + eps_v)^(1/3) lambda, lambda the largest isochoric stretch above, so that the
// neighbours along the most stretched direction keep their initial distance in units of d; in 2D
// the same as hoop).
template <class G>
inline double node_diameter(double d0, double eps_v, double x0, double x, int rule = 0, double stretch = 1.0) {
    if constexpr (G::dim == 3) {
        return rule == 3 ? d0 * std::cbrt(1.0 + eps_v) * stretch : d0 * std::cbrt(1.0 + eps_v);
    } else if constexpr (G::axisymmetric) {
        if (rule == 1) return d0 * std::sqrt(1.0 + eps_v);
        if (rule >= 2) return d0 * std::sqrt((1.0 + eps_v) * std::max(x / x0, x0 / x));
        return d0 * std::sqrt((1.0 + eps_v) * x0 / x);
    } else {
        return d0 * std::sqrt(1.0 + eps_v);
    }
}

}  // namespace gpa
