#pragma once
// Compressed sparse rows: the neighbour list of every centre node, stored as one index array
// and one offset array (row i is indices[offsets[i] .. offsets[i+1])).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gpa {

using NodeIndex = std::uint32_t;

// What an array grows by beyond what it needs when it grows past its capacity, as a divisor of
// its new size. Doubling (what resize() itself does) would double the memory of a run.
//   * Arrays per node (the node store with its ghosts, per-node sums, row offsets): 1/64. Their
//     sizes move only with the ghosts, by little, and an eighth of them took 40 bytes of a 2D
//     node at 10^6 nodes (docs/performance.md section 3).
//   * Arrays per list entry (candidates, lists, kept pair terms): 1/8. Their sizes grow with the
//     pairs at every search of a body being compressed, and each growth makes a new array whose
//     pages the system hands out afresh; at 1/64 the 3D variable benchmark faulted in 110 MB more
//     per run and its neighbours phase took 7 % longer, while the unused tail of an array is
//     never touched and costs no resident memory.
inline constexpr std::size_t per_node_slack = 64;
inline constexpr std::size_t per_entry_slack = 8;

// v.resize(n), growing past the capacity by n / slack instead of doubling.
template <class Vector>
void resize_with_slack(Vector& v, std::size_t n, std::size_t slack = per_node_slack) {
    if (n > v.capacity()) v.reserve(n + n / slack);
    v.resize(n);
}

// The same for an array about to be written whole: growing past the capacity frees the old array
// before the new one is made, so that the two never take memory at once (a copy of the old lists
// beside the new ones was the peak of a search: 3D, 10^6 nodes, 2967 against 2507 bytes per node).
template <class Vector>
void resize_discarding(Vector& v, std::size_t n, std::size_t slack = per_node_slack) {
    if (n > v.capacity()) {
        Vector().swap(v);
        v.reserve(n + n / slack);
    }
    v.resize(n);
}

struct CompressedRows {
    std::vector<std::size_t> offsets{0};
    std::vector<NodeIndex> indices;

    std::size_t rows() const { return offsets.size() - 1; }
    std::size_t entries() const { return indices.size(); }
    std::span<const NodeIndex> row(std::size_t i) const {
        return {indices.data() + offsets[i], offsets[i + 1] - offsets[i]};
    }
    std::size_t row_size(std::size_t i) const { return offsets[i + 1] - offsets[i]; }
    // Row i, or an empty row where the rows stop short of i: for rows that are kept only while
    // some row has entries (NodeStore::fixed_neighbours).
    std::span<const NodeIndex> row_or_empty(std::size_t i) const {
        return i < rows() ? row(i) : std::span<const NodeIndex>{};
    }
    void clear() {
        offsets.assign(1, 0);
        indices.clear();
    }
    bool operator==(const CompressedRows&) const = default;
};

// Builds rows from a list of per-row vectors (a convenience for set-up code and tests).
CompressedRows make_compressed_rows(const std::vector<std::vector<NodeIndex>>& rows);

}  // namespace gpa
