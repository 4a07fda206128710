#pragma once
// A body given as nodes rather than as a shape: positions and sizes imported from another tool (a
// CSV table or a VTK point file, io/node_file.hpp; docs/scene-format.md, "Imported nodes"), or made
// by an embedding program. BodySpec::node_set holds one for a body of shape "nodes".
//
// A node's size is its measure in the scene's geometry, as a lattice cell's would be: in 3D its
// volume V (m^3), in 2D its cross-section A (m^2: the area of the node's cell in the x-z plane; in
// plane strain its volume per metre of thickness, in axisymmetric geometry the section of its ring,
// whose volume is then 2 pi x A as for the lattice, lattice.hpp). Its initial diameter (Eq. 2's
// d0) is the side of the cube or square of that measure, V^(1/3) or A^(1/2): the lattice's d0 for a
// node of a regular lattice.
//
// An imported body has no lattice: its nodes have variable connectivity (no fixed lists), and the
// region it covers, for the checks of overlap and of planes, is the union of the nodes' cubes
// (squares) of side d0 centred on the nodes.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace gpa {

struct NodeSet {
    // m, before the body's origin is added; in 2D (x, z, 0).
    std::vector<std::array<double, 3>> positions;
    // 3D: volume, m^3; 2D: cross-section, m^2 (above).
    std::vector<double> sizes;
    // Where each node came from, for messages: "line 12" of a CSV file, "point 11" of a VTK file;
    // empty: "node k" (k from 0).
    std::vector<std::string> origins;
};

// The most nodes one body may import (about 3 GB of node data in 3D).
inline constexpr std::size_t max_imported_nodes = 50'000'000;
// The farthest a node may lie from the origin along an axis, m (a million km: any larger number
// is a unit gone wrong, and the bucket grid of NodeSetShape needs a finite box).
inline constexpr double max_node_coordinate = 1e9;

// Refuses (InputError, naming `what`, e.g. the file, and the node): an empty set, positions and
// sizes of different counts, a position or size that is not finite, a coordinate beyond
// max_node_coordinate, a size <= 0, a diameter below 1e-12 of the node's distance from the origin
// (its coordinates cannot resolve it), a 2D node with a third coordinate other than 0, in axisymmetric geometry (`axisymmetric`) a node at x <= 0, more
// than max_imported_nodes nodes, and two nodes closer than a quarter of their mean diameter (a
// node listed twice, or sets that overlap: their pairs would be crushed in the first step).
void check_node_set(const NodeSet& set, int dim, bool axisymmetric, const std::string& what);

// A checked node set with its diameters, its extent and a bucket grid for the point queries of the
// scene checks.
class NodeSetShape {
public:
    NodeSetShape(std::shared_ptr<const NodeSet> set, int dim);

    const NodeSet& set() const { return *set_; }
    int dim() const { return dim_; }
    std::size_t size() const { return set_->positions.size(); }
    // d0 of node k: V^(1/3) in 3D, A^(1/2) in 2D.
    double diameter(std::size_t k) const { return diameters_[k]; }
    // The median of the nodes' diameters: the body's nominal spacing (time-step estimates, reports,
    // tolerances).
    double typical_diameter() const { return typical_; }
    // The box of the nodes' cubes (squares), before the body's origin is added; in 2D components 0
    // and 1.
    const std::array<double, 3>& lower() const { return lower_; }
    const std::array<double, 3>& upper() const { return upper_; }
    // Whether p (before the origin) lies strictly inside some node's cube (square) of side d0.
    bool covers(const std::array<double, 3>& p) const;
    // Calls visit(k) for every node in p's bucket and its neighbours: every node closer to p than
    // the largest diameter along each axis, and some beyond; until visit returns true.
    template <class F>
    bool any_near(const std::array<double, 3>& p, F&& visit) const {
        const Cell home = cell_of(p);
        const int reach_z = dim_ == 3 ? 1 : 0;
        for (int dz = -reach_z; dz <= reach_z; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
                for (int dx = -1; dx <= 1; ++dx) {
                    const auto it = buckets_.find(Cell{home[0] + dx, home[1] + dy, home[2] + dz});
                    if (it == buckets_.end()) continue;
                    for (std::uint32_t m = it->second.first; m < it->second.second; ++m) {
                        if (visit(static_cast<std::size_t>(order_[m]))) return true;
                    }
                }
            }
        }
        return false;
    }
    // The nodes whose position (before the origin) lies in the box [lo, hi] on every axis of dim.
    template <class F>
    bool any_in_box(const std::array<double, 3>& lo, const std::array<double, 3>& hi, F&& visit) const {
        for (std::size_t k = 0; k < size(); ++k) {
            const auto& p = set_->positions[k];
            bool in = true;
            for (int c = 0; c < dim_; ++c) in = in && p[c] >= lo[c] && p[c] <= hi[c];
            if (in && visit(k)) return true;
        }
        return false;
    }

private:
    using Cell = std::array<std::int64_t, 3>;
    struct CellHash {
        std::size_t operator()(const Cell& c) const noexcept;
    };
    Cell cell_of(const std::array<double, 3>& p) const;

    std::shared_ptr<const NodeSet> set_;
    int dim_ = 3;
    std::vector<double> diameters_;
    double typical_ = 0.0;
    std::array<double, 3> lower_{}, upper_{};
    double bucket_ = 1.0;  // the bucket grid's cell, the largest diameter
    std::vector<std::uint32_t> order_;  // node indices by bucket
    std::unordered_map<Cell, std::pair<std::uint32_t, std::uint32_t>, CellHash> buckets_;  // [begin, end) in order_
};

}  // namespace gpa
