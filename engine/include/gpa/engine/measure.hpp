#pragma once
// How a body's final length, footprint and local peaks are measured, for particle bodies and
// element bodies alike (docs/measurement.md states the rules; this header is their one
// implementation, used by the run totals, the summary, the profile and the study).
//
// Length and footprint are taken against the first rigid plane of a scene: "height" is a point's
// distance from the plane on the bodies' side of it, "across" its coordinate along the plane's
// first other axis (the radius x in an axisymmetric scene with the plane normal to z). The plane
// gives the direction; the body itself gives the base it is measured from:
//
//   particles: a node is the centre of a cell of diameter d, so the body reaches d/2 beyond it:
//     top       = height + d/2
//     lowest    = height - d/2
//     on face   = height - base < d     (the first row stands d/2 above the base)
//     span      = [across - d/2, across + d/2]
//   elements:  nodes lie on the body's boundary, so the body ends at them:
//     top       = height
//     lowest    = height
//     on face   = height - base <= face tolerance (nodes in contact lie on the plane to round-off;
//                 half a spacing from the underside of a body off the plane: element_face_tolerance)
//     span      = [across, across]
//
// The base is the plane while the body stands on it (some point meets the face rule with base 0),
// otherwise the body's lowest point: a body that has lifted off is measured from its own underside,
// so its length does not include the gap and its footprint is that of its base. Length = top - base.
//
// In an axisymmetric body the footprint is a diameter: a span [lo, hi] of radii counts as
// [-hi, hi] (the body is symmetric about the axis).
//
// In 3D the footprint is a width in the plane, and the width of a face depends on the direction it
// is taken in (a square's is sqrt(2) times wider across its diagonal; a Taylor bar's face spreads
// in spokes along the lattice's rows). Its spans are kept along `footprint_directions` directions
// u_k = cos(theta_k) e1 + sin(theta_k) e2, theta_k = k pi / K, k = 0 .. K - 1, in the plane's other
// two axes (e1 before e2): a particle's span along u_k is [u_k . p - d/2, u_k . p + d/2] (its cell
// reaches d/2 every way); element bodies are 2D only. A half or quarter model (a body that symmetry
// planes normal to the plane's other axes cut or bound) is measured as the whole body: each node
// counts with its images across those planes (Measures, step/measures.cpp), in 2D and 3D, and so do
// the points of the local peaks below. The footprint is the mean of the
// K widths (the mean width of a convex outline; pi D for its perimeter); footprint_narrowest and
// footprint_widest give their spread.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

namespace gpa::measure {

// The running extent of one or more bodies above a plane.
//
// Heights passed to add_particle and add_element_node are taken from a base: the plane (base 0)
// in a first pass; when that pass finds no point on the plane (standing() is false) the caller
// repeats it with heights less lowest() (the body's underside), as measure_extent does.
inline constexpr int footprint_directions = 36;  // K: every 5 degrees

struct Extent {
    double top = -std::numeric_limits<double>::infinity();
    double lowest = std::numeric_limits<double>::infinity();
    double face_lo = std::numeric_limits<double>::infinity();
    double face_hi = -std::numeric_limits<double>::infinity();
    // 3D only (`planar` set by add_particle_3d): the face's span along each u_k. Filled when the
    // first 3D point arrives, so that a 2D extent (reduced over many ranges every step) carries
    // zeros it never reads.
    bool planar = false;
    std::array<double, footprint_directions> direction_lo{};
    std::array<double, footprint_directions> direction_hi{};

    void make_planar() {
        if (planar) return;
        planar = true;
        direction_lo.fill(std::numeric_limits<double>::infinity());
        direction_hi.fill(-std::numeric_limits<double>::infinity());
    }
    Extent& operator+=(const Extent& o) {
        top = std::max(top, o.top);
        lowest = std::min(lowest, o.lowest);
        face_lo = std::min(face_lo, o.face_lo);
        face_hi = std::max(face_hi, o.face_hi);
        if (o.planar) {
            make_planar();
            for (int k = 0; k < footprint_directions; ++k) {
                direction_lo[k] = std::min(direction_lo[k], o.direction_lo[k]);
                direction_hi[k] = std::max(direction_hi[k], o.direction_hi[k]);
            }
        }
        return *this;
    }
    bool seen() const { return top > -std::numeric_limits<double>::infinity(); }
    // Some point met the face rule: the body stands on its base.
    bool standing() const { return face_hi >= face_lo; }
    // Final length: the highest point above the base (0 when nothing was seen).
    double length() const { return seen() ? top : 0.0; }
    // The face's width along u_k (3D) or across (2D); 0 when no point is on the base.
    double width(int k) const {
        if (!planar) return face_hi > face_lo ? face_hi - face_lo : 0.0;
        return direction_hi[k] > direction_lo[k] ? direction_hi[k] - direction_lo[k] : 0.0;
    }
    // Footprint diameter: the width of the points on the base; in 3D the mean over the directions.
    double footprint() const {
        if (!planar) return width(0);
        double sum = 0.0;
        for (int k = 0; k < footprint_directions; ++k) sum += width(k);
        return sum / footprint_directions;
    }
    double footprint_narrowest() const {
        double w = width(0);
        for (int k = 1; planar && k < footprint_directions; ++k) w = std::min(w, width(k));
        return w;
    }
    double footprint_widest() const {
        double w = width(0);
        for (int k = 1; planar && k < footprint_directions; ++k) w = std::max(w, width(k));
        return w;
    }
};

// (cos theta_k, sin theta_k) of the footprint's directions.
inline const std::array<std::array<double, 2>, footprint_directions>& footprint_direction_table() {
    static const auto table = [] {
        std::array<std::array<double, 2>, footprint_directions> t{};
        for (int k = 0; k < footprint_directions; ++k) {
            const double theta = k * std::numbers::pi / footprint_directions;
            t[static_cast<std::size_t>(k)] = {std::cos(theta), std::sin(theta)};
        }
        return t;
    }();
    return table;
}

// The size of a particle node's cell, which the measurement rules take as its d: the square root
// of its section A (its size weight W, Eq. 4) in 2D, the cube root of its volume in 3D. With Eq. 3
// this is the node's diameter itself; it stays the cell's size when the support diameter of Eq. 2
// follows another rule (SolverOptions::node_diameter).
inline double particle_cell_size(double size_weight, int dim) { return dim == 3 ? std::cbrt(size_weight) : std::sqrt(size_weight); }

// A particle node whose cell is d wide at `height` above the base and `across` along it.
inline void add_particle(Extent& e, double height, double across, double diameter, bool axisymmetric) {
    const double half = 0.5 * diameter;
    e.top = std::max(e.top, height + half);
    e.lowest = std::min(e.lowest, height - half);
    if (height < diameter) {
        e.face_hi = std::max(e.face_hi, across + half);
        e.face_lo = std::min(e.face_lo, axisymmetric ? -(across + half) : across - half);
    }
}

// A 3D particle node at `height` above the base, at (a, b) along the plane's other two axes.
inline void add_particle_3d(Extent& e, double height, double a, double b, double diameter) {
    const double half = 0.5 * diameter;
    e.make_planar();
    e.top = std::max(e.top, height + half);
    e.lowest = std::min(e.lowest, height - half);
    if (height < diameter) {
        e.face_hi = std::max(e.face_hi, a + half);
        e.face_lo = std::min(e.face_lo, a - half);
        const auto& u = footprint_direction_table();
        for (int k = 0; k < footprint_directions; ++k) {
            const double along = u[static_cast<std::size_t>(k)][0] * a + u[static_cast<std::size_t>(k)][1] * b;
            e.direction_lo[k] = std::min(e.direction_lo[k], along - half);
            e.direction_hi[k] = std::max(e.direction_hi[k], along + half);
        }
    }
}

// An element node (on the body's boundary or inside it) at `height` above the base.
inline void add_element_node(Extent& e, double height, double across, double face_tolerance, bool axisymmetric) {
    e.top = std::max(e.top, height);
    e.lowest = std::min(e.lowest, height);
    if (height <= face_tolerance) {
        e.face_hi = std::max(e.face_hi, across);
        e.face_lo = std::min(e.face_lo, axisymmetric ? -across : across);
    }
}

// The two passes: `pass(base)` returns the extent of every point with heights measured from
// `base`. The first pass measures from the plane; a body that does not stand on it (it has lifted
// off, or has not arrived) is measured again from its lowest point. Returns the extent and, in
// `base`, the height of the base above the plane (0 while the body stands on the plane).
template <class Pass>
Extent measure_extent(Pass&& pass, double* base = nullptr) {
    Extent e = pass(0.0);
    double b = 0.0;
    if (e.seen() && !e.standing()) {
        b = e.lowest;
        e = pass(b);
    }
    if (base) *base = b;
    return e;
}

// The tolerance of "on the face" for element nodes of a body meshed at spacing h, with heights
// measured from `base` (measure_extent). From the plane (base 0): contact puts nodes on it to
// round-off (~1e-16 h), and a node leaving it moves dt |v|, some 1e-4 h or more per step at the
// speeds where lift-off matters, so 1e-6 h. From the underside of a body off the plane (base not
// 0): an underside is not flat to round-off (a face that has lifted off springs back dished, its
// middle lowest), so half a spacing, the reach of the particle rule (a node is on the face when
// its centre lies within half a cell of the lowest centre). docs/measurement.md has the figures.
inline double element_face_tolerance(double spacing, double base = 0.0) { return base == 0.0 ? 1e-6 * spacing : 0.5 * spacing; }

// The outer radius a particle of diameter d at `across` contributes to a profile, and an element
// node's: the same offsets as the spans above.
inline double particle_outline_radius(double across, double diameter) { return across + 0.5 * diameter; }
inline double element_outline_radius(double across) { return across; }

// --- local peaks ---------------------------------------------------------------------------
//
// A local field (equivalent plastic strain, temperature) is measured at its material points: a
// particle node, or an element's triangle (its centroid). The peak of a field is taken over a
// stated neighbourhood, the same for particles and elements, so that it does not depend on how
// finely the material is sampled:
//
//   mean(p) = sum_q w_q f_q / sum_q w_q   over the points q of p's body with |x_q - x_p| <= radius,
//   peak    = max over the points p of mean(p), and where it is (the point p);
//
// w_q is the point's share of the body's section: a node's size weight W (A_j in 2D, Eq. 4; V_j
// in 3D), a triangle's area. The largest value at a single point (the raw maximum) is kept too.
// Ties go to the lowest index, so the answer does not depend on the thread count.
struct FieldPoint {
    std::array<double, 3> position{0, 0, 0};  // m (2D: x, z in the first two)
    double weight = 0.0;                      // section share, m^2 (2D) or m^3 (3D)
    double value = 0.0;
    int body = 0;
};

struct LocalPeak {
    double value = 0.0;                         // largest neighbourhood mean
    std::array<double, 3> position{0, 0, 0};    // the point it is centred on
    double raw = 0.0;                           // largest value at one point
    std::array<double, 3> raw_position{0, 0, 0};
    std::size_t points = 0;                     // points measured (0: no peak; Measures counts a model's own, not their mirror images)
    // Points whose neighbourhood holds no other point of their body (a node flown off as debris):
    // their own value is no neighbourhood mean, so they take no part in `value` (they do in
    // `raw`). When every point is alone, `value` and `position` are NaN: no peak.
    std::size_t alone = 0;
    bool has_peak() const { return points > alone; }
};

// The peak of `points` over neighbourhoods of `radius` (> 0) in `dim` (2 or 3) dimensions.
// Throws std::invalid_argument for a radius that is not positive and finite.
LocalPeak local_peak(std::span<const FieldPoint> points, double radius, int dim);
// The peaks of several fields at the same points, each field a value per point in the order of
// `points` (whose own `value` is not read): one pass over the neighbourhoods serves them all, and
// each peak equals local_peak's for that field. Also throws for a field of another length.
std::vector<LocalPeak> local_peaks(std::span<const FieldPoint> points, std::span<const std::span<const double>> fields,
                                   double radius, int dim);

// Roughness of a field along the impact face, the measure of node-to-node scatter: the face
// points ordered by their coordinate across the plane, the mean over the inner ones of
// |f_k - (f_(k-1) + f_(k+1)) / 2| (a linear trend gives 0; values alternating between a - e and
// a + e from point to point give 2 e).
// `across` and `value` are the face points in any order; fewer than three give 0.
double face_roughness(std::span<const double> across, std::span<const double> value);

}  // namespace gpa::measure
