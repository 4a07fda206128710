#pragma once
// Per-body results: energies and momentum of every particle body, and what an engineer looks for
// after a projectile meets a target (docs/measurement.md, "Projectile and target"):
//
// * pieces: the connected pieces of a body's intact (not failed) nodes under the step's neighbour
//   relation (pairs of the lists between two intact nodes of the body; open pairs, separation.hpp,
//   are not in the lists). The main piece is the heaviest.
// * residual velocity: the centre-of-mass velocity of the main piece, so failed nodes and separated
//   fragments are left out.
// * impact axis: the line through the initial centre of mass of the fastest body (the projectile)
//   along its initial velocity u (in axisymmetric geometry the z axis). Depths are measured along u,
//   radii from the axis.
// * crater of a body at rest at the start (a target): its front face is the highest level, counted
//   against u, that a node's reach (centre +- d/2) had at t = 0. Crater depth = that level minus the
//   highest reach of the main piece's nodes within one node diameter of the axis; if none is left
//   there the target is perforated and the depth is its initial thickness on the axis. Crater
//   diameter = twice the smallest radius reached (rho - d/2) by a main-piece node that still reaches
//   the front level (within d/2). Both use node reaches (d/2), so on a lattice they are within one
//   spacing of the surface they measure whatever the resolution.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa {

struct BodyTotals {
    std::string name;
    std::size_t nodes = 0, failed_nodes = 0;
    double mass = 0.0;                            // kg (per radian in axisymmetric geometry, like every mass)
    double kinetic_energy = 0.0;                  // J, at the integer time (mean of the half steps, spec section 11)
    double internal_energy = 0.0;                 // J
    std::array<double, 3> momentum{0, 0, 0};      // kg m/s, half a step ahead like Totals::momentum
    std::array<double, 3> centre_velocity{0, 0, 0};  // momentum / mass, m/s
    // Measured by Simulation::measure_bodies() (body_report.hpp: the definitions).
    bool measured = false;
    std::size_t pieces = 0;                          // connected pieces of intact nodes
    double main_piece_mass = 0.0;                    // kg
    std::array<double, 3> residual_velocity{0, 0, 0};  // centre-of-mass velocity of the main piece, m/s
    double residual_speed_along_axis = 0.0;          // residual_velocity . u, m/s
    bool target = false;                             // at rest at t = 0 in a scene where another body moves
    double crater_depth = 0.0, crater_diameter = 0.0;  // m (targets only)
    bool perforated = false;
};

// What the crater rule needs from t = 0.
struct ImpactFrame {
    bool defined = false;                 // some body moves at t = 0
    int projectile = -1;                  // the fastest body
    std::array<double, 3> direction{0, 0, 0};  // u
    std::array<double, 3> point{0, 0, 0};      // a point of the axis
    bool axisymmetric = false;
    std::vector<char> target;             // per body: at rest at t = 0
    std::vector<double> front_level;      // per target: max over its nodes of (-u . x + d/2) at t = 0
    std::vector<double> back_level;       // per target: min over its nodes near the axis of (-u . x - d/2)
};

// The frame from the nodes' initial positions and diameters and the bodies' initial velocities
// (bodies numbered as NodeStore::body), so that a resumed run finds the same one.
ImpactFrame impact_frame(const NodeStore& nodes, std::size_t real_count,
                         const std::vector<std::array<double, 3>>& body_velocity, bool axisymmetric);

// Pieces, residual velocities and craters of every body (the *measured* fields of `out`, which holds
// one entry per body), from the real nodes and the rows [0, real_count) of the step's lists.
void measure_bodies(const NodeStore& nodes, std::size_t real_count, const CompressedRows& lists,
                    const ImpactFrame& frame, std::vector<BodyTotals>& out);

}  // namespace gpa
