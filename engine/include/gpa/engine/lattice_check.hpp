#pragma once
// Lattice cells of fixed-connectivity nodes (spec section 2, "[spec] Lattice cells"): a fixed
// node's lattice neighbours along the axes span cells (4 quadrants in 2D, 8 octants in 3D); a cell
// whose volume ratio (kernels.hpp, lattice_cell_ratio) has fallen to collapsed_cell_ratio or below
// has inverted or collapsed, and the node's lattice stencil no longer describes the material.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpa/engine/geometry.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa {

// A cell crushed to a fifth of its volume: no solid gets there by compression (metals reach about
// 0.6 at 100 GPa), so the stencil has tangled or inverted.
inline constexpr double collapsed_cell_ratio = 0.2;

// Each fixed node's axis neighbours (the nearest fixed lattice neighbour on each side of each
// axis), kept from one call to the next. Nodes only ever switch from fixed to variable, so a kept
// set stays right while its own nodes are still fixed, and is found again when one has switched.
// forget() after the nodes are renumbered or restored.
struct LatticeAxes {
    std::vector<std::int32_t> neighbour;  // 2 D per node: [axis][side], -1 for none
    std::vector<std::uint8_t> known;      // per node
    void forget() { known.clear(); }
};

// For every fixed-connectivity node in [0, real_count): the smallest volume ratio of its lattice
// cells whose edge nodes are all still fixed, or +infinity where it has none. Variable nodes get
// +infinity. Parallel; each node's value depends only on the state, not on the thread count, nor
// on whether `axes` kept its axis neighbours from an earlier call.
void smallest_lattice_cell_ratios(const NodeStore& nodes, std::size_t real_count, std::vector<double>& out,
                                  LatticeAxes* axes = nullptr);

}  // namespace gpa
