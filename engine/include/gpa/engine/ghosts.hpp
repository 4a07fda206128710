#pragma once
// Ghost (mirror-image) nodes of symmetry and rigid planes (spec section 7). Ghosts are stored
// after the real nodes of a NodeStore and rebuilt every step: a ghost is an exact mirror of its
// source node across one plane or, at corners, across several planes with distinct normals. It
// copies volume, size weight, diameter, alpha, connectivity mode, body and material and carries
// the mirrored position, velocity and stress. Ghosts act on real nodes as centres and as
// neighbours; they are not integrated, and the forces on them are the planes' reactions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/node_store.hpp"

namespace gpa {

// A plane normal to a coordinate axis (`axis`), or oblique (axis = -1, unit `normal`, position =
// n . x of its points). An aligned plane mirrors by changing signs (exact: a ghost's ghost is its
// source bit for bit); an oblique one by the reflection H = I - 2 n n^T.
struct GhostPlane {
    std::string name;
    int axis = 1;
    double position = 0.0;
    int side = +1;          // the real nodes lie above (+1) or below (-1) the plane along `axis` (n)
    bool lift_off = false;  // pairs with its ghosts may only push (a rigid plane with lift-off)
    bool rigid = false;     // a rigid wall (its reaction is reported) rather than a symmetry plane
    // A symmetry plane of the scene: its ghosts continue the bodies (a half or quarter model), and
    // the hourglass control pairs them like real nodes (continuing_flags). Not the axis of an
    // axisymmetric scene, whose ghosts stay out of the control as they always have.
    bool continues_body = false;

    std::array<double, 3> normal{0, 0, 0};  // axis = -1 only: the unit normal

    // Signed distance of a point's coordinate (along the normal) from the plane, positive on the real side.
    double distance(double coordinate) const { return side * (coordinate - position); }
    // The coordinate along the normal of node i (of a field of 3 component arrays), and its
    // signed distance from the plane.
    template <class Field>
    double coordinate_of(const Field& x, std::size_t i) const {
        if (axis >= 0) return x[static_cast<std::size_t>(axis)][i];
        double sum = 0.0;
        for (std::size_t c = 0; c < 3; ++c) {
            if (normal[c] != 0.0) sum += normal[c] * x[c][i];
        }
        return sum;
    }
    template <class Field>
    double distance_of(const Field& x, std::size_t i) const { return distance(coordinate_of(x, i)); }
    std::array<double, 3> unit_normal() const {
        if (axis < 0) return normal;
        std::array<double, 3> n{0, 0, 0};
        n[static_cast<std::size_t>(axis)] = 1.0;
        return n;
    }
    // Mirror images across the plane: of a point, of a vector (a velocity, a force, a
    // displacement) and of a symmetric tensor in NodeStore order (H S H; 2D: the in-plane block).
    void reflect_point(std::array<double, 3>& x) const {
        if (axis >= 0) {
            x[static_cast<std::size_t>(axis)] = 2.0 * position - x[static_cast<std::size_t>(axis)];
            return;
        }
        const double twice = 2.0 * (normal[0] * x[0] + normal[1] * x[1] + normal[2] * x[2] - position);
        for (std::size_t c = 0; c < 3; ++c) x[c] -= twice * normal[c];
    }
    void reflect_vector(std::array<double, 3>& v) const {
        if (axis >= 0) {
            v[static_cast<std::size_t>(axis)] = -v[static_cast<std::size_t>(axis)];
            return;
        }
        const double twice = 2.0 * (normal[0] * v[0] + normal[1] * v[1] + normal[2] * v[2]);
        for (std::size_t c = 0; c < 3; ++c) v[c] -= twice * normal[c];
    }
    void reflect_tensor(int dim, std::array<double, 6>& s) const;
};

// Whether two planes' normals are perpendicular (to 1e-9; aligned planes: distinct axes). Only
// such planes make corner ghosts together: their reflections commute, so that the image across
// both is one point whichever comes first.
bool perpendicular(const GhostPlane& a, const GhostPlane& b);

// Which real nodes get ghosts: those closer to every plane of a corner combination than
// base + per_diameter * d (their own diameter d). A fixed range is {range, 0}.
struct GhostReach {
    double base = 0.0;
    double per_diameter = 0.0;
    double of(double diameter) const { return base + per_diameter * diameter; }
};

class GhostSet {
public:
    GhostSet() = default;
    explicit GhostSet(std::vector<GhostPlane> planes);

    const std::vector<GhostPlane>& planes() const { return planes_; }
    std::vector<MirrorPlane> mirror_planes() const;
    bool empty() const { return planes_.empty(); }

    // Which real nodes touch each lift-off plane (bit p of NodeStore::plane_contact); only they
    // are paired with its ghosts. At the start, every node within 3/4 of its diameter of the
    // plane; later, a free node comes into contact when it is that close and moving towards the
    // plane, and a node in contact is released when its normal stress sigma_nn (with viscosity)
    // turns tensile. Decided before the neighbour lists, so that the gradient and the forces see
    // the same ghost pairs (and the energy identity holds). (A rigid plane without lift-off is,
    // as spec section 7 says, a symmetry plane: its ghost pairs always act.)
    void update_contacts(NodeStore& nodes, std::size_t real_count, bool initial) const;

    // Gives the ghost entries (real_count onwards) of a vector field the mirrored values of their
    // sources, as update() does for the velocities; `field` holds real and ghost nodes.
    void mirror_vector_field(const std::array<double*, 3>& field, int dim, std::size_t real_count) const;


    // Replaces the ghosts of `nodes` (everything after real_count) with the mirrors of the real
    // nodes within `range` of the planes (all planes of a corner mask) and of every node that a
    // fixed list names as a mirrored neighbour; across a lift-off plane only nodes in contact
    // have ghosts. Copies positions, velocities and the geometry fields (mass, volume, size
    // weight, diameter, connectivity, body, material, failed).
    //
    // keep_between_searches: the set is to serve several steps (neighbour lists with a skin):
    // every node within `range` gets its ghosts whatever its contact state, so that contacts can
    // change without a new set; the pairs of nodes out of contact are removed from the lists
    // every step instead (remove_pairs_without_contact), which gives the same pairs.
    void build(NodeStore& nodes, std::size_t real_count, GhostReach reach, bool keep_between_searches = false);
    void build(NodeStore& nodes, std::size_t real_count, double range, bool keep_between_searches = false) {
        build(nodes, real_count, GhostReach{range, 0.0}, keep_between_searches);
    }

    // The reach the pairs need, with `margin` added (the skin of neighbour lists that are to
    // serve several steps). A real node i and the ghost of a node j across a plane are at least
    // dist_i + dist_j apart (their distances from the plane), and pair only when closer than
    // 2 h_ij + margin = a (d_i + d_j) + margin; so j needs a ghost only when
    // dist_j < a d_j + max_i (a d_i - dist_i) + margin, the maximum over the real nodes and the
    // planes. (A reach of 2 a d_max for every node made each debris node of a fractured body
    // that had grown to 30 times its diameter give ghosts to everything within 30 diameters.)
    GhostReach pair_reach(const NodeStore& nodes, std::size_t real_count, double influence_distance, double margin) const;

    // Re-copies, for the ghosts of the last build, the fields that build() copies, from the
    // sources' current values (positions and velocities mirrored).
    void update(NodeStore& nodes, std::size_t real_count) const;

    // True when the ghosts of the last build include every real node within `range` of all
    // planes of a corner combination (ignoring contact): the set still serves that range.
    bool covers(const NodeStore& nodes, std::size_t real_count, GhostReach reach) const;

    // A bound on how much the distance of any real node to any ghost has changed since the
    // positions `reference` (real nodes [0, real_count), taken at the last build): per corner
    // combination, 2 max |u - U| over the nodes with such a ghost, u their displacement and U
    // the middle of those displacements with its components normal to the planes set to zero
    // (a mirror leaves U unchanged, so |u_i - mirror(u_s)| <= |u_i - U| + |u_s - U|).
    double mirrored_displacement_bound(const NodeStore& nodes, std::size_t real_count,
                                       const std::array<std::vector<double>, 3>& reference) const;

    // Removes from the real centres' rows [0, real_count) the ghosts of lift-off planes that the
    // centre or the ghost's source does not touch, so that only nodes in contact interact with
    // those ghosts.
    void remove_pairs_without_contact(CompressedRows& lists, const NodeStore& nodes, std::size_t real_count) const;

    // Copies the fields of the stress phase and the gradient from the sources: alpha, stress
    // (mirrored), pressure, viscous pressure, sound speed, volume, damage, failed.
    void refresh(NodeStore& nodes, std::size_t real_count) const;

    // For every real node, the ghost indices of its mirrored lattice neighbours
    // (NodeStore::fixed_mirrors resolved against the current ghosts).
    // (After a build with keep_between_searches, all of them, in contact or not.)
    const CompressedRows& resolved_fixed_mirrors(const NodeStore& nodes, std::size_t real_count);

    // Appends the rows of the ghost centres to `lists` (which holds the rows of the real
    // centres): ghost g = mirror(s, S) lists every real j whose mirror(j, S) is in s's list, so
    // that each real-ghost pair has its mirror image.
    void append_ghost_rows(CompressedRows& lists, std::size_t real_count) const;

    // Per ghost of the last build, 1 where every plane of its mask continues the bodies (a
    // symmetry plane of the scene: GhostPlane::continues_body), for HourglassFields::ghost_continues;
    // null when no ghost does.
    const std::uint8_t* continuing_flags();

    // The hourglass control's forces on the continuing ghosts, moved to their sources: save_forces
    // keeps the ghosts' forces before the control, fold_forces moves what the control added to each
    // continuing ghost to its source, mirrored across the ghost's planes (a force on the mirror of
    // node s is the mirror of a force on s: the whole body's centre across the plane acts on s),
    // and gives the ghost back its saved force. In ghost order, one order on any thread count.
    void save_forces(const NodeStore& nodes, std::size_t real_count);
    void fold_forces(NodeStore& nodes, std::size_t real_count) const;

    std::size_t count() const { return source_.size(); }
    NodeIndex source(std::size_t ghost) const { return source_[ghost]; }
    // The ghost of real node `node` across the planes of ghost node `like` (both node indices,
    // ghosts numbered from real_count), or -1 when the set holds none.
    std::int64_t image_like(std::size_t real_count, NodeIndex like, NodeIndex node) const {
        return ghost_of(node, slot_[like - real_count]);
    }
    std::uint8_t planes_of(std::size_t ghost) const { return mask_[ghost]; }

    // The force the planes exert on the real nodes along each plane's normal, from the forces
    // on the ghosts (spec section 7: the net force over all real-ghost pairs). Positive pushes
    // the bodies away from the plane.
    std::vector<double> normal_reactions(const NodeStore& nodes, std::size_t real_count) const;

    // Checkpoints: the ghosts of the last build and their lookup tables (the planes are the
    // scene's and are not stored; read_state checks that they match).
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in, std::size_t real_count, std::size_t node_count);

    // The bytes its arrays take (memory_use.hpp), as "ghosts: ARRAY".
    void memory_use(MemoryUse& out) const;

private:
    // The checkpoint's fields, listed once for both directions (Self const when writing).
    template <class IO, class Self>
    static void state_fields(IO& io, Self& self, std::size_t real_count, std::size_t node_count);
    void check_restored(StateReader& in, std::size_t real_count, std::size_t node_count) const;

    std::vector<std::uint8_t> continues_;                // continuing_flags()
    std::array<std::vector<double>, 3> saved_force_;     // save_forces(), per ghost
    std::vector<GhostPlane> planes_;
    std::vector<std::uint8_t> masks_;            // the corner combinations in use: distinct axes
    std::vector<NodeIndex> source_;
    std::vector<std::uint8_t> mask_;
    std::vector<std::uint8_t> slot_;          // per ghost: the index of its mask in masks_
    std::vector<NodeIndex> sources_sorted_;   // the real nodes with ghosts, ascending, once each
    // The ghosts of each node of sources_sorted_, one per mask slot (ghost node, or -1 where the
    // node has none across that combination): masks_.size() entries per source, in the order of
    // sources_sorted_. Per source, not per real node, so that it takes memory in proportion to
    // the ghosts, not to the nodes times the plane combinations. table_real_count_: the real nodes
    // of the build it describes.
    std::vector<std::int32_t> ghost_table_;
    std::size_t table_real_count_ = 0;
    // The ghost of real node `node` across the combination of slot `slot`, or -1 (a binary search
    // in sources_sorted_).
    std::int64_t ghost_of(NodeIndex node, std::size_t slot) const;
    std::uint8_t lift_off_mask_ = 0;  // bits of the lift-off planes
    bool keep_between_searches_ = false;
    CompressedRows resolved_;
    std::size_t mask_slot(std::uint8_t mask) const;
    // Ghosts [first, last) take their sources' point or vector (mirrored across their planes), or
    // symmetric tensor in NodeStore order (its first `components` entries).
    enum class Mirrored { Point, Vector };
    void mirror_to_ghosts(const std::array<double*, 3>& field, int dim, std::size_t real_count, std::size_t first,
                          std::size_t last, Mirrored kind) const;
    void mirror_tensors_to_ghosts(const std::array<double*, 6>& field, int components, int dim, std::size_t real_count,
                                  std::size_t first, std::size_t last) const;
    // True when real node i may have (or be paired with) ghosts across the planes of `mask`.
    bool allowed(const NodeStore& nodes, std::size_t i, std::uint8_t mask) const {
        return (mask & lift_off_mask_ & ~nodes.plane_contact[i]) == 0;
    }
    // Whether node i may have ghosts across `mask` in this set (every node, in a kept set).
    bool selectable(const NodeStore& nodes, std::size_t i, std::uint8_t mask) const {
        return keep_between_searches_ || allowed(nodes, i, mask);
    }
};

// Mirrors a symmetric stress (NodeStore order) across a plane normal to `axis` (spec section 7):
// the shear components with exactly one index along the normal change sign.
void mirror_stress(int dim, int axis, std::array<double, 6>& s);

}  // namespace gpa
