#pragma once
// Explicit Lagrangian finite elements in the same engine as the particles: the paper's Fig. 1,
// where a Lagrangian code is one loop for elements and particles and only the strain rates and
// nodal forces differ. Element bodies share the materials, the material point update
// (stress.hpp), the time step rule, the leapfrog integration, the energy booking and the outputs
// with particle bodies. docs/elements.md is the formulation:
//
//   * 2D axisymmetric or plane strain; each quadrilateral of the body's mesh is split by its
//     diagonals into four constant-strain triangles around a centre node (EPIC's crossed
//     triangles), with mean dilatation over the quadrilateral (the volumetric strain rate and so
//     the density are the quadrilateral's; each triangle keeps its own deviator);
//   * lumped (row-sum) nodal masses, volume-weighted in axisymmetric geometry;
//   * an artificial viscosity of the nodal viscosity's linear and quadratic form (Eq. 36) from the
//     quadrilateral's volumetric rate and its width;
//   * nodes on the axis held at x = 0; nodes on a symmetry plane held on it; frictionless
//     node-on-plane contact with rigid planes, with or without lift-off;
//   * forces assembled without atomics, quadrilaterals coloured so that two of one colour share no
//     node, so results are bit-identical on any thread count.
//
// One step, in the order of the phase graph (simulation.hpp):
//   move:       x^{n+1} = x^n + dt v^{n+1/2}
//   stress:     L from v^{n+1/2} on the mid-step geometry, rho^{n+1} = M_q / V_q(x^{n+1}),
//               Q, the material point update to sigma^{n+1}; an inverted element stops the run
//   time step:  dt^{n+3/2} <= C_cfl l / (zeta + sqrt(zeta^2 + c^2)) (stable_time_step)
//   forces:     F^{n+1} from sigma^{n+1} on x^{n+1}
//   integrate:  v^{n+3/2} = v^{n+1/2} + dt_avg F / M, then the axis, symmetry planes and contact

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/engine/state_io.hpp"

namespace gpa {

// The nodes of element bodies, structure of arrays (2D: components x, z).
struct ElementNodes {
    std::array<std::vector<double>, 2> position;  // m
    std::array<std::vector<double>, 2> velocity;  // m/s, the half step ahead after a step (v^{n+3/2})
    std::array<std::vector<double>, 2> force;     // F^{n+1}, N (a ring's force in axisymmetric geometry)
    std::vector<double> mass;                     // lumped, kg (a ring's mass in axisymmetric geometry)
    std::vector<std::int32_t> body;
    std::vector<std::uint8_t> on_axis;  // 1: held at x = 0 (axisymmetric)
    std::vector<std::uint8_t> held;     // bit k: held on plane k of the scene (symmetry, or no-lift-off contact)
    std::vector<std::uint8_t> contact;  // bit k: on rigid plane k of the scene after the last step

    std::size_t size() const { return mass.size(); }
    void resize(std::size_t n);
};

// The quadrilaterals: corners 0..3 counter-clockwise, then the centre node (where the diagonals
// cross). Triangle 4q + k is (centre, corner k, corner (k + 1) mod 4) of quadrilateral q.
struct ElementQuads {
    std::vector<std::array<NodeIndex, 5>> nodes;
    std::vector<std::int32_t> body;
    std::vector<std::int32_t> material;
    std::vector<double> mass;     // M_q = sum of its triangles' masses, kg
    std::vector<double> volume;   // V_q at the last completed step (geometric), m^3
    std::vector<double> length;   // stable length l (element_kernels.hpp E8), m
    std::vector<double> rate;     // volumetric strain rate of the last step (E7; the most compressive
                                  // of its triangles without mean dilatation), 1/s

    std::size_t size() const { return nodes.size(); }
};

// The material points: one per triangle, the same state as a particle node's. Stress in the 2D
// order of geometry.hpp (xx, zz, xz, out-of-plane).
struct ElementPoints {
    std::array<std::vector<double>, 4> deviatoric_stress;  // Pa
    std::vector<double> pressure;          // from the equation of state, Pa
    std::vector<double> viscous_pressure;  // artificial viscosity Q, Pa
    std::vector<double> sound_speed;       // m/s
    std::vector<double> internal_energy;   // specific, J/kg
    std::vector<double> temperature;       // K
    std::vector<double> plastic_strain;
    std::vector<double> plastic_strain_rate;  // d eps_p / dt of the last step, 1/s (materials::PointState)
    std::vector<double> damage;
    std::vector<double> plastic_work;      // accumulated specific, J/kg
    std::vector<double> viscous_work;      // accumulated specific, J/kg
    std::vector<std::uint8_t> failed;
    std::vector<double> mass;              // rho0 V0 of the triangle, kg
    std::vector<double> density;           // current, kg/m^3 (the quadrilateral's with mean dilatation)
    std::vector<double> volume;            // current geometric volume, m^3
    // The velocity gradient of the last step: L_xx, L_xz, L_zx, L_zz and the hoop rate (1/s).
    std::array<std::vector<double>, 5> velocity_gradient;

    std::size_t size() const { return mass.size(); }
    void resize(std::size_t n);
};

// Everything that describes the element bodies at one time: a value, copied for snapshots.
struct ElementMesh {
    GeometryKind geometry = GeometryKind::Axisymmetric;
    ElementNodes nodes;
    ElementQuads quads;
    ElementPoints points;
    // Edges on the boundary of each body's mesh (pairs of corner nodes, the body on their left).
    std::vector<std::array<NodeIndex, 2>> boundary_edges;
    std::vector<double> body_spacing;  // the mesh spacing of each scene body (0 for particle bodies), m

    std::size_t triangles() const { return points.size(); }
};

// Builds the mesh of the scene's bodies with discretisation = Elements (the others are left out):
// the cells of each body's lattice (bodies.hpp: body_lattice, the same shape at the same spacing)
// become quadrilaterals with nodes at their corners and centres, with velocity, initial stress and
// masses set. Throws InputError for a body that is not 2D or holds no cell.
ElementMesh mesh_element_bodies(const Scene& scene);

// Sets the state of an unloaded mesh from its node positions, as mesh_element_bodies does: the
// triangles' masses rho V (rho from each body's material and initial mean stress), their initial
// stress, pressure, sound speed and temperature, the lumped nodal masses (E4), and each
// quadrilateral's mass, volume and stable length. For meshes built or moved by hand (the node
// positions, velocities, bodies, materials, quadrilaterals and on_axis set). Throws InputError
// naming the element when a triangle has no positive area.
void initialise_element_state(ElementMesh& mesh, const Scene& scene);

struct ElementOptions {
    bool mean_dilatation = true;  // false: each triangle's own volumetric rate (for the locking study)
    bool viscosity = true;        // the artificial viscosity of E9 with the solver's C_L, C_Q
    double viscosity_linear = 0.2;
    double viscosity_quadratic = 4.0;
    bool failure = false;         // the materials' failure models
    ScatterScheme scatter = ScatterScheme::Graph;  // Serial: one group (the serial twin of the assembly)
};

// The options a scene gives its element bodies (its viscosity and failure settings).
ElementOptions element_options(const Scene& scene);

// The element part of a run: the mesh and its phases.
class ElementPart {
public:
    ElementPart(const Scene& scene, ElementMesh mesh, ElementOptions options);
    ~ElementPart();
    ElementPart(const ElementPart&) = delete;
    ElementPart& operator=(const ElementPart&) = delete;

    // x += dt v.
    void move(double dt);
    // Strain rates, densities, viscosity and the material point update over dt (the step that
    // led to the current positions). `step` and `time` name the step in errors: an inverted
    // element or a failed material update throws NumericalError naming the element, its nodes,
    // the step and what to do.
    void update_stress(double dt, std::size_t step, double time);
    // The smallest l / (zeta + sqrt(zeta^2 + c^2)) over the elements (element_kernels.hpp E8, E9;
    // s), without C_cfl; NaN reported as a NumericalError naming the element.
    double stable_time_step() const;
    // F^{n+1} from the current stresses on the current geometry.
    void compute_forces();
    // v += dt_avg F / M, then the constraints: nodes on the axis keep x = 0, nodes held on a plane
    // stay on it, and a node that would cross a rigid plane within dt_next lands on it (its
    // normal velocity reduced to what takes it there). The plane reactions, impulses and the
    // energy the constraints remove are booked (docs/elements.md, "Contact").
    void integrate(double dt_avg, double dt_next);

    struct Sums {
        double kinetic = 0.0, internal = 0.0, plastic = 0.0, viscous = 0.0;
        std::array<double, 2> momentum{0, 0};
    };
    // Totals over the current state, in a fixed order (bit-identical on any thread count).
    Sums sums() const;

    // The energy removed by the constraints since t = 0 (J), and each rigid plane's reaction of
    // the last step (N) and impulse since t = 0 (N s), in the order of the scene's rigid planes.
    double boundary_work() const { return boundary_work_; }
    const std::vector<double>& reactions() const { return reaction_; }
    const std::vector<double>& impulses() const { return impulse_; }

    const ElementMesh& mesh() const { return mesh_; }
    ElementMesh& mesh() { return mesh_; }
    const ScatterPlan& plan() const { return plan_; }
    const ElementOptions& options() const { return options_; }

    // Checkpoints (Simulation::save_checkpoint): the state later steps depend on, as its own section
    // (nodes' positions, velocities, forces and plane contacts; the quadrilaterals' volumes, lengths
    // and rates; every field of every triangle; the planes' reactions and impulses; the boundary
    // work). The mesh's connectivity, masses and colouring come from the scene, as at the start;
    // read_state throws CheckpointError when the counts are not those of this mesh.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

private:
    template <class G>
    void update_stress_in(double dt, std::size_t step, double time);
    template <class G>
    void compute_forces_in();
    double face_tolerance(std::size_t node) const;

    Scene scene_;
    ElementMesh mesh_;
    ElementOptions options_;
    ScatterPlan plan_;                                // quadrilaterals by colour
    std::vector<std::vector<std::size_t>> groups_;    // quadrilaterals of each material
    std::vector<std::size_t> rigid_planes_;           // scene plane index of each rigid plane
    std::vector<double> reaction_, impulse_;
    double boundary_work_ = 0.0;
};

// The colouring of the force assembly: quadrilaterals in colours such that two of one colour
// share no node, each colour cut into groups of consecutive quadrilaterals (ScatterPlan's
// "centres" are quadrilateral indices). Greedy in quadrilateral order; a structured mesh takes 4
// colours. Serial: one colour, one group.
ScatterPlan make_element_plan(const ElementQuads& quads, std::size_t node_count, ScatterScheme scheme);

// For tests: true when no two quadrilaterals of one group-parallel colour share a node and every
// quadrilateral appears exactly once.
bool element_plan_is_conflict_free(const ScatterPlan& plan, const ElementQuads& quads, std::size_t node_count);

}  // namespace gpa
