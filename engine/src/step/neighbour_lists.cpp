#include "step/neighbour_lists.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/errors.hpp"
#include "step/contact.hpp"
#include "reduce_grain.hpp"

namespace gpa {

namespace {


PositionView positions_of(const NodeStore& n) {
    PositionView v;
    v.dim = n.dim();
    for (int c = 0; c < n.dim(); ++c) v.component[c] = n.position[c].data();
    return v;
}

void write_plan(StateWriter& out, const ScatterPlan& plan) {
    out.value<std::int32_t>(static_cast<std::int32_t>(plan.scheme));
    out.array(plan.colour_offsets);
    out.array(plan.group_offsets);
    out.array(plan.centres);
}

void read_plan(StateReader& in, ScatterPlan& plan, std::size_t node_count) {
    plan.scheme = static_cast<ScatterScheme>(in.value<std::int32_t>());
    in.array(plan.colour_offsets);
    in.array(plan.group_offsets);
    in.array(plan.centres);
    const bool fits = !plan.colour_offsets.empty() && !plan.group_offsets.empty() &&
                      plan.colour_offsets.back() <= plan.group_offsets.size() - 1 &&
                      plan.group_offsets.back() <= plan.centres.size();
    if (!fits) in.fail("its scatter plan is damaged");
    for (const NodeIndex c : plan.centres) {
        if (c >= node_count) in.fail("its scatter plan names a node that does not exist");
    }
}

}  // namespace

void NeighbourLists::set_up(bool constant) {
    constant_ = constant;
    with_skin_ = solver_->neighbour_skin > 0.0 && !constant;
}

void NeighbourLists::invalidate() {
    lists_.clear();  // rebuilt in the new numbering by the next update
    search_due_ = true;
    kept_rows_ = 0;
}

void NeighbourLists::forget_kept_arrays() {
    kept_rows_ = 0;
    std::vector<double>().swap(kept_weight_over_r2_);
}

double* NeighbourLists::keep_pairs(std::size_t real) {
    kept_rows_ = 0;
    if (!keep_allowed_) {
        forget_kept_arrays();
        return nullptr;
    }
    const std::size_t entries = lists_.offsets[std::min(real, lists_.rows())];
    if (entries > kept_weight_over_r2_.capacity()) kept_weight_over_r2_.clear();  // grown: no copy of the old terms beside the new array
    resize_with_slack(kept_weight_over_r2_, entries);
    return kept_weight_over_r2_.data();
}

void NeighbourLists::place_ghosts(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool first) {
    const double a = influence_distance.value();
    // Rounding of a ghost's mirrored coordinates against the search's r < 2 h_ij: a margin far
    // below any spacing (a billionth of the bulk's interaction radius at the last search), so
    // that a pair at the edge of its reach never misses its ghost.
    if (with_skin_ && !search_due_) {
        const double rounding = 1e-9 * searched_range_;
        search_due_ = candidates_stale(nodes, real, ghosts, influence_distance, rounding) || switched_near_quiet_rows(nodes, real, ghosts);
    }
    if (ghosts.empty()) return;
    // The skin follows the bulk of the nodes (DiameterSpread): a fraction of their interaction
    // radius, whatever a few outsized nodes measure.
    const double range = with_skin_ && !search_due_ ? searched_range_ : bulk_interaction_radius(nodes, a, real);
    const double rounding = 1e-9 * range;
    ghosts.update_contacts(nodes, real, first);
    if (!with_skin_) {
        ghosts.build(nodes, real, ghosts.pair_reach(nodes, real, a, rounding));
    } else if (search_due_) {
        // Ghosts for every node within the candidates' reach, kept until the next search.
        skin_ = solver_->neighbour_skin * range;
        searched_range_ = range;
        ghosts.build(nodes, real, ghosts.pair_reach(nodes, real, a, skin_ + rounding), true);
    } else {
        ghosts.update(nodes, real);
    }
}

bool NeighbourLists::candidates_stale(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts,
                                      InfluenceDistance influence_distance, double rounding) const {
    // A pair (i, j) left out by the last search had r >= 2 h_ij + skin then. Now r has shrunk by
    // at most |u_i - u_j| <= 2 max |u - U| (u the displacements since the search, U any common
    // translation: the middle of the u), and 2 h_ij has grown by at most 2 a max (d - d_then).
    // The candidates are stale once those two can add up to the skin. Pairs with ghosts get the
    // same bound from the ghost set, which must also still hold every node within reach of a plane.
    struct Extent {
        std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        double growth = 0.0;
    };
    const int d = nodes.dim();
    const Extent e = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), Extent{},
        [&](const tbb::blocked_range<std::size_t>& r, Extent acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                for (int c = 0; c < d; ++c) {
                    const double u = nodes.position[c][i] - searched_position_[c][i];
                    acc.lo[c] = std::min(acc.lo[c], u);
                    acc.hi[c] = std::max(acc.hi[c], u);
                }
                acc.growth = std::max(acc.growth, nodes.diameter[i] - searched_diameter_[i]);
            }
            return acc;
        },
        [](Extent x, const Extent& y) {
            for (int c = 0; c < 3; ++c) {
                x.lo[c] = std::min(x.lo[c], y.lo[c]);
                x.hi[c] = std::max(x.hi[c], y.hi[c]);
            }
            x.growth = std::max(x.growth, y.growth);
            return x;
        });
    std::array<double, 3> middle{0, 0, 0};
    for (int c = 0; c < d; ++c) middle[c] = 0.5 * (e.lo[c] + e.hi[c]);
    const double largest = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                double u2 = 0.0;
                for (int c = 0; c < d; ++c) {
                    const double u = nodes.position[c][i] - searched_position_[c][i] - middle[c];
                    u2 += u * u;
                }
                acc = std::max(acc, u2);
            }
            return acc;
        },
        [](double x, double y) { return std::max(x, y); });
    double closing = 2.0 * std::sqrt(largest);
    if (!ghosts.empty()) {
        if (!ghosts.covers(nodes, real, ghosts.pair_reach(nodes, real, influence_distance.value(), rounding))) return true;
        closing = std::max(closing, ghosts.mirrored_displacement_bound(nodes, real, searched_position_));
    }
    // NaN positions make the bound NaN: search, and let the phases report them.
    return !(closing + 2.0 * influence_distance.value() * e.growth < skin_);
}

bool NeighbourLists::switched_near_quiet_rows(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts) const {
    // A quiet row lacks the fixed nodes of its body that are not its lattice neighbours; they
    // become pairs only when one of the two switches. A node that switched since the search and
    // was itself quiet lacks them all; one that was not holds every node within its reach in its
    // candidates, so the quiet centres within its reach are in its row (a ghost entry names its
    // source, whose row has the mirror image of the pair).
    if (!any_quiet_) return false;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), false,
        [&](const tbb::blocked_range<std::size_t>& r, bool found) {
            for (std::size_t i = r.begin(); i != r.end() && !found; ++i) {
                if (!searched_fixed_[i] || nodes.connectivity[i] == Connectivity::Fixed) continue;
                if (quiet_[i]) return true;
                for (NodeIndex j : candidates_.row(i)) {
                    const std::size_t centre = j < real ? j : ghosts.source(j - real);
                    if (quiet_[centre]) return true;
                }
            }
            return found;
        },
        [](bool x, bool y) { return x || y; });
}

void NeighbourLists::check_against_search(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts,
                                          InfluenceDistance influence_distance, std::size_t step) const {
    // The pairs a step without a skin would have: fresh ghosts (only the nodes in contact across
    // lift-off planes) in a copy of the nodes, a full search, the contact rule. A ghost entry is
    // compared as (source node, planes), since the two ghost sets number their ghosts differently.
    NodeStore copy = nodes;
    GhostSet fresh_ghosts = ghosts;
    CompressedRows fresh;
    NeighbourScratch scratch;
    const CompressedRows* mirrored = nullptr;
    if (!ghosts.empty()) {
        // Ghosts for every node within the largest interaction radius of the planes, not the
        // reach place_ghosts derives (GhostSet::pair_reach): the check holds that reach too.
        fresh_ghosts.build(copy, real, largest_interaction_radius(nodes, influence_distance.value(), real));
        mirrored = &fresh_ghosts.resolved_fixed_mirrors(copy, real);
    }
    find_neighbours(copy, influence_distance, real, fresh, scratch, mirrored);
    if (!ghosts.empty()) fresh_ghosts.remove_pairs_without_contact(fresh, copy, real);
    const auto key = [&](const GhostSet& set, NodeIndex j) -> std::uint64_t {
        if (j < real) return j;
        const std::size_t k = j - real;
        return (std::uint64_t{set.planes_of(k)} << 40) | set.source(k);
    };
    for (std::size_t i = 0; i < real; ++i) {
        std::vector<std::uint64_t> mine, theirs;
        for (NodeIndex j : lists_.row(i)) mine.push_back(key(ghosts, j));
        for (NodeIndex j : fresh.row(i)) theirs.push_back(key(fresh_ghosts, j));
        std::sort(mine.begin(), mine.end());
        std::sort(theirs.begin(), theirs.end());
        if (mine != theirs) {
            throw NumericalError(fmt::format("step {}: node {} has {} neighbours from the candidate lists but {} from a "
                                             "full search",
                                             step, i, mine.size(), theirs.size()));
        }
    }
}

void NeighbourLists::search_candidates(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance,
                                       bool any_automatic) {
    const CompressedRows* mirrored = ghosts.empty() ? nullptr : &ghosts.resolved_fixed_mirrors(nodes, real);
    if (ghosts.empty()) {
        searched_range_ = bulk_interaction_radius(nodes, influence_distance.value(), real);
        skin_ = solver_->neighbour_skin * searched_range_;
    }
    find_neighbours(nodes, influence_distance, real, candidates_, scratch_, mirrored, skin_, any_automatic);
    quiet_.swap(scratch_.quiet);
    quiet_.resize(real, 0);
    any_quiet_ = std::find(quiet_.begin(), quiet_.end(), std::uint8_t{1}) != quiet_.end();
    searched_fixed_.resize(real);
    for (std::size_t i = 0; i < real; ++i) searched_fixed_[i] = nodes.connectivity[i] == Connectivity::Fixed;
    lattice_entries_.assign(real, 0);
    for (std::size_t i = 0; i < real; ++i) {
        if (nodes.connectivity[i] != Connectivity::Fixed) continue;
        lattice_entries_[i] =
            static_cast<std::uint32_t>(nodes.fixed_neighbours.row(i).size() + (mirrored ? mirrored->row(i).size() : 0));
    }
    for (int c = 0; c < nodes.dim(); ++c) searched_position_[c].assign(nodes.position[c].begin(), nodes.position[c].begin() + real);
    searched_diameter_.assign(nodes.diameter.begin(), nodes.diameter.begin() + real);
    // The scatter plan of the candidates (with their ghost rows) serves every step until the
    // next search: a plan without conflicts for some lists has none for any subset of them.
    if (ghosts.empty()) {
        plan_ = make_plan(solver_->scatter, candidates_, positions_of(nodes), nodes.size());
    } else {
        // The ghost rows go on the candidates for the plan and come off again (no copy: memory).
        const std::size_t entries = candidates_.entries();
        ghosts.append_ghost_rows(candidates_, real);
        plan_ = make_plan(solver_->scatter, candidates_, positions_of(nodes), nodes.size());
        candidates_.offsets.resize(real + 1);
        candidates_.indices.resize(entries);
    }
    search_due_ = false;
    ++searches_;
}

void NeighbourLists::update(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool any_automatic,
                            Contact& contact, std::size_t step) {
    kept_rows_ = 0;
    if (constant_ && lists_.rows() == real) return;
    const int d = nodes.dim();
    if (with_skin_) {
        if (search_due_) search_candidates(nodes, real, ghosts, influence_distance, any_automatic);
        filter_candidates(nodes, influence_distance.value(), candidates_, lattice_entries_, lists_, keep_scratch_);
        if (!ghosts.empty()) ghosts.remove_pairs_without_contact(lists_, nodes, real);
        if (solver_->check_neighbour_lists) check_against_search(nodes, real, ghosts, influence_distance, step);
        contact.separate(lists_, nodes, real, influence_distance.value());
        if (!ghosts.empty()) ghosts.append_ghost_rows(lists_, real);
        contact.mirror_directions(ghosts, d, real);
        return;
    }
    ++searches_;
    plan_due_ = true;
    if (ghosts.empty()) {
        find_neighbours(nodes, influence_distance, real, lists_, scratch_);
        contact.separate(lists_, nodes, real, influence_distance.value());
        return;
    }
    const CompressedRows& mirrored = ghosts.resolved_fixed_mirrors(nodes, real);
    find_neighbours(nodes, influence_distance, real, lists_, scratch_, &mirrored);
    ghosts.remove_pairs_without_contact(lists_, nodes, real);
    contact.separate(lists_, nodes, real, influence_distance.value());
    ghosts.append_ghost_rows(lists_, real);
    contact.mirror_directions(ghosts, d, real);
}

void NeighbourLists::refresh_plan(const NodeStore& nodes) {
    if (!plan_due_) return;
    plan_ = make_plan(solver_->scatter, lists_, positions_of(nodes), nodes.size());
    plan_due_ = false;
}

void NeighbourLists::write_state(StateWriter& out, int dim) const {
    out.tag("LIST");
    write_rows(out, lists_);
    out.value<std::uint8_t>(search_due_);
    out.value<std::uint8_t>(plan_due_);
    out.value<double>(skin_);
    out.value<double>(searched_range_);
    out.value<std::uint64_t>(searches_);
    write_rows(out, candidates_);
    out.array(lattice_entries_);
    out.array(quiet_);
    out.array(searched_fixed_);
    for (int c = 0; c < dim; ++c) out.array(searched_position_[c]);
    out.array(searched_diameter_);
    write_plan(out, plan_);
}

void NeighbourLists::read_state(StateReader& in, int dim, std::size_t node_count) {
    kept_rows_ = 0;  // the restored lists are not those the terms were kept for
    in.tag("LIST");
    read_rows(in, lists_, std::numeric_limits<std::size_t>::max(), node_count);
    search_due_ = in.value<std::uint8_t>() != 0;
    plan_due_ = in.value<std::uint8_t>() != 0;
    skin_ = in.value<double>();
    searched_range_ = in.value<double>();
    searches_ = static_cast<std::size_t>(in.value<std::uint64_t>());
    read_rows(in, candidates_, std::numeric_limits<std::size_t>::max(), node_count);
    in.array(lattice_entries_);
    in.array(quiet_);
    in.array(searched_fixed_);
    any_quiet_ = std::find(quiet_.begin(), quiet_.end(), std::uint8_t{1}) != quiet_.end();
    if (quiet_.size() != searched_fixed_.size() || quiet_.size() != lattice_entries_.size()) in.fail("its neighbour lists are damaged");
    for (int c = 0; c < dim; ++c) in.array(searched_position_[c]);
    in.array(searched_diameter_);
    read_plan(in, plan_, node_count);
}

void NeighbourLists::memory_use(MemoryUse& out) const {
    add_memory(out, "neighbour lists: lists", allocated_bytes(lists_.indices) + allocated_bytes(lists_.offsets));
    add_memory(out, "neighbour lists: kept pair terms", allocated_bytes(kept_weight_over_r2_));
    add_memory(out, "neighbour lists: skin candidates", allocated_bytes(candidates_.indices) + allocated_bytes(candidates_.offsets) +
                                                            allocated_bytes(lattice_entries_) + allocated_bytes(keep_scratch_) +
                                                            allocated_bytes(quiet_) + allocated_bytes(searched_fixed_));
    std::size_t searched = allocated_bytes(searched_diameter_);
    for (const auto& p : searched_position_) searched += allocated_bytes(p);
    add_memory(out, "neighbour lists: positions at the last search", searched);
    add_memory(out, "neighbour lists: scatter plan",
               allocated_bytes(plan_.centres) + allocated_bytes(plan_.group_offsets) + allocated_bytes(plan_.colour_offsets));
    add_memory(out, "neighbour lists: cell grid", allocated_bytes(scratch_.grid.nodes) + allocated_bytes(scratch_.grid.cell_start));
}

}  // namespace gpa
