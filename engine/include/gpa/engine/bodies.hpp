#pragma once
// From bodies to nodes (spec section 12): each body of a scene becomes a lattice of nodes at cell
// centres, sized so that the lattice fills the body's length exactly.

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

// The initial volumetric strain that puts the equation of state of `material` at pressure p
// (e = 0): how a body's initial mean stress becomes an initial compression (particles and
// elements alike). Throws InputError naming the body when the EOS does not reach p.
double initial_volumetric_strain(const materials::Material& material, double pressure, const std::string& body);

// Index of the named material in scene.materials; throws InputError naming the body otherwise.
std::size_t material_index(const Scene& scene, const std::string& name, const std::string& body);

}  // namespace gpa
