#pragma once
// Test set-ups shared by the engine tests: regular and jittered lattices, random node states.

#include <cstddef>
#include <cstdint>
#include <random>

#include "gpa/engine/lattice.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa::testing {

struct LatticeOptions {
    GeometryKind geometry = GeometryKind::PlaneStrain;
    int cells = 12;              // per axis
    double spacing = 1.0;
    double x_origin = 0.0;       // lower corner along x (axisymmetric: 0 puts the first column at dx/2)
    Connectivity connectivity = Connectivity::Variable;
    int lattice_neighbours = 0;  // 0: 8 in 2D, 26 in 3D
    double density = 1.0;
    double stencil_reach = 0.0;  // LatticeBlock::stencil_reach (d0 = spacing here); last, so that the
                                 // aggregate initialisers of the tests keep their meaning
};

NodeStore make_lattice(const LatticeOptions& o);

// The paper's lattice of spec section 7: plane strain, `cells` x `cells` unit cells (nodes at 0.5,
// 1.5, ...), variable connectivity.
inline LatticeOptions unit_cells(int cells) {
    LatticeOptions o;
    o.cells = cells;
    o.spacing = 1.0;
    return o;
}

// Moves every node by a uniform random offset in [-amplitude, amplitude] * spacing per axis and
// updates the axisymmetric size weights. Diameters keep their lattice value.
void jitter(NodeStore& nodes, double amplitude, double spacing, std::uint64_t seed);

// Scales every diameter by a random factor in [1 - spread, 1 + spread].
void vary_diameters(NodeStore& nodes, double spread, std::uint64_t seed);

// Random stresses (every component), pressures, nodal viscous pressures, velocities and sound
// speeds in ranges that make every term matter.
void randomise_state(NodeStore& nodes, std::uint64_t seed);

// A uniform uniaxial stress sigma_z along the second axis of a plane-strain store, every node
// alike: s = (-1/3, 2/3, 0, -1/3) sigma_z and P = -sigma_z / 3 (the spec's lattice example, section 7).
void set_uniaxial_stress_z(NodeStore& nodes, double sigma_z);

// The index of the node at exactly (x, z) of a 2D store; std::out_of_range when there is none.
std::size_t node_at(const NodeStore& nodes, double x, double z);

// Distance from node i to the nearest edge of the lattice box (and to the axis in
// axisymmetric geometry), for selecting complete neighbourhoods.
double distance_to_boundary(const NodeStore& nodes, const LatticeOptions& o, std::size_t i);

}  // namespace gpa::testing
