#pragma once
// Private to engine/: how many nodes a task of the engine's parallel loops over nodes takes (sums, and
// the loops whose result does not depend on where they are cut).

#include <cstddef>

namespace gpa {

// Nodes per leaf of every deterministic reduction (tbb::parallel_deterministic_reduce with the
// simple partitioner): fixed, not tuned to the thread count, so that every sum is added up in one
// order on any number of threads and results are bit-identical on 1 and 2 threads. 4096 nodes are
// tens of microseconds of work per leaf, against about one of task overhead.
inline constexpr std::size_t reduce_grain = 4096;

// Nodes per task of a loop over nodes whose result does not depend on how it is split (each node
// writes its own values, or the loop takes a minimum, a maximum or an or) and whose node costs a
// few to tens of nanoseconds (a division, a square root, a diameter rule): small enough that a
// scene of 10^3 nodes, a desktop's daily run, gives both threads work, large enough that a task's
// overhead (about a microsecond) stays small beside its work.
inline constexpr std::size_t costly_node_grain = 256;

// Ghosts per task of the loops that copy or mirror every field of a ghost's source (some twenty
// loads and stores each).
inline constexpr std::size_t ghost_grain = 256;

}  // namespace gpa
