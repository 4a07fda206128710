#pragma once
// From bodies to nodes (spec section 12): each body of a scene becomes a lattice of nodes at cell
// centres, sized so that the lattice fills the body's length exactly.

#include <array>
#include <cstddef>
#include <vector>

#include "gpa/engine/lattice.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

// Appends the nodes of scene.bodies[body] (body id = its index, material id = the index of its
// material in scene.materials) with velocity, initial stress and connectivity set; fixed lists
// continue across `mirrors`. Returns the index of its first node.
std::size_t add_body_nodes(NodeStore& nodes, const Scene& scene, std::size_t body,
                           const std::vector<MirrorPlane>& mirrors);

// The lattice a body is filled with (exposed for tests and reports).
LatticeBlock body_lattice(const Scene& scene, std::size_t body);

// A node of a body filled with rings (CellFill::Rings): its place in the body's own axes (the
// cylinder's base centre at 0, its axis along z, before the body's rotation and origin) and its
// volume.
struct RingNode {
    std::array<double, 3> position{};
    double volume = 0.0;
};

// The rings that fill cylinder or plate b (CellFill::Rings): layers of height hz = length / nz,
// nz = round(length / spacing); in each layer M = round(R_k / spacing) rings of width w = R_k / M
// at radii (m + 1/2) w, with a multiple of 4 of nodes n_m near 2 pi r_m / spacing at the angles
// (q + 1/2) 2 pi / n_m, each node the n_m-th part of its annulus. R_k is the radius of the
// cylinder of the layer's volume (a nose's layers from its profile, integrated, at the height of
// their centroid), so the nodes hold the shape's volume; a layer less than half a spacing in radius
// (a cone's tip) joins its larger neighbour. The rings are mirror images of themselves across the
// planes x = 0 and y = 0, and no node lies on the axis or on those planes, as a 2D axisymmetric
// lattice has no node on its axis.
std::vector<RingNode> ring_fill(const BodySpec& b);

// The initial volumetric strain that puts the equation of state of `material` at pressure p
// (e = 0): how a body's initial mean stress becomes an initial compression (particles and
// elements alike). Throws InputError naming the body when the EOS does not reach p.
double initial_volumetric_strain(const materials::Material& material, double pressure, const std::string& body);

// Index of the named material in scene.materials; throws InputError naming the body otherwise.
std::size_t material_index(const Scene& scene, const std::string& name, const std::string& body);

}  // namespace gpa
