#pragma once
// Neighbour lists (spec section 2): fixed connectivity keeps the lattice neighbours of the
// initial configuration; variable connectivity finds, with a cell list, all nodes within the
// radius of influence 2 h_ij. A fixed-connectivity centre also finds the nodes of other bodies
// within 2 h_ij, because bodies interact only through such pairs.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

// Nodes sorted into the cells of a uniform grid (a stable counting sort, so each cell keeps
// ascending node order).
struct CellGrid {
    int dim = 2;
    double cell_size = 0.0;
    std::array<double, 3> origin{0, 0, 0};
    std::array<std::size_t, 3> cells{1, 1, 1};
    std::vector<std::size_t> cell_start;  // cell k holds nodes[cell_start[k] .. cell_start[k+1])
    std::vector<NodeIndex> nodes;

    // Puts nodes [0, count) into cells no smaller than min_cell_size; the edge grows when the
    // grid would have many more cells than nodes.
    void build(const NodeStore& store, std::size_t count, double min_cell_size);
    // The same for the nodes `members` only (in increasing order; none may be empty of a grid).
    void build(const NodeStore& store, const std::vector<NodeIndex>& members, double min_cell_size);
    std::array<std::size_t, 3> cell_of(const NodeStore& store, std::size_t i) const;
    std::size_t linear(const std::array<std::size_t, 3>& c) const {
        return (c[2] * cells[1] + c[1]) * cells[0] + c[0];
    }
};

// True when some centre in [0, centres) needs a search: a variable-connectivity centre, or more
// than one body.
bool needs_search(const NodeStore& nodes, std::size_t centres);

// Reusable state of the search (the cell grids), kept between searches.
struct NeighbourScratch {
    CellGrid grid;           // the bulk of the nodes (DiameterSpread)
    CellGrid outsized_grid;  // the outsized nodes, in cells of their own size
    std::vector<NodeIndex> bulk, outsized;
    // Per cell of `grid`: the body whose fixed nodes are all the cell holds, kEmptyCell, or
    // kMixedCell (a variable node, or nodes of two bodies).
    std::vector<std::int32_t> cell_body;
    static constexpr std::int32_t kEmptyCell = -1, kMixedCell = -2;
    // Per centre, after a search with fixed_may_switch: 1 when the centre is fixed, its lattice
    // neighbours and mirrors are all fixed, and every bulk cell within its reach held only fixed
    // nodes of its body (a quiet centre). Its row then holds its lattice neighbours and mirrors
    // (and any outsized node within reach), not the other fixed nodes of its body that would
    // become pairs only if one of the two switched: the lists are valid until a node within
    // reach of a quiet centre, or one of its lattice neighbours, switches (NeighbourLists then
    // searches the switched node's row and the quiet centre's). Without fixed_may_switch a quiet
    // centre's scan would find no pair, and is skipped too (the lists are the same).
    std::vector<std::uint8_t> quiet;
    // Called with the number of entries the lists hold so far, after each wave of rows is made
    // and before it is placed, the last time with them all; may throw (a memory limit,
    // Simulation). A full search calls it first with its guess of the entries (from every 32nd
    // row): a LimitError there only withholds room for the guess. Empty: no check.
    std::function<void(std::size_t entries)> check_entries;
    // The rows a block of a search's wave makes, one buffer per block of a wave (find_neighbours).
    std::vector<std::vector<NodeIndex>> block_entries;
};

// The neighbour lists of centres [0, centres), drawn from all nodes [0, nodes.size()):
//   a variable centre: every j != i with r_ij < 2 h_ij;
//   a fixed centre: its lattice neighbours that are fixed, then those of its rows of `extra_fixed`
//   (if given: the ghost images of lattice neighbours across planes), then every variable node of
//   its body and every node of another body with r_ij < 2 h_ij (spec section 2: a lattice pair
//   links two fixed nodes; every other pair is a variable pair).
// Deterministic and independent of the thread count. Validates a (0.8-1.5).
// With skin > 0 (a length) the rows hold candidates instead: every j with r_ij < 2 h_ij + skin
// that the rule could make a pair before the next search. filter_candidates() then cuts them to
// the pairs of the moment; they stay a superset of the pairs until some pair has closed by more
// than the skin (Verlet lists). With fixed_may_switch (automatic bodies), the candidates also
// outlive switching: a fixed centre's row holds all its lattice neighbours and mirrors, of either
// mode, then every other node within reach, fixed nodes of its body included.
void find_neighbours(const NodeStore& nodes, double influence_distance, std::size_t centres,
                     CompressedRows& out, NeighbourScratch& scratch,
                     const CompressedRows* extra_fixed = nullptr, double skin = 0.0, bool fixed_may_switch = false);
// The same with a checked once (weights.hpp, InfluenceDistance): what a run calls. With `only`
// (centres below `centres`, ascending) the rows of those centres alone: row k of `out` is the row
// of centre only[k], entry for entry what a search of every centre gives it.
void find_neighbours(const NodeStore& nodes, InfluenceDistance influence_distance, std::size_t centres,
                     CompressedRows& out, NeighbourScratch& scratch,
                     const CompressedRows* extra_fixed = nullptr, double skin = 0.0, bool fixed_may_switch = false,
                     std::span<const NodeIndex> only = {});
CompressedRows find_neighbours(const NodeStore& nodes, double influence_distance, std::size_t centres);

// The pairs of the moment from candidate lists, in the candidates' order: of row i, the first
// lattice_entries[i] entries (a fixed centre's lattice neighbours and their mirrors, of either
// mode; lattice_entries empty: no row has any) while both nodes are fixed, and every j with
// r_ij < 2 h_ij that is not a pair of two fixed nodes of one body (spec section 2). Nodes may switch between the search and the cut.
// Deterministic and independent of the thread count.
//
// What the caller knows of the lattice pairs, so that a fixed centre's row of lattice entries alone
// (no other entry after them) is kept whole without a look at its entries: without `switching` (no
// automatic body) every lattice pair links two fixed nodes for good, so every such row is kept
// whole; with it, only the rows whose `quiet` flag is set (NeighbourScratch::quiet, one per row, of
// the search that made the candidates), which the caller searches again before a cut whenever a
// node within reach of a quiet centre has switched (NeighbourLists). The lists are the same either
// way; the default takes nothing for granted.
struct LatticeRowsKept {
    bool switching = true;
    const std::uint8_t* quiet = nullptr;
    std::size_t quiet_rows = 0;
};
void filter_candidates(const NodeStore& nodes, double influence_distance, const CompressedRows& candidates,
                       const std::vector<std::uint32_t>& lattice_entries, CompressedRows& out,
                       std::vector<std::uint64_t>& keep, const LatticeRowsKept& kept_rows = {});

// The same lists from an all-pairs loop: the check for find_neighbours. O(n^2).
CompressedRows find_neighbours_brute_force(const NodeStore& nodes, double influence_distance,
                                           std::size_t centres, const CompressedRows* extra_fixed = nullptr);

// A permutation (new_to_old, for NodeStore::permute) of nodes [first, last) that sorts them by
// cell of a grid of the given edge, the longest axis varying slowest (so that slabs across it
// are contiguous index ranges); nodes outside the
// range keep their places.
std::vector<NodeIndex> locality_order(const NodeStore& nodes, double cell_size, std::size_t first,
                                      std::size_t last);

// The largest interaction radius 2 a d_max over nodes [0, count).
double largest_interaction_radius(const NodeStore& nodes, double influence_distance, std::size_t count);

// How the node diameters of [0, count) spread. A node is outsized when its diameter exceeds twice
// the mean: debris of a fractured body whose volume has grown many times over (a hypervelocity
// impact's spall and ejecta reach 30 times the mean), a node far from its initial radius under
// the hoop rule. The search puts them in a grid of their own, and the skin, the ghosts' reach and
// the locality cells follow the bulk, so that a few outsized nodes do not coarsen the cells of
// all the others (the search of a hypervelocity impact otherwise came to cost more than the rest
// of the step together). Deterministic: a serial mean in index order.
struct DiameterSpread {
    double bulk = 0.0;     // the largest diameter that is not outsized
    double largest = 0.0;  // the largest diameter of all
    double cut = 0.0;      // diameters above this are outsized (twice the mean)
    bool any_outsized() const { return largest > cut; }
};
DiameterSpread diameter_spread(const NodeStore& nodes, std::size_t count);

// The interaction radius 2 a d_bulk of the bulk of nodes [0, count) (DiameterSpread): what sizes
// the search cells, the skin and the locality order.
double bulk_interaction_radius(const NodeStore& nodes, double influence_distance, std::size_t count);

}  // namespace gpa
