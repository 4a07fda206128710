#include "step/neighbour_lists.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iterator>
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

// A scatter plan in a checkpoint, both directions (Plan const when writing); read, it must name
// only nodes below `node_count`.
template <class IO, class Plan>
void plan_fields(IO& io, Plan& plan, std::size_t node_count) {
    auto scheme = static_cast<std::int32_t>(plan.scheme);
    io.field(scheme);
    io.field(plan.colour_offsets);
    io.field(plan.group_offsets);
    io.field(plan.centres);
    if constexpr (IO::reading) {
        plan.scheme = static_cast<ScatterScheme>(scheme);
        const bool fits = !plan.colour_offsets.empty() && !plan.group_offsets.empty() &&
                          plan.colour_offsets.back() <= plan.group_offsets.size() - 1 &&
                          plan.group_offsets.back() <= plan.centres.size();
        if (!fits) io.fail("its scatter plan is damaged");
        for (const NodeIndex c : plan.centres) {
            if (c >= node_count) io.fail("its scatter plan names a node that does not exist");
        }
    }
}

}  // namespace

void NeighbourLists::set_up(bool constant) {
    constant_ = constant;
    with_skin_ = solver_->neighbour_skin > 0.0 && !constant;
}

void NeighbourLists::invalidate() {
    // Rebuilt in the new numbering by the next update; their memory freed now, not only emptied,
    // so that the renumbering of the nodes (its copies of the lattice lists) has it.
    lists_ = CompressedRows{};
    candidates_ = CompressedRows{};
    found_ = CompressedRows{};
    std::vector<std::uint64_t>().swap(keep_scratch_);
    forget_kept_arrays();
    search_due_ = true;
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
    resize_with_slack(kept_weight_over_r2_, entries, per_entry_slack);
    return kept_weight_over_r2_.data();
}

void NeighbourLists::place_ghosts(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool first) {
    const double a = influence_distance.value();
    // Rounding of a ghost's mirrored coordinates against the search's r < 2 h_ij: a margin far
    // below any spacing (a billionth of the bulk's interaction radius at the last search), so
    // that a pair at the edge of its reach never misses its ghost.
    rows_due_.clear();
    if (with_skin_ && !search_due_) {
        const double rounding = 1e-9 * searched_range_;
        const Staleness s = staleness(nodes, real, ghosts, influence_distance, rounding);
        // A full search when the ghosts no longer cover the planes' reach, or when a position or
        // diameter is not finite (the phases after the search report it).
        if (s.ghosts_short || !std::isfinite(s.largest_budget)) {
            search_due_ = true;
        } else {
            // The rows of nodes that have switched next to a quiet centre (or were quiet
            // themselves), and those quiet centres: searched alone, each of their pairs goes into
            // both rows.
            const std::vector<NodeIndex> switched = switched_near_quiet_rows(nodes, real, ghosts);
            // Rows searched alone leave only the per-row bound (the header), whose argument needs
            // every row's budget within a third of the skin from the moment a row is searched
            // alone: where the common bound held, the budgets have not been measured yet.
            double largest = s.largest_budget;
            if (s.common_bound_holds && !switched.empty()) largest = largest_budget(nodes, real, influence_distance.value());
            if (!std::isfinite(largest)) {
                search_due_ = true;
            } else if ((!s.common_bound_holds || !switched.empty()) && !(3.0 * largest + rounding < skin_)) {
                // Neither bound holds, or the per-row one is about to serve alone and does not:
                // search the rows that have moved, or all.
                choose_rows(nodes, real, influence_distance);
            }
            if (!search_due_) add_rows_due(switched, real);
        }
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
        place_ghosts_for_search(nodes, real, ghosts, a, range);
    } else {
        ghosts.update(nodes, real);
    }
}

void NeighbourLists::place_ghosts_for_search(NodeStore& nodes, std::size_t real, GhostSet& ghosts, double a, double range) {
    // Ghosts for every node within the candidates' reach, kept until the next search.
    skin_ = solver_->neighbour_skin * range;
    searched_range_ = range;
    ghosts.build(nodes, real, ghosts.pair_reach(nodes, real, a, skin_ + 1e-9 * range), true);
}

double NeighbourLists::row_budget(const NodeStore& nodes, std::size_t i, double a) const {
    // Row i's budget (the header): its node's displacement since the row was searched, plus a
    // times the change of its diameter since then.
    double u2 = 0.0;
    for (int c = 0; c < nodes.dim(); ++c) {
        const double u = nodes.position[c][i] - searched_position_[c][i];
        u2 += u * u;
    }
    return std::sqrt(u2) + a * std::abs(nodes.diameter[i] - searched_diameter_[i]);
}

double NeighbourLists::largest_budget(const NodeStore& nodes, std::size_t real, double a) const {
    // The per-row budget (the header): |u_i| + a |d_i - d_then,i|, each row from its own search;
    // NaN with a NaN position or diameter (place_ghosts then searches in full).
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, costly_node_grain), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double budget = row_budget(nodes, i, a);
                // A NaN, once met, stays: std::max would drop it, and so would a test that lets a
                // later finite budget replace it (as this one did, unless the NaN ended its task).
                if (!std::isnan(acc) && !(budget <= acc)) acc = budget;
            }
            return acc;
        },
        [](double x, double y) { return std::isnan(x) ? x : (std::isnan(y) || y > x ? y : x); });
}

NeighbourLists::Staleness NeighbourLists::staleness(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts,
                                                    InfluenceDistance influence_distance, double rounding) const {
    const int d = nodes.dim();
    const double a = influence_distance.value();
    Staleness out;
    // The ghost set must still hold every node within reach of a plane.
    if (!ghosts.empty() && !ghosts.covers(nodes, real, ghosts.pair_reach(nodes, real, a, rounding))) {
        out.ghosts_short = true;
        return out;
    }
    if (!rows_searched_alone_) {
        // The common bound (after a full search, while no row has been searched alone): a pair
        // (i, j) left out by the last search had r >= 2 h_ij + skin then. Now r has shrunk by at
        // most |u_i - u_j| <= 2 max |u - U| (u the displacements since the search, U any common
        // translation: the middle of the u), and 2 h_ij has grown by at most 2 a max (d - d_then).
        // The candidates are stale once those two can add up to the skin. Pairs with ghosts get
        // the same bound from the ghost set.
        struct Extent {
            std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
            double growth = 0.0;
        };
        const Extent e = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, real, costly_node_grain), Extent{},
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
            tbb::blocked_range<std::size_t>(0, real, costly_node_grain), 0.0,
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
        if (!ghosts.empty()) closing = std::max(closing, ghosts.mirrored_displacement_bound(nodes, real, searched_position_));
        // NaN positions make the bound NaN: it fails.
        out.common_bound_holds = closing + 2.0 * a * e.growth < skin_;
        if (out.common_bound_holds) return out;
    }
    out.largest_budget = largest_budget(nodes, real, a);
    return out;
}

void NeighbourLists::choose_rows(const NodeStore& nodes, std::size_t real, InfluenceDistance influence_distance) {
    // A row is searched again when its budget is above a sixth of the skin: the rest keep at
    // most that, so the next search of rows is due only when one of them has used up twice as
    // much again. When they are many (a body in flight, say) or the candidates have grown by a
    // quarter since the last full search (rows searched alone keep their old entries), a full
    // search costs less and starts every row afresh.
    const double a = influence_distance.value();
    const double limit = skin_ / 6.0;
    for (std::size_t i = 0; i < real; ++i) {
        if (!(row_budget(nodes, i, a) <= limit)) rows_due_.push_back(static_cast<NodeIndex>(i));
    }
    full_search_if_cheaper(real);
}

void NeighbourLists::full_search_if_cheaper(std::size_t real) {
    if (rows_due_.size() > real / 8 || candidates_.entries() > full_search_entries_ + full_search_entries_ / 4) {
        rows_due_.clear();
        search_due_ = true;
    }
}

void NeighbourLists::add_rows_due(const std::vector<NodeIndex>& rows, std::size_t real) {
    if (rows.empty()) return;
    // Both ascending: the union, ascending (search_rows takes the rows due in this order).
    std::vector<NodeIndex> merged;
    merged.reserve(rows_due_.size() + rows.size());
    std::set_union(rows_due_.begin(), rows_due_.end(), rows.begin(), rows.end(), std::back_inserter(merged));
    rows_due_.swap(merged);
    full_search_if_cheaper(real);
}

std::vector<NodeIndex> NeighbourLists::switched_near_quiet_rows(const NodeStore& nodes, std::size_t real,
                                                                const GhostSet& ghosts) const {
    // A quiet row holds its lattice neighbours alone: it lacks the other fixed nodes of its body
    // within reach, which become pairs only when one of the two switches, and the cut keeps it
    // whole. A node that has switched since its row was searched is due if it was quiet (its
    // row lacks them all) or if its candidates hold a quiet centre (a ghost entry names its
    // source); so is that quiet centre. Searched alone, each row gains its pairs, each put into
    // both rows (search_rows), and the quiet centre, now next to a variable node or with a
    // switched lattice neighbour, is quiet no more (find_neighbours). A quiet centre farther than
    // a quiet switched node's lattice neighbours gains the new pair at the end of its row, which
    // the cut then takes entry by entry. The rows ascending, each once.
    using Rows = std::vector<NodeIndex>;
    if (!any_quiet_) return {};
    Rows rows = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real, costly_node_grain), Rows{},
        [&](const tbb::blocked_range<std::size_t>& r, Rows found) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                if (!searched_fixed_[i] || nodes.connectivity[i] == Connectivity::Fixed) continue;
                const std::size_t before = found.size();
                for (NodeIndex j : candidates_.row(i)) {
                    const std::size_t centre = j < real ? j : ghosts.source(j - real);
                    if (quiet_[centre]) found.push_back(static_cast<NodeIndex>(centre));
                }
                if (quiet_[i] || found.size() > before) found.push_back(static_cast<NodeIndex>(i));
            }
            return found;
        },
        [](Rows x, const Rows& y) {
            x.insert(x.end(), y.begin(), y.end());
            return x;
        });
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    return rows;
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
    // The lattice counts only where some row has lattice entries (filter_candidates reads none as 0).
    if (nodes.fixed_neighbours.rows() == 0 && (!mirrored || mirrored->rows() == 0)) {
        std::vector<std::uint32_t>().swap(lattice_entries_);
    } else {
        lattice_entries_.assign(real, 0);
    }
    for (std::size_t i = 0; i < real && !lattice_entries_.empty(); ++i) {
        if (nodes.connectivity[i] != Connectivity::Fixed) continue;
        lattice_entries_[i] =
            static_cast<std::uint32_t>(nodes.fixed_neighbours.row_or_empty(i).size() + (mirrored ? mirrored->row_or_empty(i).size() : 0));
    }
    for (int c = 0; c < nodes.dim(); ++c) searched_position_[c].assign(nodes.position[c].begin(), nodes.position[c].begin() + real);
    searched_diameter_.assign(nodes.diameter.begin(), nodes.diameter.begin() + real);
    plan_with_ghost_rows(nodes, ghosts, real);
    search_due_ = false;
    rows_searched_alone_ = false;
    full_search_entries_ = candidates_.entries();
    ++searches_;
}

void NeighbourLists::plan_with_ghost_rows(const NodeStore& nodes, GhostSet& ghosts, std::size_t real) {
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
}

void NeighbourLists::search_rows(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance,
                                 bool any_automatic) {
    // The rows of rows_due_ searched as a full search would (find_neighbours with `only`), then
    // every pair found put into both rows: (i, j) into row j for a real j, and for a ghost of
    // source s across planes P, the ghost of i across P into row s (the same pair seen from the
    // other side of the planes). A row keeps its old entries (the candidates only grow until the
    // next full search, which choose_rows calls when they have grown by a quarter) and gains those
    // it lacks at its end, in the order found: rows due first, in their own order, then the
    // other side of each pair in the order of the rows due.
    const CompressedRows* mirrored = ghosts.empty() ? nullptr : &ghosts.resolved_fixed_mirrors(nodes, real);
    find_neighbours(nodes, influence_distance, real, found_, scratch_, mirrored, skin_, any_automatic, rows_due_);
    std::vector<std::pair<NodeIndex, NodeIndex>> pairs;  // (row, entry), the order above
    pairs.reserve(2 * found_.entries());
    for (std::size_t k = 0; k < rows_due_.size(); ++k) {
        for (NodeIndex j : found_.row(k)) pairs.emplace_back(rows_due_[k], j);
    }
    for (std::size_t k = 0; k < rows_due_.size(); ++k) {
        const NodeIndex i = rows_due_[k];
        for (NodeIndex j : found_.row(k)) {
            if (j < real) {
                pairs.emplace_back(j, i);
                continue;
            }
            const std::int64_t image = ghosts.image_like(real, j, i);
            if (image < 0) {
                // i has no ghost across those planes (it has come within their reach since the
                // ghosts were placed): the ghosts placed again, and a full search.
                const double a = influence_distance.value();
                place_ghosts_for_search(nodes, real, ghosts, a, bulk_interaction_radius(nodes, a, real));
                search_candidates(nodes, real, ghosts, influence_distance, any_automatic);
                return;
            }
            pairs.emplace_back(ghosts.source(j - real), static_cast<NodeIndex>(image));
        }
    }
    // The pairs by row, in the order above (a stable counting sort), then those a row lacks.
    std::vector<std::size_t> add_offsets(real + 1, 0);
    for (const auto& p : pairs) ++add_offsets[p.first + 1];
    for (std::size_t i = 0; i < real; ++i) add_offsets[i + 1] += add_offsets[i];
    std::vector<NodeIndex> additions(pairs.size());
    {
        std::vector<std::size_t> next(add_offsets.begin(), add_offsets.end() - 1);
        for (const auto& p : pairs) additions[next[p.first]++] = p.second;
    }
    std::vector<std::uint8_t> listed(nodes.size(), 0);
    std::vector<NodeIndex> changed;  // ascending
    std::vector<std::size_t> added_count;
    std::size_t total_added = 0;
    for (std::size_t i = 0; i < real; ++i) {
        const std::size_t first = add_offsets[i], last = add_offsets[i + 1];
        if (first == last) continue;
        for (NodeIndex j : candidates_.row(i)) listed[j] = 1;
        std::size_t kept = first;
        for (std::size_t e = first; e < last; ++e) {
            const NodeIndex j = additions[e];
            if (listed[j] || j == i) continue;
            listed[j] = 1;
            additions[kept++] = j;
        }
        for (NodeIndex j : candidates_.row(i)) listed[j] = 0;
        for (std::size_t e = first; e < kept; ++e) listed[additions[e]] = 0;
        if (kept == first) continue;
        changed.push_back(static_cast<NodeIndex>(i));
        added_count.push_back(kept - first);
        total_added += kept - first;
    }
    const std::size_t old_entries = candidates_.entries();
    const std::size_t new_entries = old_entries + total_added;
    if (scratch_.check_entries) scratch_.check_entries(new_entries);
    // In place, from the last row back: each stretch of rows between two that gain entries moves
    // up by the entries gained before its end, then the row before it takes its additions.
    resize_with_slack(candidates_.indices, new_entries, per_entry_slack);
    NodeIndex* index = candidates_.indices.data();
    std::size_t end_old = old_entries, shift = total_added;
    for (std::size_t c = changed.size(); c-- > 0;) {
        const NodeIndex i = changed[c];
        const std::size_t start_old = candidates_.offsets[i + 1];
        if (shift > 0 && end_old > start_old) std::memmove(index + start_old + shift, index + start_old, (end_old - start_old) * sizeof(NodeIndex));
        shift -= added_count[c];
        const std::size_t first = add_offsets[i];
        std::copy(additions.begin() + static_cast<std::ptrdiff_t>(first),
                  additions.begin() + static_cast<std::ptrdiff_t>(first + added_count[c]), index + start_old + shift);
        end_old = start_old;
    }
    {
        std::size_t gained = 0, c = 0;
        for (std::size_t i = 0; i < real; ++i) {
            candidates_.offsets[i] += gained;
            if (c < changed.size() && changed[c] == i) gained += added_count[c++];
        }
        candidates_.offsets[real] += gained;
    }
    // The rows searched take this moment as their reference, and their node's mode and quietness.
    for (NodeIndex i : rows_due_) {
        for (int c = 0; c < nodes.dim(); ++c) searched_position_[c][i] = nodes.position[c][i];
        searched_diameter_[i] = nodes.diameter[i];
        searched_fixed_[i] = nodes.connectivity[i] == Connectivity::Fixed;
        quiet_[i] = scratch_.quiet.empty() ? 0 : scratch_.quiet[i];
    }
    any_quiet_ = std::find(quiet_.begin(), quiet_.end(), std::uint8_t{1}) != quiet_.end();
    plan_with_ghost_rows(nodes, ghosts, real);
    rows_searched_alone_ = true;
    ++row_searches_;
    rows_searched_ += rows_due_.size();
    rows_due_.clear();
}

void NeighbourLists::update(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool any_automatic,
                            Contact& contact, std::size_t step) {
    kept_rows_ = 0;
    if (constant_ && lists_.rows() == real) return;
    const int d = nodes.dim();
    if (with_skin_) {
        if (search_due_) {
            search_candidates(nodes, real, ghosts, influence_distance, any_automatic);
        } else if (!rows_due_.empty()) {
            search_rows(nodes, real, ghosts, influence_distance, any_automatic);
        }
        // The quiet rows' lattice pairs are whole until a node near one of them, or one of their
        // lattice neighbours, switches: place_ghosts then makes the switched node's row and the
        // quiet centres in it due, searched before this cut (switched_near_quiet_rows).
        LatticeRowsKept kept_rows;
        kept_rows.switching = any_automatic;
        kept_rows.quiet = quiet_.data();
        kept_rows.quiet_rows = quiet_.size();
        filter_candidates(nodes, influence_distance.value(), candidates_, lattice_entries_, lists_, keep_scratch_, kept_rows);
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

template <class IO, class Self>
void NeighbourLists::state_fields(IO& io, Self& self, int dim, std::size_t node_count) {
    constexpr std::size_t any_rows = std::numeric_limits<std::size_t>::max();
    io.tag("LIST");
    rows_field(io, self.lists_, any_rows, node_count);
    io.field(self.search_due_);
    io.field(self.plan_due_);
    io.field(self.skin_);
    io.field(self.searched_range_);
    io.field(self.searches_);
    rows_field(io, self.candidates_, any_rows, node_count);
    io.field(self.lattice_entries_);
    io.field(self.quiet_);
    io.field(self.searched_fixed_);
    if constexpr (IO::reading) {
        if (self.quiet_.size() != self.searched_fixed_.size() ||
            (!self.lattice_entries_.empty() && self.quiet_.size() != self.lattice_entries_.size())) {
            io.fail("its neighbour lists are damaged");
        }
    }
    for (int c = 0; c < dim; ++c) io.field(self.searched_position_[c]);
    io.field(self.searched_diameter_);
    io.field(self.rows_searched_alone_);
    io.field(self.row_searches_);
    io.field(self.rows_searched_);
    io.field(self.full_search_entries_);
    plan_fields(io, self.plan_, node_count);
}

void NeighbourLists::write_state(StateWriter& out, int dim) const { state_fields(out, *this, dim, 0); }

void NeighbourLists::read_state(StateReader& in, int dim, std::size_t node_count) {
    kept_rows_ = 0;  // the restored lists are not those the terms were kept for
    state_fields(in, *this, dim, node_count);
    any_quiet_ = std::find(quiet_.begin(), quiet_.end(), std::uint8_t{1}) != quiet_.end();
}

void NeighbourLists::memory_use(MemoryUse& out) const {
    add_memory(out, "neighbour lists: lists", allocated_bytes(lists_.indices) + allocated_bytes(lists_.offsets));
    add_memory(out, "neighbour lists: kept pair terms", allocated_bytes(kept_weight_over_r2_));
    add_memory(out, "neighbour lists: skin candidates", allocated_bytes(candidates_.indices) + allocated_bytes(candidates_.offsets) +
                                                            allocated_bytes(lattice_entries_) + allocated_bytes(keep_scratch_) +
                                                            allocated_bytes(quiet_) + allocated_bytes(searched_fixed_) +
                                                            allocated_bytes(found_.indices) + allocated_bytes(found_.offsets) +
                                                            allocated_bytes(rows_due_));
    std::size_t searched = allocated_bytes(searched_diameter_);
    for (const auto& p : searched_position_) searched += allocated_bytes(p);
    add_memory(out, "neighbour lists: positions at the last search", searched);
    add_memory(out, "neighbour lists: scatter plan",
               allocated_bytes(plan_.centres) + allocated_bytes(plan_.group_offsets) + allocated_bytes(plan_.colour_offsets));
    add_memory(out, "neighbour lists: cell grid", allocated_bytes(scratch_.grid.nodes) + allocated_bytes(scratch_.grid.cell_start));
    std::size_t wave = 0;
    for (const auto& b : scratch_.block_entries) wave += allocated_bytes(b);
    add_memory(out, "neighbour lists: a search's wave of rows", wave);
}

}  // namespace gpa
