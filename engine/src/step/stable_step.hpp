#pragma once
// A part of the time step (simulation.cpp): the stable time step (spec section 11) and what it
// needs beyond the node fields: the largest bond-viscous pressure Q_ij of each centre's pairs,
// which the force pass of a bond-viscosity scene writes. The rule, the limits on the step's growth
// and length, and the landing on the end time are the scene's solver options, read once. Saves
// and restores those pressures itself, as part of the checkpoint's TIME section (no tag of its
// own): the step after a resume takes the same dt.

#include <cstddef>
#include <vector>

#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

class StableStep {
public:
    // The scene outlives the part (both belong to one Simulation).
    explicit StableStep(const Scene& scene) : scene_(&scene) {}

    // Force pass of a bond-viscosity scene: an array of `nodes` zeros for each centre's largest
    // Q_ij (ForceFields::largest_bond_viscosity).
    double* bond_viscosity(std::size_t nodes);

    // dt^{n+3/2} (spec section 11): C_cfl times the smallest of the real nodes' limits and
    // `element_limit`, at most time_step_growth times `dt_half` (when > 0) and max_time_step, and
    // shortened so as to land on the end time. `closing_speed` (null: none) is each node's largest
    // closing speed across an open interface (separation.hpp). Throws NumericalError, naming the
    // node, when a node's limit is not a number, and when the step is not positive and finite.
    double next(const NodeStore& nodes, std::size_t real, const double* closing_speed, double element_limit, double time,
                double dt_half) const;

    void memory_use(MemoryUse& out) const;
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self);

    const Scene* scene_;
    std::vector<double> largest_bond_q_;  // per centre, the largest Q_ij of its pairs (bond viscosity)
};

}  // namespace gpa
