#pragma once
// Node storage as structure of arrays: one contiguous array per field, so that a kernel
// touches only the fields it reads and writes (spec: "NodeStore").
//
// Vector fields hold one array per component; in 2D only components 0 (x) and 1 (z) are
// allocated. Stress components follow the order given in geometry.hpp.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/geometry.hpp"
#include "gpa/engine/memory_use.hpp"

namespace gpa {

class StateWriter;
class StateReader;

enum class Connectivity : std::uint8_t { Fixed = 0, Variable = 1 };

class NodeStore {
public:
    explicit NodeStore(GeometryKind geometry, std::size_t count = 0);

    GeometryKind geometry() const { return geometry_; }
    int dim() const { return dim_; }
    std::size_t size() const { return mass.size(); }

    // Changes the node count; new nodes have every field zero (connectivity Fixed, body and
    // material 0) and no fixed neighbours.
    void resize(std::size_t count);

    // Reorders every per-node field so that new node k is old node new_to_old[k], and rewrites
    // the fixed neighbour lists in the new numbering. new_to_old must be a permutation.
    void permute(std::span<const NodeIndex> new_to_old);

    // Checkpoints (Simulation::save_checkpoint): every field of every node and the fixed lists.
    // read_state throws CheckpointError when the data is not that of a store of this geometry.
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

    // The bytes each field takes (memory_use.hpp), as "nodes: FIELD".
    void memory_use(MemoryUse& out) const;

    // From now on reference_position is one of the fields (resized, reordered, checkpointed and
    // reported with them), starting at the current positions. A scene without the relaxing
    // stiffness never calls it and carries nothing.
    void carry_reference_positions();
    bool carries_reference_positions() const { return carries_reference_; }
    // From now on alpha_shear is not one of the fields: its arrays are freed, and resizing,
    // reordering, checkpoints and the memory report leave it out. For a run with the per-direction
    // normalisation, which never writes or reads it (8 bytes per node in 2D, 24 in 3D). A store
    // carries it until this is called.
    void drop_shear_normalisation();
    bool carries_shear_normalisation() const { return carries_shear_; }
    // Frees the lattice lists when no row has an entry (fixed_neighbours below); the set-up calls it
    // once the lattices are prepared.
    void release_empty_lattice_rows();

    // --- state carried from step to step -------------------------------------------------
    std::array<std::vector<double>, 3> position;   // m
    // Position on the initial lattice, m: x0 of Eq. 3, and the lattice distances r0 that weigh
    // fixed-connectivity pairs (spec section 2).
    std::array<std::vector<double>, 3> initial_position;
    std::array<std::vector<double>, 3> velocity;   // m/s
    // The relaxing reference of the hourglass stiffness on flowing nodes (SolverOptions::
    // hourglass_stiffness_relaxation), m: the position when carry_reference_positions() was
    // called, drawn towards the position with the relaxation's time constant. Empty unless
    // carried.
    std::array<std::vector<double>, 3> reference_position;
    std::vector<double> mass;                      // kg (a ring's mass in axisymmetric geometry)
    std::vector<double> volume;                    // V, m^3 (unit thickness in plane strain)
    std::vector<double> initial_volume;            // V0
    std::vector<double> size_weight;               // W_j: A_j in 2D (Eq. 4), V_j in 3D
    std::vector<double> diameter;                  // d (Eq. 3)
    std::vector<double> initial_diameter;          // d0
    std::vector<double> volumetric_strain;         // eps_v = V/V0 - 1 (Eq. 13)
    std::array<std::vector<double>, 6> deviatoric_stress;  // s, Pa
    std::vector<double> pressure;                  // P from the equation of state, Pa
    std::vector<double> viscous_pressure;          // nodal artificial viscosity Q_i (Eq. 36), Pa
    std::vector<double> sound_speed;               // longitudinal wave speed c_i, m/s
    std::vector<double> internal_energy;           // specific, J/kg
    std::vector<double> temperature;               // K
    std::vector<double> plastic_strain;            // equivalent plastic strain
    std::vector<double> plastic_strain_rate;       // d eps_p / dt of the last step, 1/s (materials::PointState)
    std::vector<double> damage;                    // Johnson-Cook damage D
    std::vector<double> plastic_work;              // accumulated specific plastic work, J/kg
    std::vector<double> viscous_work;              // accumulated specific artificial-viscous work, J/kg
    // 3D only: the left Cauchy-Green tensor B = F F^T (kernels.hpp, advance_left_cauchy_green), in
    // the stress order; the identity when a body is filled. Carried while the node diameter follows
    // the stretch (SolverOptions::node_diameter), the identity otherwise.
    std::array<std::vector<double>, 6> left_cauchy_green;
    std::vector<std::uint8_t> failed;              // 1 once the node has failed (no deviator, no tension)
    std::vector<std::uint8_t> plane_contact;       // bit p: in contact with lift-off plane p (ghosts.hpp)
    std::vector<std::uint8_t> velocity_region;     // 0: free; k + 1: held by Scene::prescribed_velocities[k] (prescribed.hpp)
    std::vector<std::int32_t> body;
    std::vector<std::int32_t> material;
    // The node's id: its place in the order the scene's particle bodies were filled (bodies in scene
    // order, each in lattice order: fill_lattice), kept through every reordering, so that outputs and
    // messages can name a node for the whole run. A ghost carries its source's id.
    std::vector<std::uint32_t> id;
    std::vector<Connectivity> connectivity;

    // --- results of the gradient and force phases, rewritten every step ------------------
    std::array<std::vector<double>, 3> alpha;              // geometry factors (Eq. 14, 15, 51-53)
    std::array<std::vector<double>, 3> alpha_shear;        // off-diagonal normalisation (full only):
                                                           // 2D xz; 3D yz, xz, xy; empty once dropped
    std::array<std::vector<double>, 9> velocity_gradient;  // L_ab at [a * dim + b]
    std::vector<double> volumetric_strain_rate;            // eps_v_dot (Eq. 12), with hoop term
    std::vector<double> smallest_h;                        // min_j h_ij
    std::vector<double> stable_length;                     // c / omega of the node (kernels.hpp)
    std::array<std::vector<double>, 3> force;              // N (a ring's force in axisymmetric)

    // Lattice neighbours of each node for fixed connectivity (spec section 2). Either a row per
    // node or no rows at all: in a scene where no node has lattice neighbours the lists hold
    // nothing, not an offset per node, and every row reads as empty (CompressedRows::row_or_empty,
    // the way to read them). Rows kept at the set-up stay, empty or not, when nodes switch.
    CompressedRows fixed_neighbours;
    // Lattice neighbours that lie across a symmetry or rigid plane: the ghost image of node
    // fixed_mirrors.indices[k] across the planes in bit mask fixed_mirror_planes[k] (spec section 7:
    // "a fixed-connectivity node next to a plane has its ghost images in its neighbour list").
    // Rows as above: one per node, or none.
    CompressedRows fixed_mirrors;
    std::vector<std::uint8_t> fixed_mirror_planes;

private:
    // Calls f(name, field) for every per-node field: the one list of the fields that resizing,
    // reordering, checkpoints and the memory report share.
    template <class F>
    void for_each_field(F&& f);

    GeometryKind geometry_;
    int dim_;
    bool carries_reference_ = false;
    bool carries_shear_ = true;
};

// "node i at (x, z) = (...) m", or (x, y, z) in 3D: where an error message places a node.
std::string describe_node(const NodeStore& nodes, std::size_t i);

// Checks what the method cannot work with, for nodes [first, last): a non-finite or (in
// axisymmetric geometry) non-positive radial coordinate, a non-positive mass, volume, size
// weight or diameter, a non-finite velocity. Throws InputError naming the node and its position.
void validate_nodes(const NodeStore& nodes, std::size_t first, std::size_t last);
inline void validate_nodes(const NodeStore& nodes) { validate_nodes(nodes, 0, nodes.size()); }

// Sets W_j from the current volume and position: V/(2 pi x) axisymmetric, V otherwise.
void update_size_weights(NodeStore& nodes, std::size_t first, std::size_t last);

}  // namespace gpa
