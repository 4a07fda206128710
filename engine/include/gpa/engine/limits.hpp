#pragma once
// Memory limits of a run: sizes computed from the input (nodes at set-up, neighbour lists as they
// grow during a run) are estimated before they are allocated and refused, with the estimate and
// the limit in one line, when they would not fit.

#include <cstddef>
#include <cstdint>
#include <string>

#include "gpa/engine/scene.hpp"

namespace gpa {

struct MemoryLimit {
    std::uint64_t bytes = 0;  // 0: physical_memory_bytes()
    // How messages name the limit, e.g. "--max-memory 2G"; empty: "the machine's physical memory".
    std::string source;
};

// The memory this process may use: the machine's physical memory, or less where a control
// group (/sys/fs/cgroup/memory.max) sets a lower limit.
std::uint64_t physical_memory_bytes();

// "1.5 GiB", "730 MiB", "12 kiB", "512 B".
std::string format_bytes(double bytes);

// Memory of a run per node, besides its neighbour lists: the node store and the copy a
// snapshot is written from, lattice-row offsets, search scratch, scatter plan, cell grid,
// ghosts (docs/performance.md section 3: 2D about 350 bytes of node store and 320 of the rest;
// 3D 445 and about 200, and since issue 23 the 48 bytes of a 3D node's B).
double bytes_per_node_besides_lists(int dim);
// Memory per candidate pair of the neighbour lists: the candidate index (4 bytes), its keep
// bit (1/8; the word each row starts is in the bytes per node above) and its share of the cut
// lists (4).
constexpr double bytes_per_list_entry = 8.125;
// And per list entry the term a step keeps for its sweeps (R_ij / r_ij^2, 8 bytes, with the 1/8 the
// array grows by beyond what it needs, per_entry_slack; NeighbourLists::keep_pairs). A run whose
// lists fit the memory limit without them, but not with them, goes without them: its forces,
// energy booking and smoothing then make those terms again, slower, to the same numbers.
constexpr double bytes_per_kept_pair = 9.0;
// Candidate pairs per node at the start of a run (skin 0.25, influence distance 1): about 21 in
// 2D and 56 in 3D (docs/performance.md section 3).
double list_entries_per_node(int dim);

// The nodes the scene's bodies will hold (an upper bound: every lattice cell of every body).
double estimated_node_count(const Scene& scene);

// Throws LimitError when the scene's nodes with their lists would need more than the limit:
// "the scene's bodies need about 1.6e+13 nodes, an estimated 15.7 PiB of memory (1.1 kiB per
// node); the memory limit is 23.4 GiB (the machine's physical memory)".
void check_scene_memory(const Scene& scene, const MemoryLimit& limit);

// The limit in bytes (physical memory where limit.bytes is 0) and its description.
std::uint64_t limit_bytes(const MemoryLimit& limit);
std::string describe_limit(const MemoryLimit& limit);

}  // namespace gpa
