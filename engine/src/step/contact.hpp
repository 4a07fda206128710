#pragma once
// A part of the time step (simulation.cpp): contact and separation. Which pairs may open
// (separation.hpp: pairs between bodies, and through failed nodes when failure is on and
// solver.separate_failed), the closing speeds of the closed ones (for the time step) and, under
// sliding contact, each node's outward direction where it touches another body (for the contact
// normals, fields.hpp). Everything here is made afresh every step in the neighbours phase, so it
// has no checkpoint section.

#include <array>
#include <cstddef>
#include <vector>

#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/memory_use.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

class Contact {
public:
    explicit Contact(const Scene& scene)
        : failed_pairs_separate_(scene.solver.failure && scene.solver.separate_failed),
          separation_(scene.bodies.size() > 1 || failed_pairs_separate_),
          sliding_(separation_ && scene.solver.sliding_contact) {}

    // Some pairs may open (more than one body, or failed nodes that separate).
    bool separation() const { return separation_; }
    // Closed separable pairs carry normal velocity differences and forces only.
    bool sliding() const { return sliding_; }
    bool failed_pairs_separate() const { return failed_pairs_separate_; }

    void set_up(std::size_t real) {
        if (separation_) closing_speed_.assign(real, 0.0);
    }

    // The pair fields of a phase, with sliding contact where the scene has it (fields.hpp).
    template <int D>
    PairFields<D> fields(PairFields<D> p, const NodeStore& nodes) const {
        p.sliding_contact = sliding_;
        p.failed_pairs_separate = failed_pairs_separate_;
        p.failed = nodes.failed.data();
        if (sliding_) {
            for (int c = 0; c < D; ++c) p.contact_direction[c] = direction_[c].data();
        }
        return p;
    }

    // The open separable pairs out of the real rows of `lists` (separation.hpp), with the closing
    // speeds and contact directions of the step. Nothing without separation.
    void separate(CompressedRows& lists, const NodeStore& nodes, std::size_t real, double influence_distance);
    // The ghosts' contact directions, mirrored from their sources once the ghost rows are in.
    void mirror_directions(GhostSet& ghosts, int dim, std::size_t real);

    // Per real node, the largest speed at which a closed separable pair closes on it (the time
    // step, spec section 11); null without separation.
    const double* closing_speed() const { return closing_speed_.empty() ? nullptr : closing_speed_.data(); }

    void memory_use(MemoryUse& out) const {
        std::size_t directions = 0;
        for (const auto& d : direction_) directions += allocated_bytes(d);
        add_memory(out, "contact: closing speeds and directions", allocated_bytes(closing_speed_) + directions);
    }

private:
    bool failed_pairs_separate_;
    bool separation_;
    bool sliding_;
    std::vector<double> closing_speed_;             // per real node
    std::array<std::vector<double>, 3> direction_;  // per node, ghosts mirrored
};

}  // namespace gpa
