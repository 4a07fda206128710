#include "step/switching.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/lattice_check.hpp"

namespace gpa {

Switching::Switching(const Scene& scene) {
    for (const auto& b : scene.bodies) body_mode_.push_back(b.connectivity.value_or(scene.solver.connectivity));
    any_automatic_ = std::any_of(body_mode_.begin(), body_mode_.end(), [](ConnectivityMode m) { return m == ConnectivityMode::Automatic; });
    any_lattice_ = std::any_of(body_mode_.begin(), body_mode_.end(), [](ConnectivityMode m) { return m != ConnectivityMode::Variable; });
}

void Switching::prepare_lattices(const Scene& scene, NodeStore& nodes, std::size_t real, std::size_t first_scene_plane) const {
    const auto drop_variable_rows = [&](CompressedRows& rows, std::vector<std::uint8_t>* tags) {
        if (rows.rows() == 0) return;  // no lattice lists (node_store.hpp)
        CompressedRows kept;
        std::vector<std::uint8_t> kept_tags;
        kept.offsets.assign(1, 0);
        for (std::size_t i = 0; i < real; ++i) {
            if (body_mode_[static_cast<std::size_t>(nodes.body[i])] != ConnectivityMode::Variable) {
                for (std::size_t e = rows.offsets[i]; e < rows.offsets[i + 1]; ++e) {
                    kept.indices.push_back(rows.indices[e]);
                    if (tags) kept_tags.push_back((*tags)[e]);
                }
            }
            kept.offsets.push_back(kept.indices.size());
        }
        rows = std::move(kept);
        if (tags) *tags = std::move(kept_tags);
    };
    drop_variable_rows(nodes.fixed_neighbours, nullptr);
    drop_variable_rows(nodes.fixed_mirrors, &nodes.fixed_mirror_planes);
    nodes.release_empty_lattice_rows();
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (body_mode_[b] == ConnectivityMode::Variable || scene.bodies[b].discretisation != Discretisation::Particles) continue;
        for (std::size_t k = 0; k < scene.planes.size(); ++k) {
            const std::size_t bit = first_scene_plane + k;
            bool touches = false;
            for (std::size_t i = 0; i < real && !touches; ++i) {
                if (nodes.body[i] != static_cast<std::int32_t>(b)) continue;
                if (i >= nodes.fixed_mirrors.rows()) break;  // no mirrored lattice neighbours anywhere
                for (std::size_t e = nodes.fixed_mirrors.offsets[i]; e < nodes.fixed_mirrors.offsets[i + 1]; ++e) {
                    touches |= (nodes.fixed_mirror_planes[e] >> bit) & 1u;
                }
            }
            if (!touches) {
                throw InputError(fmt::format(
                    "body \"{}\" uses {} connectivity but does not start on plane \"{}\": fixed nodes meet a plane "
                    "only through the mirror images of their lattice neighbours; start the body on the plane (its "
                    "lattice then continues across it) or give it variable connectivity",
                    scene.bodies[b].name, body_mode_[b] == ConnectivityMode::Fixed ? "fixed" : "automatic",
                    scene.planes[k].name));
            }
        }
    }
}

Switching::Report Switching::switch_nodes(const Scene& scene, NodeStore& nodes, std::size_t real) {
    // Lattice cells first (spec section 2, "[spec] Lattice cells"): a fixed node whose cell has
    // collapsed or inverted cannot go on with its lattice stencil. In a fixed body the run stops
    // there; in an automatic body the node switches at once. Then paper section 6: a fixed node of
    // an automatic body switches to variable connectivity, for the rest of the run, once its
    // equivalent plastic strain exceeds the threshold.
    smallest_lattice_cell_ratios(nodes, real, cell_ratio_, &axes_);
    const double threshold = scene.solver.switch_plastic_strain;
    Report report;
    const auto where = [&](std::size_t i) {
        const auto& body = scene.bodies[static_cast<std::size_t>(nodes.body[i])];
        std::string at = fmt::format("body \"{}\", node {} at ", body.name, i);
        if (nodes.dim() == 2) {
            return at + fmt::format("(x, z) = ({:.4g}, {:.4g}) mm", nodes.position[0][i] * 1e3, nodes.position[1][i] * 1e3);
        }
        return at + fmt::format("(x, y, z) = ({:.4g}, {:.4g}, {:.4g}) mm", nodes.position[0][i] * 1e3, nodes.position[1][i] * 1e3,
                                nodes.position[2][i] * 1e3);
    };
    for (std::size_t i = 0; i < real; ++i) {
        if (nodes.connectivity[i] != Connectivity::Fixed) continue;
        const bool collapsed = !(cell_ratio_[i] > collapsed_cell_ratio);
        if (body_mode_[static_cast<std::size_t>(nodes.body[i])] == ConnectivityMode::Fixed) {
            if (!collapsed) continue;
            // The step's report adds the step, time, phase, body and position (Simulation::step).
            throw NumericalError(
                fmt::format("a lattice cell of this fixed-connectivity node has {} (volume ratio {:.3g}); a fixed lattice "
                            "cannot follow this deformation. Give the body connectivity = \"automatic\" (nodes switch to "
                            "variable connectivity as they deform) or \"variable\"; a finer spacing helps only where the "
                            "lattice tangles at a sharp gradient, not under large flow",
                            cell_ratio_[i] <= 0.0 ? "inverted" : "collapsed", cell_ratio_[i]),
                i, "lattice cell volume ratio");
        }
        if (!collapsed && !(nodes.plastic_strain[i] > threshold)) continue;
        // The candidate lists hold every node within reach of a fixed centre too, so they stay
        // valid: the next cut applies the variable rule to the switched node's pairs.
        nodes.connectivity[i] = Connectivity::Variable;
        if (collapsed && !(nodes.plastic_strain[i] > threshold)) {
            if (report.collapse_switches++ == 0) {
                report.first_collapse_switch = fmt::format("{} (cell volume ratio {:.3g})", where(i), cell_ratio_[i]);
            }
        }
    }
    return report;
}

}  // namespace gpa
