#pragma once
// Private to engine/: the grain of the engine's parallel sums over nodes.

#include <cstddef>

namespace gpa {

// Nodes per leaf of every deterministic reduction (tbb::parallel_deterministic_reduce with the
// simple partitioner): fixed, not tuned to the thread count, so that every sum is added up in one
// order on any number of threads and results are bit-identical on 1 and 2 threads. 4096 nodes are
// tens of microseconds of work per leaf, against about one of task overhead.
inline constexpr std::size_t reduce_grain = 4096;

}  // namespace gpa
