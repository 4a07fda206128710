#pragma once
// How a body's final length and footprint are measured, for particle bodies and element bodies
// alike (docs/measurement.md states the rules; this header is their one implementation, used by
// the run totals, the summary, the profile and the study).
//
// Both are taken against the first rigid plane of a scene: "height" is a point's distance from
// the plane on the bodies' side of it, "across" its coordinate along the plane's first other
// axis (the radius x in an axisymmetric scene with the plane normal to z).
//
//   particles: a node is the centre of a cell of diameter d, so the body reaches d/2 beyond it:
//     top       = height + d/2
//     on face   = height < d            (the first row stands d/2 above the plane)
//     span      = [across - d/2, across + d/2]
//   elements:  nodes lie on the body's boundary, so the body ends at them:
//     top       = height
//     on face   = height <= face tolerance (nodes in contact lie on the plane to round-off)
//     span      = [across, across]
//
// In an axisymmetric body the footprint is a diameter: a span [lo, hi] of radii counts as
// [-hi, hi] (the body is symmetric about the axis).

#include <algorithm>
#include <limits>

namespace gpa::measure {

// The running extent of one or more bodies above a plane.
struct Extent {
    double top = -std::numeric_limits<double>::infinity();
    double face_lo = std::numeric_limits<double>::infinity();
    double face_hi = -std::numeric_limits<double>::infinity();

    Extent& operator+=(const Extent& o) {
        top = std::max(top, o.top);
        face_lo = std::min(face_lo, o.face_lo);
        face_hi = std::max(face_hi, o.face_hi);
        return *this;
    }
    // Final length: the highest point above the plane (0 when nothing was seen).
    double length() const { return top > -std::numeric_limits<double>::infinity() ? top : 0.0; }
    // Footprint diameter: the width of the points on the plane (0 when none is on it).
    double footprint() const { return face_hi > face_lo ? face_hi - face_lo : 0.0; }
};

// A particle node of diameter d at `height` above the plane and `across` along it.
inline void add_particle(Extent& e, double height, double across, double diameter, bool axisymmetric) {
    const double half = 0.5 * diameter;
    e.top = std::max(e.top, height + half);
    if (height < diameter) {
        e.face_hi = std::max(e.face_hi, across + half);
        e.face_lo = std::min(e.face_lo, axisymmetric ? -(across + half) : across - half);
    }
}

// An element node (on the body's boundary or inside it) at `height` above the plane.
inline void add_element_node(Extent& e, double height, double across, double face_tolerance, bool axisymmetric) {
    e.top = std::max(e.top, height);
    if (height <= face_tolerance) {
        e.face_hi = std::max(e.face_hi, across);
        e.face_lo = std::min(e.face_lo, axisymmetric ? -across : across);
    }
}

// The tolerance of "on the plane" for element nodes of a body meshed at spacing h: contact puts
// nodes on the plane to round-off (~1e-16 h); a node leaving it moves dt |v|, some 1e-4 h or more
// per step at the speeds where lift-off matters.
inline double element_face_tolerance(double spacing) { return 1e-6 * spacing; }

// The outer radius a particle of diameter d at `across` contributes to a profile, and an element
// node's: the same offsets as the spans above.
inline double particle_outline_radius(double across, double diameter) { return across + 0.5 * diameter; }
inline double element_outline_radius(double across) { return across; }

}  // namespace gpa::measure
