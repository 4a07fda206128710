#pragma once
// A part of the time step (simulation.cpp): connectivity. Each body's connectivity mode (fixed,
// variable, automatic: paper section 6), the lattice lists its set-up keeps, and the switching
// phase: lattice cells checked (spec section 2, "[spec] Lattice cells"), fixed nodes of automatic
// bodies switched to variable connectivity above the plastic-strain threshold or where a cell
// collapsed. A node's connectivity is a node field (NodeStore::connectivity), so this part has no
// checkpoint section of its own.

#include <cstddef>
#include <string>
#include <vector>

#include "gpa/engine/lattice_check.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

class Switching {
public:
    explicit Switching(const Scene& scene);

    ConnectivityMode mode(std::size_t body) const { return body_mode_[body]; }
    // Some body switches fixed nodes to variable (the search keeps their candidates too).
    bool any_automatic() const { return any_automatic_; }
    // Some body has lattice nodes: the switching phase is in the step (it checks fixed bodies' cells too).
    bool any_lattice() const { return any_lattice_; }

    // Set-up, once the particle nodes are made: variable bodies' nodes never read their lattice
    // lists, which are dropped (memory); a fixed or automatic body must start on every plane of
    // the scene (a fixed node meets a plane only through the mirror images of its lattice
    // neighbours), else InputError naming body and plane. `first_scene_plane`: the ghost-plane bit
    // of the scene's first plane (after the axis of an axisymmetric scene).
    void prepare_lattices(const Scene& scene, NodeStore& nodes, std::size_t real, std::size_t first_scene_plane) const;

    // The switching phase. Decisions read the state before any switch. Throws NumericalError
    // naming the node when a cell of a fixed body's node has collapsed or inverted; counts the
    // nodes switched for a collapsed cell alone and describes the first.
    struct Report {
        std::size_t collapse_switches = 0;
        std::string first_collapse_switch;
    };
    Report switch_nodes(const Scene& scene, NodeStore& nodes, std::size_t real);

    // The nodes were renumbered or the state restored: the kept axis neighbours (lattice_check.hpp) are found again.
    void forget_lattice_axes() { axes_.forget(); }
    void memory_use(MemoryUse& out) const {
        add_memory(out, "switching: lattice cell ratios", allocated_bytes(cell_ratio_));
        add_memory(out, "switching: lattice axis neighbours", allocated_bytes(axes_.neighbour) + allocated_bytes(axes_.known));
    }

private:
    std::vector<ConnectivityMode> body_mode_;
    bool any_automatic_ = false;
    bool any_lattice_ = false;
    std::vector<double> cell_ratio_;  // per node, its smallest lattice-cell volume ratio (lattice_check.hpp)
    LatticeAxes axes_;                // each fixed node's axis neighbours, kept between steps
};

}  // namespace gpa
