#pragma once
// What a run holds in memory, array by array (Simulation::memory_use): the node fields, the
// neighbour lists and their caches, the ghosts and the scratch of each part of the step. Bytes are
// those allocated (a vector's capacity), so the table adds up to what the arrays really take.

#include <cstddef>
#include <string>
#include <vector>

namespace gpa {

struct ArrayMemory {
    std::string array;  // "part: array", e.g. "nodes: position", "neighbour lists: candidates"
    std::size_t bytes = 0;
};

using MemoryUse = std::vector<ArrayMemory>;

// Bytes allocated by a std::vector.
template <class V>
std::size_t allocated_bytes(const V& v) {
    return v.capacity() * sizeof(typename V::value_type);
}

// Adds `bytes` under `array`, to an existing row of that name if there is one (fields with
// several components report as one array).
inline void add_memory(MemoryUse& out, const std::string& array, std::size_t bytes) {
    for (auto& row : out) {
        if (row.array == array) {
            row.bytes += bytes;
            return;
        }
    }
    out.push_back({array, bytes});
}

}  // namespace gpa
