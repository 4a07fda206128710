#pragma once
// Filling bodies with nodes (spec section 12): a lattice of spacing (dx, dz) or dx = dy = dz in
// 3D with nodes at cell centres, so that no node lies on a boundary, the axis or a plane; and
// the lattice neighbours that fixed connectivity keeps (spec section 2).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "gpa/engine/node_store.hpp"
#include "gpa/engine/orientation.hpp"

namespace gpa {

// Which lattice neighbours a fixed-connectivity node keeps.
//   2D: 4 (along the axes) or 8 (with diagonals); 3D: 6 (faces), 18 (+ edges) or 26 (+ corners).
int check_lattice_stencil(int dim, int neighbours);  // returns neighbours, or throws InputError

// A plane across which the lattice continues by mirror images (a symmetry plane, the axis of an
// axisymmetric body, a rigid plane with ghosts): bit `bit` of a mirror mask.
// In the scene's axes its normal is axis `axis`, or `normal` for axis = -1 (an oblique plane,
// position = n . x of its points); LatticeBlock::mirror_planes holds them in the block's own axes
// (lattice_mirror_planes), where only planes along a lattice axis continue it.
struct MirrorPlane {
    int axis = 1;
    double position = 0.0;
    int side = +1;  // the body lies where the coordinate is above (+1) or below (-1) the plane
    int bit = 0;
    std::array<double, 3> normal{0, 0, 0};  // axis = -1 only
};

struct LatticeBlock {
    // Lattice cell k (integer, per axis) has its node at origin + (k + 1/2) * spacing.
    std::array<double, 3> origin{0, 0, 0};
    std::array<double, 3> spacing{1, 1, 1};   // 3D: all three equal
    std::array<std::int64_t, 3> first{0, 0, 0};  // cells [first, last) per axis
    std::array<std::int64_t, 3> last{1, 1, 1};
    double density = 1.0;                        // rho0, kg/m^3
    std::array<double, 3> velocity{0, 0, 0};     // initial velocity of every node, m/s
    std::int32_t body = 0;
    std::int32_t material = 0;
    Connectivity connectivity = Connectivity::Variable;
    int lattice_neighbours = 8;                  // stencil of the fixed lists (see above)
    // Beyond the stencil, every lattice node closer than this many d0 (on the undeformed lattice;
    // d0 as below) is a lattice neighbour too; 0: the stencil alone; at most 3. A body with
    // influence distance a > 1 takes 2 a, so that its fixed nodes keep the neighbours a variable
    // node finds on the undeformed lattice (r < 2 h, h = a d0) and a node that switches keeps its
    // stencil (docs/connectivity.md).
    double stencil_reach = 0.0;
    // Keeps the cells whose centre it accepts (x, z) or (x, y, z); empty: keep all.
    std::function<bool(const std::array<double, 3>&)> inside;
    // Trimmed cells (BodySpec::fill, CellFill::Trimmed; docs/scene-format.md): every cell the shape
    // `inside` covers in part becomes a node of that part, instead of the cells whose centre it
    // covers. A cell whose corners and centre all lie inside is whole (its node at its centre, as
    // without trimming); any other is sampled at trim_samples^D points (midpoints of equal
    // sub-cells, placed symmetrically about the centre so that a mirror-symmetric shape gets
    // mirror-symmetric nodes). Its share of the cell is the fraction inside, its node the mean of
    // the points inside, its size the share of the cell's (volume; in 2D the section, a ring's
    // volume 2 pi x A about the node's radius) and its d0 the side of a cube (square) of that size.
    // A part below smallest_share of a cell (a sliver) is merged into the face neighbour, among
    // the cells at least that full, with the largest share (the first along x, y, z at a tie):
    // the neighbour's node moves to the centroid of both parts, so no mass is lost and no node is
    // a sliver (whose small d0 would shorten the stable step). A shape thinner than a cell that
    // misses every corner and the centre is not seen.
    bool trim = false;
    int trim_samples = 10;
    double smallest_share = 0.25;
    // Planes with ghosts, in the block's own axes (axis-aligned): a stencil neighbour that falls
    // behind them and whose mirror image is a cell of this block becomes a mirrored lattice
    // neighbour (NodeStore::fixed_mirrors).
    std::vector<MirrorPlane> mirror_planes;
    // The block turned about `pivot` (a body's rotation, scene.hpp): everything above (origin,
    // cells, inside, mirror planes) is in the block's own axes, and a cell centre c of those axes
    // becomes the node at place(c) = pivot + R (c - pivot). Velocities are in the scene's axes.
    Rotation rotation = identity_rotation;
    std::array<double, 3> pivot{0, 0, 0};
    std::array<double, 3> place(const std::array<double, 3>& c) const {
        if (is_identity(rotation)) return c;
        const auto q = turn(rotation, {c[0] - pivot[0], c[1] - pivot[1], c[2] - pivot[2]});
        return {pivot[0] + q[0], pivot[1] + q[1], pivot[2] + q[2]};
    }
};

// The planes of `planes` (the scene's axes) in the own axes of `block` (its rotation): an aligned
// plane of an unrotated block as it is; otherwise those whose normal turns into a lattice axis (to
// 1e-9), with their position and side in the block's axes. The others are left out: fixed lists
// do not continue a lattice across a plane oblique to it (variable nodes find their ghosts by search).
std::vector<MirrorPlane> lattice_mirror_planes(const LatticeBlock& block, const std::vector<MirrorPlane>& planes, int dim);

// Appends the block's nodes to `nodes`, with mass, volume, size weight, diameter (d0 = sqrt(dx dz)
// in 2D, dx in 3D), x0, velocity, body, material and connectivity set, and fixed lists that link
// each new node to its stencil neighbours among the new nodes. Returns the index of the first
// new node. Throws InputError for a non-positive spacing or density or (axisymmetric) a cell
// centre at x <= 0.
std::size_t fill_lattice(NodeStore& nodes, const LatticeBlock& block);

}  // namespace gpa
