#pragma once
// A run of a scene: the nodes of its bodies, its planes and ghosts, and the time step as a
// phase graph (spec section 11):
//
//   x^{n+1} = x^n + dt v^{n+1/2}                          move (and penetration guard)
//   [every reorder_interval steps: nodes in cell order]  reorder
//   geometry at x^{n+1}: d, W, ghosts, neighbours, alpha  geometry, neighbours, gradient
//     (a full search only when the candidate lists with a skin may have gone stale)
//   L from v^{n+1/2}; eps_v, V, sigma^{n+1}, e^{n+1}      stress
//   ghost stresses, the scatter plan                      plan
//   dt^{n+3/2} = C_cfl min l / (c + sqrt(Q / rho))        time step
//   F^{n+1} from sigma^{n+1}                              forces
//   v^{n+3/2} = v^{n+1/2} + (dt^{n+1/2} + dt^{n+3/2})/2 F / M   integrate, [smoothing]
//   fixed -> variable above the plastic-strain threshold  [switching]
//
// Element bodies (elements.hpp) take part in the same step with phases of their own, between the
// particle phases of the same name: element move after move, element stress after stress,
// element forces after forces, element integrate after integrate; the time step, the totals and
// the energy booking cover both.
//
// After step() the positions, stresses and energies are those of t^{n+1}; velocities are the
// half step ahead (v^{n+3/2}), and the kinetic energy reported for t^{n+1} is the mean of the two
// half steps around it.

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/phase_graph.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

struct PlaneReport {
    std::string name;
    double reaction = 0.0;  // normal force the plane exerts on the bodies, F^{n+1} of the last step (N; ring total in axisymmetric)
    double impulse = 0.0;   // time integral of the reaction since t = 0 (N s)
};

struct Totals {
    double time = 0.0;
    double time_step = 0.0;  // dt^{n+1/2}, the step that led here
    std::size_t step = 0;
    double kinetic_energy = 0.0;   // J
    double internal_energy = 0.0;  // sum M e, J (includes plastic, viscous and smoothing heat)
    double plastic_work = 0.0;     // sum M w_p, J
    double viscous_work = 0.0;     // work of artificial viscosity (nodal and bond), J
    double boundary_work = 0.0;    // energy removed by velocity constraints, J
    double initial_kinetic_energy = 0.0;  // J
    double initial_energy = 0.0;   // kinetic + internal at t = 0, J
    double energy_error = 0.0;     // (KE + IE + boundary work - E0) / E0
    std::array<double, 3> momentum{0, 0, 0};  // sum M v^{n+3/2}, kg m/s: half a step ahead, like the impulse
                                              // (the axial component is the meaningful one in axisymmetric)
    std::vector<PlaneReport> planes;          // rigid planes, scene order
    // Final length and footprint against the first rigid plane, by the rules of measure.hpp
    // (docs/measurement.md): particles reach d/2 beyond their centres, element nodes lie on the
    // boundary.
    double length = 0.0;              // highest point above the plane, m
    double footprint_diameter = 0.0;  // width of the body on the plane, m
    std::size_t real_nodes = 0, ghost_nodes = 0, variable_nodes = 0, failed_nodes = 0, pairs = 0;
    std::size_t element_nodes = 0, elements = 0;  // nodes and quadrilaterals of element bodies
    std::size_t neighbour_searches = 0;  // full searches so far (the others steps reuse candidate lists)
};

class ElementPart;

class Simulation {
public:
    // Builds the nodes of every body and the phase graph. threads = 0 uses all hardware threads.
    // Throws InputError for an impossible scene.
    explicit Simulation(Scene scene, int threads = 0);
    ~Simulation();
    Simulation(const Simulation&) = delete;
    Simulation& operator=(const Simulation&) = delete;

    void step();
    // True when a stop criterion of the scene is met; stop_reason() says which.
    bool finished() const;
    std::string stop_reason() const;

    const Scene& scene() const;
    const NodeStore& nodes() const;
    std::size_t real_count() const;
    const Totals& totals() const;
    double time() const;
    std::size_t steps() const;
    // The time step the next step() advances by (dt^{n+1/2}; totals().time_step is the last one taken).
    double next_time_step() const;
    int threads() const;
    std::vector<PhaseTime> phase_times() const;
    // The names of the phases in this scene's graph, in order.
    std::vector<std::string> phases() const;
    // Node-steps processed so far (sum over steps of the real particle nodes and the nodes of
    // element bodies).
    double node_steps() const;
    // Element-steps (quadrilaterals times steps) processed so far.
    double element_steps() const;
    // The element bodies (nullptr when the scene has none).
    const ElementPart* elements() const;
    // The neighbour lists of the last step: rows [0, real_count()) of the real nodes, then the
    // rows of the ghosts (indices >= real_count() are ghosts).
    const CompressedRows& neighbour_lists() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gpa
