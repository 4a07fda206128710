#pragma once
// A part of the time step (simulation.cpp): measurement. The sums over the nodes that the totals
// report (energies, momentum, counts, the body's extent on the first rigid plane: measure.hpp), the
// per-body totals, the local peaks and face roughness, and what they carry from step to step: the
// kinetic energy of the last half step (the kinetic energy at t^n is the mean of the two half steps
// around it, spec section 11), per body too, and the impact frame of the initial state. Saves and
// restores the half-step energies as its own checkpoint section.

#include <array>
#include <cstddef>
#include <vector>

#include "gpa/engine/body_report.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

// The sums of one pass over the real particle nodes.
struct NodeSums {
    double kinetic = 0.0, internal = 0.0, plastic = 0.0, viscous = 0.0;
    std::array<double, 3> momentum{0, 0, 0};
    measure::Extent extent;  // on the first rigid plane, if there is one
    std::size_t variable = 0, failed = 0;

    NodeSums& operator+=(const NodeSums& o);
};

class Measures {
public:
    // Set-up, from the initial state: the impact frame (body_report.hpp) and a half-step kinetic
    // energy per body.
    void set_up(const Scene& scene, const NodeStore& nodes, std::size_t real);
    const ImpactFrame& impact() const { return impact_; }

    // The sums over the real nodes in a fixed order (deterministic on any thread count), with the
    // extent on `plane` (null: none).
    NodeSums node_sums(const NodeStore& nodes, std::size_t real, const GhostPlane* plane, bool axisymmetric) const;
    // The extent of the particles, heights measured from `base` above the plane (measure.hpp).
    measure::Extent particle_extent(const NodeStore& nodes, std::size_t real, const GhostPlane& plane, bool axisymmetric,
                                    double base) const;
    // The element rule of measure.hpp: element nodes lie on the boundary (no d/2).
    static measure::Extent element_extent(const ElementMesh& mesh, const GhostPlane& plane, bool axisymmetric, double base = 0.0);

    // The kinetic energy at t^n from that of the half step now ahead (all bodies): the mean of
    // the two half steps; the half step now ahead is kept for the next call.
    double advance_kinetic(double half_step_now);
    double half_step_kinetic() const { return kinetic_half_; }
    // A velocity set between steps (Simulation::set_velocity) changed the kinetic energy of the
    // half step ahead by `change` in `body`: the mean the next step reports starts from it.
    void add_to_half_step_kinetic(std::size_t body, double change) {
        kinetic_half_ += change;
        if (body < body_kinetic_half_.size()) body_kinetic_half_[body] += change;
    }
    const std::vector<double>& body_half_step_kinetic() const { return body_kinetic_half_; }

    // Per body, the sums of node_sums (one reduction with a slot per body; bodies are few). A
    // scene of one body takes `particle_sums` instead of a second pass over the nodes. With
    // `advance_kinetic` each body's kinetic energy is the mean of its two half steps (as above).
    void body_totals(const Scene& scene, const NodeStore& nodes, std::size_t real, bool advance_kinetic,
                     const NodeSums* particle_sums, std::vector<BodyTotals>& bodies);

    // Local peaks over a neighbourhood of the scene's peak radius (else two spacings of the first
    // body) for particle nodes and element triangles, and the face roughness over the points on
    // the body's base (measure.hpp); nothing measured without a radius.
    void local_fields(const Scene& scene, const NodeStore& nodes, std::size_t real, const GhostPlane* plane,
                      const ElementPart* elements, double base_height, Totals::LocalFields& out) const;

    void write_state(StateWriter& out) const;
    void read_state(StateReader& in, std::size_t bodies);

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self);

    // The symmetry planes bodies reach (set_up), and of them those that stand on `plane`, one per
    // axis: a node's images across them belong to the body's extent (measure.hpp).
    std::vector<GhostPlane> mirrors_on(const GhostPlane& plane) const;

    std::vector<GhostPlane> width_mirrors_;
    ImpactFrame impact_;
    double kinetic_half_ = 0.0;              // kinetic energy of the current half-step velocities
    std::vector<double> body_kinetic_half_;  // per body, the same
};

}  // namespace gpa
