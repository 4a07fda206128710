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
//   v^{n+3/2} = v^{n+1/2} + (dt^{n+1/2} + dt^{n+3/2})/2 F / M   integrate, then the held components of
//     prescribed-velocity regions set (prescribed.hpp), [smoothing] (held components left alone)
//   lattice cells checked; fixed -> variable above the    [switching]
//     plastic-strain threshold or where a cell collapsed
//
// Element bodies (elements.hpp) take part in the same step with phases of their own, between the
// particle phases of the same name: element move after move, element stress after stress,
// element forces after forces, element integrate after integrate; the time step, the totals and
// the energy booking cover both.
//
// After step() the positions, stresses and energies are those of t^{n+1}; velocities are the
// half step ahead (v^{n+3/2}), and the kinetic energy reported for t^{n+1} is the mean of the two
// half steps around it.

#include <array>
#include <cstddef>
#include <cstdint>
#include <istream>
#include <memory>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/body_report.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/phase_graph.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/memory_use.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

struct PlaneReport {
    std::string name;
    double reaction = 0.0;  // normal force the plane exerts on the bodies, F^{n+1} of the last step (N; ring total in axisymmetric)
    double impulse = 0.0;   // time integral of the reaction since t = 0 (N s)
    bool friction = false;  // the plane has Coulomb friction (PlaneSpec::friction_static or friction_dynamic > 0)
    double friction_work = 0.0;  // heat its friction has made since t = 0, J (>= 0; in the bodies' internal energy)
    // The part of `impulse` that pressed nodes against it, since t = 0 (N s): the sum over nodes of
    // their push where it was one (impulse also counts the pull of nodes in tension on a plane they
    // touch). Friction takes at most mu_s of it, exactly mu_d of it where every node slid.
    double pressing_impulse = 0.0;
};

// A prescribed-velocity region (scene.hpp, PrescribedVelocitySpec; prescribed.hpp). Reaction and
// impulse are ring totals in axisymmetric geometry, like a plane's; components that the region
// leaves free read 0.
struct RegionReport {
    std::string name;
    std::array<bool, 3> held{false, false, false};  // the components it prescribes
    std::size_t nodes = 0;                          // nodes it holds
    std::array<double, 3> velocity{0, 0, 0};        // the prescribed velocity at this time, m/s
    std::array<double, 3> displacement{0, 0, 0};    // of its nodes since t = 0 along the held components, m
    // The force its nodes need to follow the prescribed motion, M a_prescribed - F_internal summed
    // over them, of the last step (F^{n+1}: the reaction that takes v^{n+1/2} to v^{n+3/2}), N.
    std::array<double, 3> reaction{0, 0, 0};
    // The momentum it has given the bodies since t = 0, half a step ahead like Totals::momentum:
    // the time integral of the reaction, plus what velocity smoothing moved across its boundary
    // (smoothing.hpp), N s.
    std::array<double, 3> impulse{0, 0, 0};
    // The work it has done on the bodies since t = 0 (the time integral of reaction . velocity,
    // prescribed.hpp), J, up to the instant of the energy balance's kinetic energy: through the
    // last velocity update (half a step ahead, like the impulse) with the compatible energy update
    // of particle bodies, up to t^{n+1} otherwise. The balance books it as boundary work of the
    // opposite sign.
    double work = 0.0;
};

struct Totals {
    double time = 0.0;
    double time_step = 0.0;  // dt^{n+1/2}, the step that led here
    std::size_t step = 0;
    double kinetic_energy = 0.0;   // J
    double internal_energy = 0.0;  // sum M e, J (includes plastic, viscous and smoothing heat)
    double plastic_work = 0.0;     // sum M w_p, J
    double viscous_work = 0.0;     // work of artificial viscosity (nodal, bond and hourglass control), J
    double hourglass_work = 0.0;   // the part of viscous_work done by the hourglass damping (solver.hourglass_nodes), J
    double hourglass_energy = 0.0; // the part of internal_energy put in by the hourglass stiffness (solver.hourglass_stiffness), J
    double boundary_work = 0.0;    // energy removed by velocity constraints (less the work of prescribed velocities
                                   // and of a program's external forces and set velocities), J
    // The work a program embedding the run has done on the bodies since t = 0 through
    // Simulation::apply_force and set_velocity (at the instant of the balance's kinetic energy, as
    // for the regions' work), J; part of boundary_work with the opposite sign.
    double external_work = 0.0;
    double initial_kinetic_energy = 0.0;  // J
    double initial_energy = 0.0;   // kinetic + internal at t = 0, J
    // The energy the run was given: E0, plus the work of the prescribed velocities when they
    // have put energy in (a bar pulled from rest has E0 = 0), J.
    double energy_given = 0.0;
    double energy_error = 0.0;     // (KE + IE + boundary work - E0) / energy_given
    std::array<double, 3> momentum{0, 0, 0};  // sum M v^{n+3/2}, kg m/s: half a step ahead, like the impulse
                                              // (the axial component is the meaningful one in axisymmetric)
    std::vector<PlaneReport> planes;          // rigid planes, scene order
    std::vector<RegionReport> regions;        // prescribed-velocity regions, scene order
    // Every body of the scene, scene order (element bodies carry zeros): energies and momentum every
    // step; pieces, residual velocity and crater (body_report.hpp) as of the last measure_bodies().
    std::vector<BodyTotals> bodies;
    // Final length and footprint against the first rigid plane, by the rules of measure.hpp
    // (docs/measurement.md): particles reach d/2 beyond their centres, element nodes lie on the
    // boundary.
    double length = 0.0;              // highest point above the base, m
    double footprint_diameter = 0.0;  // width of the body on its base, m (3D: the mean over directions)
    // 3D: the narrowest and widest of the widths the footprint is the mean of (measure.hpp); in 2D
    // both are the footprint.
    double footprint_narrowest = 0.0;
    double footprint_widest = 0.0;
    double base_height = 0.0;         // the base above the plane: 0 while the body stands on it, m
    // Local peaks (measure.hpp, docs/measurement.md): equivalent plastic strain and temperature,
    // each the largest mean over a neighbourhood of `local_radius`, with where it is and the largest
    // value at a single point; the roughness of the plastic strain along the impact face. Measured by
    // Simulation::measure_bodies(), not every step.
    struct LocalFields {
        bool measured = false;
        double radius = 0.0;                     // m
        measure::LocalPeak plastic_strain;
        measure::LocalPeak temperature;          // K
        double face_roughness = 0.0;             // of the plastic strain (measure::face_roughness)
        std::size_t face_points = 0;             // points on the face it was measured over
    } local;
    std::size_t real_nodes = 0, ghost_nodes = 0, variable_nodes = 0, failed_nodes = 0, pairs = 0;
    std::size_t element_nodes = 0, elements = 0;  // nodes and quadrilaterals of element bodies
    std::size_t neighbour_searches = 0;  // full searches so far (the others steps reuse candidate lists)
    // Searches of the rows of the nodes that had moved, alone, and the rows they searched.
    std::size_t row_searches = 0, rows_searched = 0;
    // Fixed nodes of automatic bodies that the last step switched because a lattice cell had
    // collapsed or inverted (before their plastic strain reached the threshold), and the first of them.
    std::size_t collapse_switches = 0;
    std::string first_collapse_switch;
};

// What a checkpoint file says about itself (Simulation::checkpoint_info).
struct CheckpointInfo {
    std::uint32_t format = 0;
    std::string build;              // build_id() of the program that wrote it
    std::string scene_fingerprint;  // as given to save_checkpoint
    std::string scene_name;
    std::size_t step = 0;
    double time = 0.0;
    std::string user_data;
};

class ElementPart;

class Simulation {
public:
    // Builds the nodes of every body and the phase graph. threads = 0 uses all hardware threads.
    // Throws InputError for an impossible scene, LimitError when its nodes would not fit in the
    // memory limit (checked before they are made; the neighbour lists are checked against it
    // before every search allocates them).
    explicit Simulation(Scene scene, int threads = 0, MemoryLimit memory = {});
    ~Simulation();
    Simulation(const Simulation&) = delete;
    Simulation& operator=(const Simulation&) = delete;

    // Advances one step. A failing step throws StepFailure (step, time, phase, node, body,
    // position, field and cause in one line), and so does a step after which the energy error
    // exceeds stop.energy_error (the energy guard) or the time no longer advances; after a
    // failure no further step runs.
    void step();
    // True when a stop criterion of the scene is met; stop_reason() says which.
    bool finished() const;
    std::string stop_reason() const;

    const Scene& scene() const;
    const NodeStore& nodes() const;
    std::size_t real_count() const;
    const Totals& totals() const;
    // Measures the bodies' pieces, residual velocities and craters (body_report.hpp) from the
    // current state into totals().bodies, and the local peaks into totals().local; the run program
    // calls it before every history row and the summary (a union-find over the lists and a
    // neighbourhood sum per point, too much to do every step).
    void measure_bodies();
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
    // The bytes the run's arrays take now, array by array (memory_use.hpp): node fields, neighbour
    // lists and their caches, ghosts, and the scratch of each part of the step (particle bodies;
    // element bodies are not counted yet).
    MemoryUse memory_use() const;

    // --- between steps: what a program that embeds gpa may do (docs/api.md) -------------------
    // Particle nodes are addressed by id (NodeStore::id: 0, 1, ... in the order the scene's particle
    // bodies were filled, fixed for the run), since their indices change when they are reordered.
    // Vectors have the nodes' components: x, y, z in 3D; x (the radius in axisymmetric) and z in
    // 2D, with the third entry 0. In axisymmetric scenes forces are ring totals, as the reactions
    // are. Every call throws InputError with a message naming what is wrong (an id no particle
    // node has, a vector that is not finite or has a third component in 2D, a held component).

    // The index in nodes() of the particle node with this id now (valid until the next step).
    std::size_t index_of(std::uint64_t id) const;
    // Adds an external force (N) to the node for the next step only: it joins the internal forces
    // in that step's velocity update. Its work, dt_avg F . (v^{n+1/2} + v^{n+3/2}) / 2, is booked
    // (Totals::external_work) and the energy balance stays closed.
    void apply_force(std::uint64_t id, const std::array<double, 3>& force);
    // Sets the node's velocity (the half step ahead, v^{n+3/2}, with which the next step moves
    // it); the change of its kinetic energy is booked as external work. A component held by a
    // prescribed-velocity region must keep its value (set_region_velocity changes it).
    void set_velocity(std::uint64_t id, const std::array<double, 3>& velocity);
    // The region holds its components at this velocity from now on (m/s; its ramp is over): the
    // next step's velocity update gives the held nodes this velocity, and they move with it from
    // the step after (the next step moves them with the velocity already imposed). Components the
    // region leaves free must be 0. Its reaction, displacement and work are reported in
    // Totals::regions as before.
    void set_region_velocity(std::string_view name, const std::array<double, 3>& velocity);

    // --- checkpoints --------------------------------------------------------------------------
    // Writes everything later steps depend on (every node field, the ghosts, the neighbour lists
    // and their candidates with the positions and diameters of the last search, the scatter
    // plan, both time steps, the half-step kinetic energy, impulses, boundary work, the bookings
    // of the prescribed velocities, counters, totals and phase times), so that a Simulation built
    // from the same scene and restored from it continues bit-identically to one never stopped, on
    // any thread count. The file is versioned and carries build_id(), `scene_fingerprint` (what
    // identifies the scene to the caller, e.g. a hash of its file) and `user_data` (anything the
    // caller wants back).
    void save_checkpoint(std::ostream& out, std::string_view scene_fingerprint, std::string_view user_data = {}) const;
    // Where each field of save_checkpoint's output begins (bytes from the file's start; each
    // section's tag is one), so that two checkpoints can be compared field by field.
    std::vector<std::uint64_t> checkpoint_field_starts(std::string_view scene_fingerprint, std::string_view user_data = {}) const;
    // Every scene can be checkpointed, element bodies included (format 5); kept for programs
    // written against earlier versions, where element scenes could not.
    bool can_checkpoint() const;
    // Restores a checkpoint of `size` bytes (`source` names it in messages) into a Simulation
    // built from the same scene; returns its user_data. Throws CheckpointError, before changing
    // anything, when the format, the build or the scene fingerprint differ; for a damaged file
    // (it throws too) the Simulation is left unusable.
    std::string restore_checkpoint(std::istream& in, std::uint64_t size, const std::string& source,
                                   std::string_view scene_fingerprint);
    // Reads the header of a checkpoint (no Simulation needed). Throws CheckpointError.
    static CheckpointInfo checkpoint_info(std::istream& in, std::uint64_t size, const std::string& source);
    // The format version save_checkpoint writes.
    // 4: a section per part of the step; 5: element bodies; 6: B of 3D nodes; 7: external loads;
    // 8: the ghosts' table per source (GhostSet)
    static constexpr std::uint32_t checkpoint_format = 8;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gpa
