#pragma once
// Prescribed-velocity regions (scene.hpp, PrescribedVelocitySpec): which nodes a region holds, and
// the constraint that holds them, for particle nodes and element nodes alike.
//
// Where it sits in the step (simulation.hpp): right after the velocity update and before
// smoothing, so that nothing later in the step changes a held component before the nodes move
// (smoothing leaves held components alone, see smoothing.hpp; ghosts copy their sources' velocities
// in the next geometry phase, so they mirror the prescribed ones; the hourglass control and the
// bond viscosity are forces, part of F below):
//
//   v_int      = v^{n+1/2} + dt_avg F^{n+1} / M                  integrate (every node)
//   v^{n+3/2}  = v_p(t^{n+1} + dt^{n+3/2} / 2)                    held components only
//
// The reaction of a held node is the force that makes the update land on the prescribed velocity,
//
//   R = M (v^{n+3/2} - v_int) / dt_avg = M (v^{n+3/2} - v^{n+1/2}) / dt_avg - F^{n+1},
//
// the node's mass times its prescribed acceleration less the internal force on it (a ring's mass
// and force in axisymmetric geometry, like the plane reactions). Its work over the step is taken
// in the leapfrog's own form: the kinetic energy of the node's half steps changes by
// dt_avg (F + R) . (v^{n+1/2} + v^{n+3/2}) / 2 exactly, of which the F part is the internal force's
// work as at every free node, so the region's share is
//
//   dW = dt_avg R . (v^{n+1/2} + v^{n+3/2}) / 2,
//
// and with it the energy balance of a held node is that of a free one (docs/elements.md books its
// plane constraints the same way). With the compatible energy update (docs/energy.md) the internal
// energy is the work of the forces at the mean velocities of the update, (v^{n+1/2} + v^{n+3/2}) / 2
// for the held components too (set_mean_velocity), so that the F and R parts together are the held
// node's kinetic-energy change and the balance of a pulled elastic bar closes to round-off.
//
// The penetration guard of the move phase still acts on held nodes; validate_scene refuses regions
// that would drive nodes touching a plane along its normal.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

// The line along z a region's radii are measured from: (x, y) of the centre of the body's extent
// across z (its own axis for cylinders, plates and spheres; x = 0 in axisymmetric geometry).
std::array<double, 2> body_axis(const Scene& scene, std::size_t body);

// Whether a node at initial position p lies in the region (bounds inclusive).
bool in_region(const PrescribedVelocitySpec& region, GeometryKind geometry, const std::array<double, 2>& axis,
               const std::array<double, 3>& p);

// The velocity the region prescribes along component c at time t (m/s; 0 where c is free).
double prescribed_velocity(const PrescribedVelocitySpec& region, int c, double t);

// Bit c set: the region prescribes component c.
std::uint8_t held_components(const PrescribedVelocitySpec& region);

// What the constraint did to one region's nodes in one step.
struct RegionStep {
    std::array<double, 3> reaction{0, 0, 0};  // sum of R over the nodes, per component (N; 0 where free)
    double work = 0.0;                        // sum of dW, J
    std::array<double, 3> velocity{0, 0, 0};  // the velocity it imposed, v^{n+3/2} (m/s; 0 where free)
};

// The held nodes of one node set (the particle nodes or the element nodes), grouped by region.
class HeldNodes {
public:
    // region_of[i]: 0 = free, k + 1 = held by region k, for nodes [0, count).
    void index(const std::uint8_t* region_of, std::size_t count, std::size_t regions);
    bool empty() const { return nodes_.entries() == 0; }
    // Row k: the nodes of region k, ascending.
    const CompressedRows& nodes() const { return nodes_; }

    // Remembers v^{n+1/2} of the held nodes (before the update).
    void capture(const std::array<const double*, 3>& velocity, int dim);
    // Sets the held components to the values prescribed at `time` (the time of v^{n+3/2}) and
    // returns, per region, the reaction and the work of the step (formulas above). Serial over
    // the held nodes in a fixed order, so that the sums do not depend on the thread count.
    std::vector<RegionStep> impose(const std::vector<PrescribedVelocitySpec>& regions, int dim, double time, double dt_avg,
                                   const std::array<double*, 3>& velocity, const double* mass) const;

    // After impose: the held components of `mean` set to (v^{n+1/2} + v^{n+3/2}) / 2, the velocity
    // the held nodes' forces work with over the update (the compatible energy update books the
    // internal energy with it; simulation.cpp).
    void set_mean_velocity(const std::vector<PrescribedVelocitySpec>& regions, int dim,
                           const std::array<const double*, 3>& velocity, const std::array<double*, 3>& mean) const;

private:
    CompressedRows nodes_;
    std::vector<double> before_;  // v^{n+1/2} of the held nodes, dim per entry of nodes_
};

}  // namespace gpa
