#pragma once
// Compressed sparse rows: the neighbour list of every centre node, stored as one index array
// and one offset array (row i is indices[offsets[i] .. offsets[i+1])).

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace gpa {

using NodeIndex = std::uint32_t;

// What an array grows by beyond what it needs when it grows past its capacity: 1/64. Arrays
// rebuilt every step (lists, ghost fields, the node store with its ghosts) then stay within 1/64 of
// what they need. Doubling (what resize() itself does) would double the memory of a run; an eighth
// took 90 bytes of a 2D node's 975 at 10^6 nodes (docs/performance.md section 3), and a sixty-fourth
// still grows a 10^6-node store about 16000 ghosts at a time.
inline constexpr std::size_t growth_slack_divisor = 64;

// v.resize(n), growing past the capacity by the slack above instead of doubling.
template <class Vector>
void resize_with_slack(Vector& v, std::size_t n) {
    if (n > v.capacity()) v.reserve(n + n / growth_slack_divisor);
    v.resize(n);
}

// The same for an array about to be written whole: growing past the capacity frees the old array
// before the new one is made, so that the two never take memory at once (a copy of the old lists
// beside the new ones was the peak of a search: 3D, 10^6 nodes, 2967 against 2507 bytes per node).
template <class Vector>
void resize_discarding(Vector& v, std::size_t n) {
    if (n > v.capacity()) {
        Vector().swap(v);
        v.reserve(n + n / growth_slack_divisor);
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
