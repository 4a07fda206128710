#pragma once
// Compressed sparse rows: the neighbour list of every centre node, stored as one index array
// and one offset array (row i is indices[offsets[i] .. offsets[i+1])).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gpa {

using NodeIndex = std::uint32_t;

// v.resize(n), but growing past the capacity reserves 1/8 more instead of doubling: arrays
// rebuilt every step (lists, ghost fields) then stay within 1/8 of what they need.
template <class Vector>
void resize_with_slack(Vector& v, std::size_t n) {
    if (n > v.capacity()) v.reserve(n + n / 8);
    v.resize(n);
}

// The same for an array about to be written whole: growing past the capacity frees the old array
// before the new one is made, so that the two never take memory at once (a copy of the old lists
// beside the new ones was the peak of a search: 3D, 10^6 nodes, 2967 against 2507 bytes per node).
template <class Vector>
void resize_discarding(Vector& v, std::size_t n) {
    if (n > v.capacity()) {
        Vector().swap(v);
        v.reserve(n + n / 8);
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
