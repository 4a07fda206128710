#include "gpa/engine/node_store.hpp"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

CompressedRows make_compressed_rows(const std::vector<std::vector<NodeIndex>>& rows) {
    CompressedRows out;
    out.offsets.reserve(rows.size() + 1);
    for (const auto& r : rows) {
        out.indices.insert(out.indices.end(), r.begin(), r.end());
        out.offsets.push_back(out.indices.size());
    }
    return out;
}

NodeStore::NodeStore(GeometryKind geometry, std::size_t count)
    : geometry_(geometry), dim_(dimension_of(geometry)) {
    resize(count);
}

template <class F>
void NodeStore::for_each_field(F&& f) {
    const int d = dim_;
    for (int c = 0; c < d; ++c) {
        f(position[c]);
        f(velocity[c]);
        f(alpha[c]);
        f(force[c]);
    }
    for (int c = 0; c < d * d; ++c) f(velocity_gradient[c]);
    for (int c = 0; c < stress_components(d); ++c) f(deviatoric_stress[c]);
    f(mass);
    f(volume);
    f(initial_volume);
    f(size_weight);
    f(diameter);
    f(initial_diameter);
    f(initial_radius);
    f(volumetric_strain);
    f(pressure);
    f(viscous_pressure);
    f(sound_speed);
    f(internal_energy);
    f(temperature);
    f(plastic_strain);
    f(damage);
    f(body);
    f(material);
    f(connectivity);
    f(volumetric_strain_rate);
    f(smallest_h);
}

void NodeStore::resize(std::size_t count) {
    if (count > std::size_t{0xFFFFFFFFu}) {
        throw InputError(fmt::format("node count {} exceeds the limit of 2^32 - 1 nodes", count));
    }
    for_each_field([count](auto& field) { field.resize(count); });
    const std::size_t rows = fixed_neighbours.rows();
    if (rows < count) {
        fixed_neighbours.offsets.resize(count + 1, fixed_neighbours.offsets.back());
    } else if (rows > count) {
        fixed_neighbours.offsets.resize(count + 1);
        fixed_neighbours.indices.resize(fixed_neighbours.offsets.back());
        // Lists of the remaining nodes may still name removed nodes; drop those entries.
        CompressedRows kept;
        kept.offsets.reserve(count + 1);
        for (std::size_t i = 0; i < count; ++i) {
            for (NodeIndex j : fixed_neighbours.row(i)) {
                if (j < count) kept.indices.push_back(j);
            }
            kept.offsets.push_back(kept.indices.size());
        }
        fixed_neighbours = std::move(kept);
    }
}

void NodeStore::permute(std::span<const NodeIndex> new_to_old) {
    const std::size_t n = size();
    if (new_to_old.size() != n) {
        throw InputError(fmt::format("NodeStore::permute: permutation has {} entries for {} nodes",
                                     new_to_old.size(), n));
    }
    std::vector<NodeIndex> old_to_new(n, NodeIndex(-1));
    for (std::size_t k = 0; k < n; ++k) {
        const NodeIndex old = new_to_old[k];
        if (old >= n || old_to_new[old] != NodeIndex(-1)) {
            throw InputError(fmt::format(
                "NodeStore::permute: entry {} (= {}) repeats a node or is out of range", k, old));
        }
        old_to_new[old] = static_cast<NodeIndex>(k);
    }
    for_each_field([&](auto& field) {
        auto copy = field;
        for (std::size_t k = 0; k < n; ++k) field[k] = copy[new_to_old[k]];
    });
    CompressedRows remapped;
    remapped.offsets.reserve(n + 1);
    remapped.indices.reserve(fixed_neighbours.entries());
    for (std::size_t k = 0; k < n; ++k) {
        for (NodeIndex j : fixed_neighbours.row(new_to_old[k])) remapped.indices.push_back(old_to_new[j]);
        remapped.offsets.push_back(remapped.indices.size());
    }
    fixed_neighbours = std::move(remapped);
}

namespace {

std::string where(const NodeStore& nodes, std::size_t i) {
    if (nodes.dim() == 3) {
        return fmt::format("node {} at (x, y, z) = ({:.6g}, {:.6g}, {:.6g}) m", i, nodes.position[0][i],
                           nodes.position[1][i], nodes.position[2][i]);
    }
    return fmt::format("node {} at (x, z) = ({:.6g}, {:.6g}) m", i, nodes.position[0][i],
                       nodes.position[1][i]);
}

}  // namespace

void validate_nodes(const NodeStore& nodes, std::size_t first, std::size_t last) {
    const int d = nodes.dim();
    for (std::size_t i = first; i < last; ++i) {
        for (int c = 0; c < d; ++c) {
            if (!std::isfinite(nodes.position[c][i])) {
                throw InputError(fmt::format("node {}: coordinate {} is {} (must be finite)", i, c,
                                             nodes.position[c][i]));
            }
            if (!std::isfinite(nodes.velocity[c][i])) {
                throw InputError(fmt::format("{}: velocity component {} is {} (must be finite)",
                                             where(nodes, i), c, nodes.velocity[c][i]));
            }
        }
        if (nodes.geometry() == GeometryKind::Axisymmetric && !(nodes.position[0][i] > 0.0)) {
            throw InputError(fmt::format(
                "{}: an axisymmetric node must have radius x > 0 (Eq. 4 and 9 are singular on the "
                "axis)",
                where(nodes, i)));
        }
        const auto positive = [&](const std::vector<double>& field, const char* name) {
            if (!(field[i] > 0.0) || !std::isfinite(field[i])) {
                throw InputError(fmt::format("{}: {} is {} (must be positive and finite)",
                                             where(nodes, i), name, field[i]));
            }
        };
        positive(nodes.mass, "mass");
        positive(nodes.volume, "volume");
        positive(nodes.size_weight, "size weight W (area or volume)");
        positive(nodes.diameter, "diameter");
    }
}

void update_size_weights(NodeStore& nodes, std::size_t first, std::size_t last) {
    if (nodes.geometry() == GeometryKind::Axisymmetric) {
        for (std::size_t i = first; i < last; ++i) {
            // Eq. 4: A = V / (2 pi x)
            nodes.size_weight[i] = nodes.volume[i] / (2.0 * std::numbers::pi * nodes.position[0][i]);
        }
    } else {
        for (std::size_t i = first; i < last; ++i) nodes.size_weight[i] = nodes.volume[i];
    }
}

}  // namespace gpa
