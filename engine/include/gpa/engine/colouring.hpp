#pragma once
// Plans for scattering pairwise forces without atomics. Centres are put in groups, groups in
// colours: two groups of one colour never write the same node, so the groups of a colour run
// in parallel, the colours one after another, and each group walks its centres in a fixed
// order. Every node therefore receives its contributions in an order that depends on the plan
// only, never on the thread count.

#include <array>
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"

namespace gpa {

enum class ScatterScheme {
    Slabs,   // slabs along the longest axis, at least twice the largest pair reach wide, 2 colours
    Cells,   // cells at least the largest pair reach wide, 3^dim colours
    Graph,   // greedy distance-2 colouring of the neighbour graph (stays valid while lists do)
    Serial,  // one colour, one group: the serial twin
};

std::string_view name_of(ScatterScheme s);

struct ScatterPlan {
    ScatterScheme scheme = ScatterScheme::Serial;
    std::vector<std::size_t> colour_offsets{0};  // colour c: groups [colour_offsets[c], colour_offsets[c+1])
    std::vector<std::size_t> group_offsets{0};   // group g: centres[group_offsets[g] .. group_offsets[g+1])
    std::vector<NodeIndex> centres;

    std::size_t colours() const { return colour_offsets.size() - 1; }
    std::size_t groups() const { return group_offsets.size() - 1; }
    std::span<const NodeIndex> group(std::size_t g) const {
        return {centres.data() + group_offsets[g], group_offsets[g + 1] - group_offsets[g]};
    }
};

// Positions as one pointer per component (dim of them are read).
struct PositionView {
    int dim = 2;
    std::array<const double*, 3> component{};
};

// All plans cover the centres [0, lists.rows()).
ScatterPlan make_serial_plan(const CompressedRows& lists);
ScatterPlan make_slab_plan(const CompressedRows& lists, const PositionView& x);
ScatterPlan make_cell_plan(const CompressedRows& lists, const PositionView& x);
// group_size: how many centres of one colour a task takes; any size gives the same result
// (centres of one colour never share a written node); 0 picks one that gives each colour about
// 16 groups.
ScatterPlan make_graph_plan(const CompressedRows& lists, std::size_t node_count,
                            std::size_t group_size = 0);
ScatterPlan make_plan(ScatterScheme scheme, const CompressedRows& lists, const PositionView& x,
                      std::size_t node_count);

// For tests: true when no two groups of one colour write the same node (a centre writes itself
// and its neighbours), and every centre appears exactly once.
bool plan_is_conflict_free(const ScatterPlan& plan, const CompressedRows& lists,
                           std::size_t node_count);

}  // namespace gpa
