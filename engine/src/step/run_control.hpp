#pragma once
// A part of the time step (simulation.cpp): run control. The scene's stop criteria (end time, a
// fraction of the initial kinetic energy, a step count), the memory limit the neighbour lists must
// fit in, and the reports of a failed step: the step, time, phase, node, body, position and field
// where it failed (StepFailure, errors.hpp), after an exception in a phase, a time step that no
// longer advances the time, or the energy guard (stop.energy_error). It keeps no state of its own
// between steps, so it has no checkpoint section.

#include <cstddef>
#include <exception>
#include <string>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"

namespace gpa {

class RunControl {
public:
    // The scene outlives the part (both belong to one Simulation).
    RunControl(const Scene& scene, MemoryLimit memory) : scene_(&scene), memory_(std::move(memory)) {}

    // Whether the run has met a stop criterion at `time` after `steps` steps; `reason` says which.
    bool finished(double time, std::size_t steps, const Totals& totals, std::string& reason) const;

    // Throws LimitError when neighbour lists of `entries` pairs would not fit with the nodes in
    // the memory limit (checked before a search allocates them). Returns whether the terms kept per
    // pair (bytes_per_kept_pair) fit as well.
    bool check_list_memory(const NodeStore& nodes, std::size_t real, std::size_t entries) const;

    // The report of a phase that threw `e` during step steps + 1: the node the error names, else
    // the first real node with a value that is not a number.
    StepFailure step_failure(const std::exception& e, const std::string& phase, std::size_t steps, double time,
                             const NodeStore& nodes, std::size_t real) const;

    // After a step: throws StepFailure when the time did not advance past `time_before`, or when
    // the energy error exceeds stop.energy_error (naming the fastest node, where an instability
    // puts the energy it makes).
    void check_step(double time_before, double time, double dt_half, std::size_t steps, const Totals& totals,
                    const NodeStore& nodes, std::size_t real) const;

private:
    const Scene* scene_;
    MemoryLimit memory_;
};

}  // namespace gpa
