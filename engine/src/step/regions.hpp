#pragma once
// A part of the time step (simulation.cpp): the prescribed-velocity regions of a run. Owns which
// particle and element nodes each region holds (prescribed.hpp, HeldNodes), and what each region
// has done since t = 0: the work of its constraint, its impulse, the displacement of its nodes and
// the last step's reaction. Saves and restores that as its own checkpoint section.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpa/engine/node_store.hpp"
#include "gpa/engine/prescribed.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

struct ElementNodes;

class Regions {
public:
    // The scene's regions; the scene outlives the part (both belong to one Simulation).
    explicit Regions(const std::vector<PrescribedVelocitySpec>& specs) : specs_(&specs) {}

    bool empty() const { return specs_->empty(); }

    // Set-up: every node of a region's body inside it at t = 0 (scene.hpp; validate_scene has
    // checked that each region holds nodes and that no two share one) is held, at the velocity
    // prescribed at t = 0. Particle nodes are marked in nodes.velocity_region (a node field, so that
    // it follows reordering); element nodes are indexed here. Throws InputError for a region that
    // names an unknown body or holds no node, and for two regions sharing a node.
    void assign(const Scene& scene, NodeStore& nodes, std::size_t real, ElementNodes* element_nodes);

    // The held particle nodes by region, and their held components per node (smoothing), in the
    // current node numbering: after the set-up, every reordering and a restore.
    void index(const NodeStore& nodes, std::size_t real);

    HeldNodes& particles() { return held_particles_; }
    const HeldNodes& particles() const { return held_particles_; }
    HeldNodes& elements() { return held_elements_; }
    // Per real node: the components its region holds (bit c), for smoothing; null without regions.
    const std::uint8_t* held_bits() const { return held_bits_.empty() ? nullptr : held_bits_.data(); }

    // One step's constraint (HeldNodes::impose): its work and, over dt_avg, its impulse.
    void book(const std::vector<RegionStep>& step, double dt_avg);
    // The held nodes move with v^{n+1/2}, the velocity the last constraint set (at t + dt / 2).
    void advance_displacements(int dim, double dt);
    // The momentum that smoothing would have moved into held components (and that the free nodes
    // got instead) comes from the regions (smoothing.hpp): total_change holds each node's velocity
    // change, dim per node.
    void book_smoothing(int dim, const double* mass, const std::vector<double>& total_change);

    // The regions' reports at `time`, and the work counted in the energy balance: the work up to
    // the last velocity update when the balance takes the kinetic energy of the half step ahead
    // (at_half_step), else half of the last update's work is not yet done at t (none at t = 0).
    double report(double time, bool at_half_step, bool at_start, std::vector<RegionReport>& out) const;

    void write_state(StateWriter& out) const;
    // Reads the section back; then, once the nodes are restored, `index` and `check_restored`.
    void read_state(StateReader& in);
    // A restored run holds the same count of nodes in each region as the scene's set-up did.
    void check_restored(StateReader& in, const NodeStore& nodes, std::size_t real);

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self);

    const std::vector<PrescribedVelocitySpec>* specs_;
    // A scene is all particles or all elements, so one of the two sets of held nodes is empty.
    HeldNodes held_particles_, held_elements_;
    std::vector<std::uint8_t> held_bits_;
    // Per region: the nodes it holds, the work of its constraint through v^{n+3/2}, the last step's
    // reaction and work, the impulse given since t = 0 and the displacement of its nodes.
    std::vector<std::size_t> node_count_;
    std::vector<double> work_;
    std::vector<RegionStep> last_;
    std::vector<std::array<double, 3>> impulse_, displacement_;
};

}  // namespace gpa
