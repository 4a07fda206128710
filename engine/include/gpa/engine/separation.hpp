#pragma once
// Pairs that can open: bodies that touch without welding, and cracks through failed nodes
// (spec section 2, "[spec] Separable pairs"; docs/contact.md).
//
// A pair (i, j) is separable when its nodes belong to different bodies, or (with
// failed_pairs_separate) when either node has failed. A separable pair is open, and acts in no
// phase of the step (strain rates, forces, smoothing), when
//   (v_j - v_i) . (x_j - x_i) >= 0                 the nodes are not approaching, and
//   n . sigma_i . n + n . sigma_j . n >= 0           the normal stresses across it are not compressive,
// with n = (x_j - x_i) / r_ij and sigma = s - (P + Q) I the in-plane Cauchy stresses at the start of
// the step. Otherwise it is closed and is an ordinary variable-connectivity pair. The rule is decided
// once per step, before the velocity gradient, from quantities symmetric in i and j (the test gives
// the same answer bit for bit from either end), so both rows keep or drop the pair together: the
// forces stay equal and opposite and the gradient and the forces see the same pairs, which keeps the
// spatial discretisation's energy identity (spec section 5) exact. Opening a pair therefore does no
// work of its own: there is no energy to book.

#include <array>
#include <cstddef>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa {

struct SeparationCounts {
    std::size_t closed = 0;  // separable pairs that act this step (each pair counted once per row)
    std::size_t open = 0;    // separable pairs removed from the lists
};

// Removes the open separable pairs from the rows [0, real_count) of `lists` (the real centres;
// their partners may be ghosts, whose velocity and stress mirror their sources). Rows keep their
// order; the ghost rows are to be appended afterwards (GhostSet::append_ghost_rows mirrors the
// real rows). 2D node stores use the in-plane stress (x, z), 3D the full one.
// closing_speed (optional, one value per real node): the largest speed -(v_j - v_i) . n at which a
// closed separable pair of the node is closing, 0 if none. Across an interface the velocity jumps
// by up to the impact speed within one spacing, a discontinuity that the viscosity has not yet seen
// (Q = 0 before the first compression), so the time step adds it to the signal speed (spec section
// 11, "[spec] Closing interfaces").
// contact_direction (optional, D arrays of one value per real node): for a node with a closed
// partner in another body, the outward direction of its own body there, -sum_j (1 - r_ij / 2 h_ij) l_ij
// over its kept neighbours j of its own body, h_ij from `influence_distance` (Eq. 2; the weight makes
// a neighbour at the edge of the support count for nothing, so that round-off in which of those are
// listed does not tilt it); 0 for other nodes. A contact pair's sliding direction is formed from the
// two ends' (PairFields::sliding_normal).
SeparationCounts remove_open_pairs(CompressedRows& lists, const NodeStore& nodes, std::size_t real_count,
                                   bool failed_pairs_separate, double* closing_speed = nullptr,
                                   const std::array<double*, 3>& contact_direction = {}, double influence_distance = 1.0);

// The test of one pair, for tests and diagnostics: true if (i, j) is separable and open.
bool pair_is_open(const NodeStore& nodes, std::size_t i, std::size_t j, bool failed_pairs_separate);

}  // namespace gpa
