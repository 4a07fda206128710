#pragma once
// A part of the time step (simulation.cpp): what a program that embeds gpa does to a run between
// steps (simulation.hpp, "Between steps"; docs/api.md). Owns
//   * the nodes' ids and where each is now (nodes are reordered during a run; NodeStore::id),
//   * external forces on particle nodes, waiting for the next velocity update, and
//   * the work those forces and set velocities have done on the bodies since t = 0,
// and saves and restores them, with the prescribed regions' velocities as the program last set
// them, as its own checkpoint section.
//
// An external force F acts in one velocity update, with the internal forces:
//   v^{n+3/2} = v^{n+1/2} + dt_avg (F_int + F) / M,
// and its work is taken in the leapfrog's own form, as a region's is (prescribed.hpp):
//   dW = dt_avg F . (v^{n+1/2} + v^{n+3/2}) / 2,
// which, with the internal forces' work, is exactly the node's change of half-step kinetic energy.
// A velocity set between steps changes the half-step kinetic energy by M (|v_new|^2 - |v_old|^2) / 2,
// booked as work done on the bodies at once. The energy balance books both as boundary work of the
// opposite sign (Totals::boundary_work, external_work).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <vector>

#include "gpa/engine/memory_use.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

class ExternalLoads {
public:
    // Where each id is: a map made at the first look-up after the set-up, a reorder or a restore
    // (forget_ids, from the step's thread), so that a run no program looks into carries none (4
    // bytes per node). The ids of the real nodes are 0 ... real - 1, each once (check_ids: false
    // when they are not).
    static bool check_ids(const NodeStore& nodes, std::size_t real);
    void forget_ids() {
        std::vector<std::uint32_t>().swap(index_of_id_);
        mapped_.store(false, std::memory_order_relaxed);
    }
    // The index of the real node with this id now, of `nodes` with `real` real nodes (the run's).
    // Throws InputError for an id no real node has. Several threads may call it at once between
    // steps (docs/api.md): the first makes the map, under a lock, and the others wait for it.
    std::size_t index_of(const NodeStore& nodes, std::size_t real, std::uint64_t id) const;

    // Adds F to the node's external force in the next velocity update (forces on one node add up).
    void add_force(std::uint32_t id, const std::array<double, 3>& force);
    bool forces_pending() const { return !pending_.empty(); }

    // In the velocity update, before it: the forces join the nodes' forces, and v^{n+1/2} of their
    // nodes is kept. After it (and the prescribed components): their work; then they are cleared.
    void add_to_forces(NodeStore& nodes, std::size_t real);
    void book(const NodeStore& nodes, double dt_avg);

    // Work done on the bodies outside the step (a velocity set between steps), J.
    void add_work(double work) { work_ += work; }
    // The work of external forces and set velocities since t = 0, at the instant of the energy
    // balance's kinetic energy (the regions' rule, Regions::report): all of it when the balance
    // takes the half step ahead, otherwise less half of the last update's force work.
    double work(bool at_half_step) const { return at_half_step ? work_ : work_ - 0.5 * last_force_work_; }

    // The section also holds each region's velocity and ramp, which a program may have changed
    // (Simulation::set_region_velocity); read_state puts them back into `regions`.
    void memory_use(MemoryUse& out) const;

    void write_state(StateWriter& out, const std::vector<PrescribedVelocitySpec>& regions) const;
    // The loads' ids are checked against `real` (the scene's node count); counts against what is
    // left of the file.
    void read_state(StateReader& in, std::vector<PrescribedVelocitySpec>& regions, std::size_t real);

private:
    // The checkpoint's fields, listed once for both directions (Self and Regions const when
    // writing; `real` bounds the loads' ids when reading).
    template <class IO, class Self, class Regions>
    static void state_fields(IO& io, Self& self, Regions& regions, std::size_t real);

    struct Load {
        std::uint32_t id = 0;
        std::array<double, 3> force{0, 0, 0};
    };
    std::vector<Load> pending_;                    // in the order they were given, one per id
    std::vector<std::size_t> applied_to_;          // the node of each pending load, during the update
    std::vector<std::array<double, 3>> half_step_; // its v^{n+1/2}
    mutable std::vector<std::uint32_t> index_of_id_;  // id -> index of a real node; empty until a look-up
    mutable std::atomic<bool> mapped_{false};         // index_of_id_ is made
    mutable std::mutex map_mutex_;
    double work_ = 0.0, last_force_work_ = 0.0;
};

}  // namespace gpa
