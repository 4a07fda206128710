#pragma once
// A part of the time step (simulation.cpp): the rigid planes of a run (spec section 7). Owns which
// ghost plane each rigid plane of the scene is, the normal force each plane exerted on the particle
// bodies in the last force pass, and the impulse each has given them since t = 0 (the force over
// every velocity update and the momentum the penetration guard took away). Also the penetration
// guard itself, for every plane with ghosts. Saves and restores its reactions and impulses itself,
// as part of the checkpoint's TIME section (no tag of its own).

#include <array>
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
    // Set-up: `rigid` lists the ghost-plane index of each rigid plane of the scene, in scene order;
    // `friction` each one's Coulomb coefficients {static, dynamic} (PlaneSpec), in the same order.
    void assign(std::vector<std::size_t> rigid, std::vector<std::array<double, 2>> friction);
    bool has_friction() const { return with_friction_; }

    std::size_t size() const { return ghost_plane_.size(); }
    // The first rigid plane (the one a Taylor bar stands on, measure.hpp), or null without one.
    const GhostPlane* first(const GhostSet& ghosts) const;

    // After the force pass: each rigid plane's reaction from the forces on its ghosts
    // (GhostSet::normal_reactions).
    void take_reactions(const GhostSet& ghosts, const NodeStore& nodes, std::size_t real);
    // After the velocity update over dt_avg: the reactions' impulse.
    void add_impulses(double dt_avg);

    // Coulomb friction of the rigid planes (PlaneSpec::friction_static, friction_dynamic), after the
    // force pass and before the velocity update over dt_avg. The push N of a plane on a real node is
    // read from the node's ghost across that plane alone (ghosts.hpp): the force on the ghost is the
    // mirror image of the force the node's pairs with ghosts exert on it, so N = -side F_ghost,axis
    // (GhostSet::normal_reactions sums the same over the ghosts); only N > 0 (a push) makes friction.
    // With v_t the node's tangential velocity, F_t the tangential force on it and
    // w = v_t + dt_avg F_t / M the tangential velocity the update would give, the friction force is
    //   -M w / dt_avg                 when M |w| / dt_avg <= mu_s N  (the node sticks: w -> 0),
    //   -mu_d N w / |w|               otherwise (it slides, against the friction of sliding),
    // added to the node's force. Held nodes (prescribed.hpp) and corner ghosts take no part.
    void apply_friction(const GhostSet& ghosts, NodeStore& nodes, std::size_t real, double dt_avg);
    // After the velocity update: each friction force's work over it, F . (v^{n+1/2} + v^{n+3/2}) / 2
    // dt_avg (exactly the kinetic energy it took, <= 0 when it opposed the motion), becomes heat of
    // its node (internal energy) and is summed per plane (PlaneReport::friction_work).
    void book_friction(NodeStore& nodes, double dt_avg);

    // Spec section 7, the penetration guard, after the position update: a real node that ends
    // behind a rigid plane or the axis is put back just in front of it (by 1 % of its initial
    // diameter) and loses its velocity towards the plane (not behind a symmetry plane of the scene:
    // see the definition). The kinetic energy taken is booked in the ledger as boundary work,
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
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self);

    struct FrictionForce {
        NodeIndex node;
        std::size_t plane;                // index among the rigid planes
        std::array<double, 3> force;      // on the node, N
        std::array<double, 3> velocity;   // v^{n+1/2} of the node, before the update
    };
    std::vector<std::size_t> ghost_plane_;  // ghost-plane index of each rigid plane
    std::vector<std::array<double, 2>> friction_;  // {mu_s, mu_d} of each rigid plane
    bool with_friction_ = false;
    std::vector<FrictionForce> friction_forces_;  // this step's (apply_friction to book_friction)
    std::vector<double> friction_work_;  // J, since t = 0, per rigid plane
    std::vector<double> pressing_impulse_;  // N s, since t = 0, per rigid plane with friction
    std::vector<double> reaction_;    // N, the last force pass's
    std::vector<double> impulse_;     // N s, since t = 0
};

}  // namespace gpa
