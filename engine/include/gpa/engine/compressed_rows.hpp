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

struct CompressedRows {
    std::vector<std::size_t> offsets{0};
    std::vector<NodeIndex> indices;

    std::size_t rows() const { return offsets.size() - 1; }
    std::size_t entries() const { return indices.size(); }
    std::span<const NodeIndex> row(std::size_t i) const {
        return {indices.data() + offsets[i], offsets[i + 1] - offsets[i]};
    }
    std::size_t row_size(std::size_t i) const { return offsets[i + 1] - offsets[i]; }
    void clear() {
        offsets.assign(1, 0);
        indices.clear();
    }
    bool operator==(const CompressedRows&) const = default;
};

// Builds rows from a list of per-row vectors (a convenience for set-up code and tests).
CompressedRows make_compressed_rows(const std::vector<std::vector<NodeIndex>>& rows);

}  // namespace gpa
