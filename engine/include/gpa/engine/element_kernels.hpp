#pragma once
// The kernels of the element solver as small pure functions over one triangle or one
// quadrilateral: geometry, velocity gradient, lumped mass, nodal forces, mean dilatation,
// artificial viscosity and the stable length. They see neither threads nor storage; the drivers
// in elements.cpp apply them. docs/elements.md derives every formula; the equation labels (E1,
// E2, ...) below are that page's.
//
// Coordinates are the engine's 2D ones, (x, z): x radial in axisymmetric geometry. A quadrilateral
// has corners c0..c3 counter-clockwise and a centre node c4 where its diagonals cross (the EPIC
// arrangement of Johnson's crossed triangles); its triangle k is (c4, c_k, c_(k+1) mod 4), also
// counter-clockwise.

#include <array>
#include <cmath>

#include <Eigen/Core>

#include "gpa/engine/geometry.hpp"

namespace gpa::element {

using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;

// E1: a linear (constant-strain) triangle. A = ((x1 - x0) x (x2 - x0)) / 2 (positive when
// counter-clockwise), grad N_a = (z_b - z_c, x_c - x_b) / (2 A) for (a, b, c) cyclic; the
// centroid radius xbar = (x0 + x1 + x2) / 3; the volume V = 2 pi xbar A in axisymmetric geometry
// (Pappus: the ring swept by the triangle), A in plane strain (unit thickness).
struct Triangle {
    double area = 0.0;
    std::array<Vec2, 3> gradient;  // grad N_a
    double radius = 0.0;           // xbar
    double volume = 0.0;
};

template <class G>
inline Triangle triangle(const Vec2& p0, const Vec2& p1, const Vec2& p2) {
    Triangle t;
    const double twice = (p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y());
    t.area = 0.5 * twice;
    const double inv = 1.0 / twice;
    t.gradient[0] = Vec2(p1.y() - p2.y(), p2.x() - p1.x()) * inv;
    t.gradient[1] = Vec2(p2.y() - p0.y(), p0.x() - p2.x()) * inv;
    t.gradient[2] = Vec2(p0.y() - p1.y(), p1.x() - p0.x()) * inv;
    t.radius = (p0.x() + p1.x() + p2.x()) / 3.0;
    if constexpr (G::axisymmetric) {
        t.volume = 2.0 * M_PI * t.radius * t.area;
    } else {
        t.volume = t.area;
    }
    return t;
}

// E2: the velocity gradient of a linear velocity field over the triangle, L = sum_a v_a (x) grad N_a,
// exact for any affine field; in axisymmetric geometry the hoop rate u(xbar) / xbar with
// u(xbar) = (u0 + u1 + u2) / 3, the radial velocity of the linear field at the centroid (exact
// there for an affine field, and the rate of the ring's circumference at its centroid).
struct Kinematics {
    Mat2 velocity_gradient = Mat2::Zero();  // L_ab = dv_a / dx_b, (x, z)
    double hoop_rate = 0.0;                 // L_theta_theta; 0 in plane strain
};

template <class G>
inline Kinematics kinematics(const Triangle& t, const std::array<Vec2, 3>& v) {
    Kinematics k;
    for (int a = 0; a < 3; ++a) k.velocity_gradient.noalias() += v[a] * t.gradient[a].transpose();
    if constexpr (G::axisymmetric) k.hoop_rate = (v[0].x() + v[1].x() + v[2].x()) / (3.0 * t.radius);
    return k;
}

// E3: the rate of the triangle's volume over its volume, tr L (+ the hoop rate): dV/dt = V (tr L +
// u(xbar)/xbar) exactly for the linear field (Pappus' V = 2 pi xbar A differentiated).
inline double volumetric_rate(const Kinematics& k) { return k.velocity_gradient.trace() + k.hoop_rate; }

// E4: lumped (row-sum) masses of a triangle of mass M = rho V: node a receives
// int rho N_a dV. Plane strain: M / 3 each. Axisymmetric, with dV = 2 pi x dA and x linear:
// 2 pi rho A (2 x_a + x_b + x_c) / 12 = M (x_a + 3 xbar) / (12 xbar). These masses give the
// momentum and the centre of mass of the interpolated velocity field exactly, and every node,
// those on the axis included, a positive mass (docs/elements.md, "Masses").
template <class G>
inline std::array<double, 3> lumped_masses(const Triangle& t, const std::array<Vec2, 3>& p, double mass) {
    if constexpr (G::axisymmetric) {
        const double f = mass / (12.0 * t.radius);
        return {f * (p[0].x() + 3.0 * t.radius), f * (p[1].x() + 3.0 * t.radius), f * (p[2].x() + 3.0 * t.radius)};
    } else {
        return {mass / 3.0, mass / 3.0, mass / 3.0};
    }
}

// E5: the nodal forces of one triangle. With the deviator s (in-plane s_xx, s_zz, s_xz and the
// out-of-plane s_tt) weighted by w and a pressure P acting on the triangle's volume V,
//   F_a = - w [ s grad N_a + e_x s_tt / (3 xbar) ] + P V [ grad N_a + e_x / (3 xbar) ],
// which is -d/dv_a of the power w s : D - P dV/dt (E2, E3), so that sum_a F_a . v_a is minus that
// power exactly, and sum_a F_a = (sum of the hoop terms) e_x: the axial (plane strain: both)
// components sum to zero, as sum_a grad N_a = 0. The hoop terms (e_x parts) are absent in plane
// strain. Mean dilatation (E7) gives P the quadrilateral's mean pressure; without it, the
// triangle's own P + Q and w = V.
struct Deviator {
    double xx = 0.0, zz = 0.0, xz = 0.0, tt = 0.0;
};

template <class G>
inline std::array<Vec2, 3> triangle_forces(const Triangle& t, const Deviator& s, double weight, double pressure) {
    Mat2 sigma;
    sigma << s.xx, s.xz, s.xz, s.zz;
    std::array<Vec2, 3> f;
    const double pv = pressure * t.volume;
    for (int a = 0; a < 3; ++a) f[a] = -weight * (sigma * t.gradient[a]) + pv * t.gradient[a];
    if constexpr (G::axisymmetric) {
        const double hoop = (-weight * s.tt + pv) / (3.0 * t.radius);
        for (int a = 0; a < 3; ++a) f[a].x() += hoop;
    }
    return f;
}

// E6: the stress power of the triangle in the same terms, w s : D - P dV/dt; minus the work rate of
// the forces of E5 (the energy identity of the spatial discretisation).
inline double stress_power(const Kinematics& k, const Deviator& s, double weight, double pressure, double volume) {
    const Mat2& l = k.velocity_gradient;
    const double s_d = s.xx * l(0, 0) + s.zz * l(1, 1) + s.xz * (l(0, 1) + l(1, 0)) + s.tt * k.hoop_rate;
    return weight * s_d - pressure * volume * volumetric_rate(k);
}

// E7 (mean dilatation, Nagtegaal, Parks and Rice 1974): the volumetric strain rate of the
// quadrilateral's four triangles is replaced by their volume-weighted mean, the rate of the
// quadrilateral's volume, sum_t V_t (tr L_t + hoop_t) / sum_t V_t; each triangle keeps its own
// deviatoric rate. Over a step the engine takes it from the volumes themselves,
// 2 (V^(n+1) - V^n) / (dt (V^(n+1) + V^n)), so that the density rho = M_q / V_q stays exact.
inline double mean_dilatation_rate(double volume_old, double volume_new, double dt) {
    return 2.0 * (volume_new - volume_old) / (dt * (volume_new + volume_old));
}

// E8: the stable length of a quadrilateral of four crossed triangles, the length l with which
// dt = C_cfl l / (c + sqrt(Q / rho)) (spec section 11's rule, element size and sound speed):
// the quadrilateral's area over its longer diagonal, A_q / max(|c2 - c0|, |c3 - c1|), which is
// the spacing over sqrt(2) for a square and shrinks with the quadrilateral's thinnest width; and
// never more than twice the smallest altitude of its triangles, so that a triangle squeezed
// between the centre node and an edge (while the quadrilateral keeps its shape) also shortens the
// step. docs/elements.md, "Time step", gives the stability limit measured with it.
inline double stable_length(const std::array<Vec2, 5>& c, const std::array<Triangle, 4>& t) {
    const double diagonal = std::max((c[2] - c[0]).norm(), (c[3] - c[1]).norm());
    double area = 0.0, altitude = INFINITY;
    for (int k = 0; k < 4; ++k) {
        area += t[k].area;
        const Vec2& a = c[4];
        const Vec2& b = c[k];
        const Vec2& d = c[(k + 1) % 4];
        const double longest = std::max({(b - a).norm(), (d - b).norm(), (a - d).norm()});
        altitude = std::min(altitude, 2.0 * t[k].area / longest);
    }
    return std::min(area / diagonal, 2.0 * altitude);
}

// E9: the artificial viscosity takes the nodal form (Eq. 36), Q = C_L rho c h |eps_v_dot| +
// C_Q rho h^2 eps_v_dot^2 in compression, with the quadrilateral's mean volumetric rate (E7) and
// h = l, the stable length of E8: the width across which the element is compressed (for a
// quadrilateral flattened against a plane, its thickness; sqrt(A) would be many thicknesses
// there). The step then takes the viscosity as the damping it is: with
// zeta = C_L c + C_Q l |eps_v_dot| (Q = rho l |eps_v_dot| zeta, so zeta l is its diffusivity),
//   dt <= l / (zeta + sqrt(zeta^2 + c^2)),
// the bound of a damped oscillator (and of explicit advection-diffusion) that reduces to l / c
// without viscosity. (The nodal rule c + sqrt(Q / rho) of spec section 11 underestimates the
// linear term's damping: with it, runs of the copper Taylor bar went unstable at C_cfl = 0.4.)
inline double viscous_speed(double volumetric_rate, double sound_speed, double length, double c_linear, double c_quadratic) {
    if (!(volumetric_rate < 0.0)) return 0.0;
    return c_linear * sound_speed + c_quadratic * length * (-volumetric_rate);
}

inline double stable_time_step(double length, double sound_speed, double zeta) {
    return length / (zeta + std::sqrt(zeta * zeta + sound_speed * sound_speed));
}

}  // namespace gpa::element
