#pragma once
// A part of the time step (simulation.cpp): the neighbour lists and their scatter plan. Owns the
// rows every pair pass reads (real rows, then the ghost rows), the Verlet candidates of
// SolverOptions::neighbour_skin (every pair within 2 h_ij + skin at the last search, the positions
// and diameters then, and how many leading entries of a fixed centre's row are lattice neighbours),
// and the conflict-free scatter plan of the force passes (colouring.hpp). Places the ghosts each
// step (their reach follows the skin) and decides when a search is due. Saves and restores its
// state as its own checkpoint section.
//
// The lists of a step are the same with or without a skin, as sets; only the order of a row's
// entries may differ (check_neighbour_lists compares them with a full search every step).
//
// When the candidates go stale, a few rows may be searched again instead of all (search_rows):
// those of the nodes that have moved (or grown) by more than a sixth of the skin since their row
// was searched. Each pair that search finds goes into both rows, so a pair left out of both rows
// was farther than 2 h_ij + skin when the later of its two rows was searched; from then on it has
// closed by at most the displacement of each of its nodes since that search, one of them bounded
// by its own row's reference and the other by twice its budget (its displacement then and now
// from its own reference). The candidates hold every pair while three times the largest budget
// stays below the skin (docs/engine.md, "The search": rows searched alone).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

class Contact;

class NeighbourLists {
public:
    explicit NeighbourLists(const SolverOptions& solver) : solver_(&solver) {}

    // Set-up: `constant` when the lists can never change (every node fixed, one body, no ghosts):
    // then one search serves the whole run and there is no skin.
    void set_up(bool constant);
    // Called with the entry count before every search allocates its lists (memory limits); it
    // throws when the lists do not fit and returns whether the kept pair terms fit too.
    void set_entry_check(std::function<bool(std::size_t)> check) {
        scratch_.check_entries = [this, check = std::move(check)](std::size_t entries) {
            keep_allowed_ = check(entries);
            if (!keep_allowed_) forget_kept_arrays();  // before the search allocates its lists
        };
    }
    NeighbourLists(const NeighbourLists&) = delete;  // the entry check above holds `this`
    NeighbourLists& operator=(const NeighbourLists&) = delete;

    const CompressedRows& rows() const { return lists_; }

    // Each pair's R_ij / r_ij^2 for the sweeps of a step (fields.hpp, PairFields::kept_weight_over_r2):
    // keep_pairs gives the gradient sweep an array for the entries of the rows [0, real) to write,
    // pairs_kept says it has, and with_kept_pairs hands them to the sweeps after it. They are
    // forgotten when the positions move (forget_kept_pairs, the move phase) and when the lists
    // change. Not checkpointed: every step makes them again before it reads them. When the memory
    // limit leaves no room for them (set_entry_check), keep_pairs gives null pointers and the
    // sweeps make the terms themselves.
    double* keep_pairs(std::size_t real);
    void pairs_kept(std::size_t real) { kept_rows_ = keep_allowed_ ? real : 0; }
    void forget_kept_arrays();
    void forget_kept_pairs() { kept_rows_ = 0; }
    template <int D>
    PairFields<D> with_kept_pairs(PairFields<D> pairs) const {
        pairs.kept_weight_over_r2 = kept_weight_over_r2_.data();
        pairs.kept_rows = kept_rows_;
        return pairs;
    }
    const ScatterPlan& plan() const { return plan_; }
    std::size_t searches() const { return searches_; }
    // Searches of some rows alone (the candidates of the nodes that had moved), and the rows they searched.
    std::size_t row_searches() const { return row_searches_; }
    std::size_t rows_searched() const { return rows_searched_; }

    // The nodes are renumbered (NodeStore::permute): search again in the new numbering. Frees the
    // lists and candidates at once (called before the renumbering, whose copies then take their place).
    void invalidate();

    // Geometry phase, after the diameters: decides whether the candidates are stale, then places
    // the ghosts of `ghosts` (all within reach of a plane, with the skin when a search is due;
    // `first` on the set-up's call, when contacts start from the initial state).
    void place_ghosts(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool first);

    // Neighbours phase: the lists of this step, from the candidates (searched again when due) or
    // from a full search; pairs across planes without contact out, open separable pairs out
    // (contact), ghost rows appended. `any_automatic`: the search keeps fixed centres' candidates
    // too. `step` names the step in the error of check_neighbour_lists.
    void update(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool any_automatic,
                Contact& contact, std::size_t step);

    // Plan phase: a plan for lists searched without a skin (with a skin the search made one that
    // serves every step until the next search; lists that did not change keep theirs).
    void refresh_plan(const NodeStore& nodes);

    void memory_use(MemoryUse& out) const;

    void write_state(StateWriter& out, int dim) const;
    void read_state(StateReader& in, int dim, std::size_t node_count);

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self, int dim, std::size_t node_count);

    // What the geometry phase learns of the candidates: whether the ghosts still cover every
    // node within reach of a plane, whether the bound of the last full search still holds (every
    // reference from one moment; the displacements measured from their middle), and the largest
    // budget of a row (its node's displacement and diameter change since its row was searched).
    struct Staleness {
        bool ghosts_short = false;
        bool common_bound_holds = false;
        double largest_budget = 0.0;
    };
    Staleness staleness(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts, InfluenceDistance influence_distance,
                        double rounding) const;
    double row_budget(const NodeStore& nodes, std::size_t i, double a) const;
    // The largest row_budget of the real rows; NaN where a position or diameter is NaN.
    double largest_budget(const NodeStore& nodes, std::size_t real, double a) const;
    // The rows whose budget is above a sixth of the skin; a full search instead when they are many.
    void choose_rows(const NodeStore& nodes, std::size_t real, InfluenceDistance influence_distance);
    void search_rows(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance, bool any_automatic);
    void plan_with_ghost_rows(const NodeStore& nodes, GhostSet& ghosts, std::size_t real);
    void place_ghosts_for_search(NodeStore& nodes, std::size_t real, GhostSet& ghosts, double a, double range);
    // The nodes that have switched since their rows were searched and were quiet, or have a quiet
    // centre within their reach, and those quiet centres: their rows are due (the quiet rows lack
    // the switched nodes' pairs, and are kept whole by the cut while quiet).
    std::vector<NodeIndex> switched_near_quiet_rows(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts) const;
    // `rows` (ascending) join the rows due; then, as choose_rows does, a full search instead
    // where the rows due are many or the candidates have grown by a quarter.
    void add_rows_due(const std::vector<NodeIndex>& rows, std::size_t real);
    void full_search_if_cheaper(std::size_t real);
    void search_candidates(NodeStore& nodes, std::size_t real, GhostSet& ghosts, InfluenceDistance influence_distance,
                           bool any_automatic);
    void check_against_search(const NodeStore& nodes, std::size_t real, const GhostSet& ghosts, InfluenceDistance influence_distance,
                              std::size_t step) const;

    const SolverOptions* solver_;
    CompressedRows lists_;
    bool constant_ = false;
    bool with_skin_ = false;
    bool search_due_ = true;
    bool plan_due_ = false;  // lists searched without a skin need a new scatter plan
    double skin_ = 0.0;
    double searched_range_ = 0.0;  // the bulk's interaction radius at the last search (bulk_interaction_radius)
    std::size_t searches_ = 0;
    NeighbourScratch scratch_;
    CompressedRows candidates_;
    std::vector<std::uint32_t> lattice_entries_;  // per row: how many leading candidates are lattice neighbours
    // Per row: the centre was quiet at the last search (NeighbourScratch::quiet), and whether it
    // was fixed then. A node that has switched since, with a quiet centre within its reach (or
    // quiet itself), makes its row due (switched_near_quiet_rows).
    std::vector<std::uint8_t> quiet_, searched_fixed_;
    bool any_quiet_ = false;
    std::vector<std::uint64_t> keep_scratch_;  // filter_candidates' kept entries, as bits
    // Per row, the position and diameter of its node when the row was last searched (all from
    // one moment after a full search; rows searched alone since take their own moment).
    std::array<std::vector<double>, 3> searched_position_;
    std::vector<double> searched_diameter_;
    bool rows_searched_alone_ = false;  // since the last full search: only the per-row bound holds
    std::size_t row_searches_ = 0, rows_searched_ = 0;
    std::size_t full_search_entries_ = 0;  // the candidates' entries after the last full search
    std::vector<NodeIndex> rows_due_;      // rows to search alone in this step's neighbours phase
    CompressedRows found_;                 // their rows (search_rows)
    ScatterPlan plan_;
    std::vector<double> kept_weight_over_r2_;  // per list entry of the rows [0, kept_rows_)
    std::size_t kept_rows_ = 0;
    bool keep_allowed_ = true;  // the memory limit leaves room for the kept pair terms
};

}  // namespace gpa
