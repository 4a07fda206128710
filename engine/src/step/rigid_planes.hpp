#pragma once
// A part of the time step (simulation.cpp): the rigid planes of a run (spec section 7). Owns which
// ghost plane each rigid plane of the scene is, the normal force each plane exerted on the particle
// bodies in the last force pass, and the impulse each has given them since t = 0 (the force over
// every velocity update and the momentum the penetration guard took away). Also the penetration
// guard itself, for every plane with ghosts. Saves and restores its reactions and impulses itself,
// as part of the checkpoint's TIME section (no tag of its own).

#include <cstddef>
#include <vector>

#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"
#include "energy_ledger.hpp"

namespace gpa {

class RigidPlanes {
public:
    // Set-up: `rigid` lists the ghost-plane index of each rigid plane of the scene, in scene order.
    void assign(std::vector<std::size_t> rigid);

    std::size_t size() const { return ghost_plane_.size(); }
    // The first rigid plane (the one a Taylor bar stands on, measure.hpp), or null without one.
    const GhostPlane* first(const GhostSet& ghosts) const;

    // After the force pass: each rigid plane's reaction from the forces on its ghosts
    // (GhostSet::normal_reactions).
    void take_reactions(const GhostSet& ghosts, const NodeStore& nodes, std::size_t real);
    // After the velocity update over dt_avg: the reactions' impulse.
    void add_impulses(double dt_avg);

    // Spec section 7, the penetration guard, after the position update: a real node that ends
    // behind a plane is put back just in front of it (by 1 % of its initial diameter) and loses its
    // velocity towards the plane. The kinetic energy taken is booked in the ledger as boundary work,
    // plane by plane; the momentum taken is the rigid plane's impulse. Sums in a fixed order: nothing
    // depends on the thread count.
    void guard_penetration(const GhostSet& ghosts, NodeStore& nodes, std::size_t real, EnergyLedger& ledger);

    // The planes' reports: the particle bodies' reaction and impulse plus those of the element
    // bodies (null without element bodies).
    void report(const GhostSet& ghosts, const std::vector<double>* element_reactions,
                const std::vector<double>* element_impulses, std::vector<PlaneReport>& out) const;

    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    std::vector<std::size_t> ghost_plane_;  // ghost-plane index of each rigid plane
    std::vector<double> reaction_;    // N, the last force pass's
    std::vector<double> impulse_;     // N s, since t = 0
};

}  // namespace gpa
