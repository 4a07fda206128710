#include "gpa/engine/node_store.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <string_view>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/state_io.hpp"

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
        f("position", position[c]);
        f("initial_position", initial_position[c]);
        if (carries_reference_) f("reference_position", reference_position[c]);
        f("velocity", velocity[c]);
        f("alpha", alpha[c]);
        f("force", force[c]);
    }
    for (int c = 0; c < d * d; ++c) f("velocity_gradient", velocity_gradient[c]);
    for (int c = 0; c < (carries_shear_ ? (d == 3 ? 3 : 1) : 0); ++c) f("alpha_shear", alpha_shear[c]);
    for (int c = 0; c < stress_components(d); ++c) f("deviatoric_stress", deviatoric_stress[c]);
    for (int c = 0; c < (d == 3 ? 6 : 0); ++c) f("left_cauchy_green", left_cauchy_green[c]);
    f("mass", mass);
    f("volume", volume);
    f("initial_volume", initial_volume);
    f("size_weight", size_weight);
    f("diameter", diameter);
    f("initial_diameter", initial_diameter);
    f("volumetric_strain", volumetric_strain);
    f("pressure", pressure);
    f("viscous_pressure", viscous_pressure);
    f("sound_speed", sound_speed);
    f("internal_energy", internal_energy);
    f("temperature", temperature);
    f("plastic_strain", plastic_strain);
    f("plastic_strain_rate", plastic_strain_rate);
    f("damage", damage);
    f("plastic_work", plastic_work);
    f("viscous_work", viscous_work);
    f("failed", failed);
    f("plane_contact", plane_contact);
    f("velocity_region", velocity_region);
    f("stable_length", stable_length);
    f("body", body);
    f("material", material);
    f("id", id);
    f("connectivity", connectivity);
    f("volumetric_strain_rate", volumetric_strain_rate);
    f("smallest_h", smallest_h);
}

namespace {

// Grows rows with empty lists, or drops the rows of removed nodes and every entry that names a
// removed node (keeping `tags`, one per entry, aligned).
void resize_rows(CompressedRows& rows, std::vector<std::uint8_t>* tags, std::size_t count) {
    const std::size_t old_rows = rows.rows();
    if (old_rows == 0) return;  // no rows: every row is empty, however many nodes (node_store.hpp)
    if (old_rows <= count) {
        rows.offsets.resize(count + 1, rows.offsets.back());
        return;
    }
    // In place (an entry only ever moves towards the front): the ghosts go at every reorder, and a
    // copy of the lattice lists beside them was the peak of a 2D fixed run (126 bytes per node).
    std::size_t kept = 0, start = rows.offsets[0];
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t end = rows.offsets[i + 1];
        for (std::size_t k = start; k < end; ++k) {
            if (rows.indices[k] >= count) continue;
            rows.indices[kept] = rows.indices[k];
            if (tags) (*tags)[kept] = (*tags)[k];
            ++kept;
        }
        start = end;
        rows.offsets[i + 1] = kept;
    }
    rows.offsets.resize(count + 1);
    rows.indices.resize(kept);
    if (tags) tags->resize(kept);
}

// Rewrites rows in a new node order (new node k is old node new_to_old[k]).
void permute_rows(CompressedRows& rows, std::vector<std::uint8_t>* tags, std::span<const NodeIndex> new_to_old,
                  const std::vector<NodeIndex>& old_to_new) {
    if (rows.rows() == 0) return;
    CompressedRows out;
    std::vector<std::uint8_t> out_tags;
    out.offsets.reserve(new_to_old.size() + 1);
    out.indices.reserve(rows.entries());
    for (NodeIndex old : new_to_old) {
        for (std::size_t k = rows.offsets[old]; k < rows.offsets[old + 1]; ++k) {
            out.indices.push_back(old_to_new[rows.indices[k]]);
            if (tags) out_tags.push_back((*tags)[k]);
        }
        out.offsets.push_back(out.indices.size());
    }
    rows = std::move(out);
    if (tags) *tags = std::move(out_tags);
}

}  // namespace

void NodeStore::resize(std::size_t count) {
    if (count > std::size_t{0xFFFFFFFFu}) {
        throw InputError(fmt::format("node count {} exceeds the limit of 2^32 - 1 nodes", count));
    }
    // Growing past the capacity reserves 1/64 more than asked (resize_with_slack, per_node_slack),
    // not the doubling that resize() itself would do: the ghosts come and go every step, and
    // doubled fields would double the memory of a run.
    for_each_field([count](std::string_view, auto& field) { resize_with_slack(field, count); });
    resize_rows(fixed_neighbours, nullptr, count);
    resize_rows(fixed_mirrors, &fixed_mirror_planes, count);
}

void NodeStore::release_empty_lattice_rows() {
    if (fixed_neighbours.entries() == 0 && fixed_mirrors.entries() == 0) {
        fixed_neighbours = CompressedRows{};  // the arrays freed, not only emptied
        fixed_mirrors = CompressedRows{};
        fixed_mirror_planes = std::vector<std::uint8_t>{};
    }
}

void NodeStore::carry_reference_positions() {
    if (carries_reference_) return;
    carries_reference_ = true;
    for (int c = 0; c < dim_; ++c) {
        reference_position[c] = position[c];
        reference_position[c].reserve(position[c].capacity());
    }
}

void NodeStore::drop_shear_normalisation() {
    carries_shear_ = false;
    for (auto& field : alpha_shear) std::vector<double>().swap(field);
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
    for_each_field([&](std::string_view, auto& field) {
        auto copy = field;
        for (std::size_t k = 0; k < n; ++k) field[k] = copy[new_to_old[k]];
    });
    permute_rows(fixed_neighbours, nullptr, new_to_old, old_to_new);
    permute_rows(fixed_mirrors, &fixed_mirror_planes, new_to_old, old_to_new);
}

std::string describe_node(const NodeStore& nodes, std::size_t i) {
    if (nodes.dim() == 3) {
        return fmt::format("node {} at (x, y, z) = ({:.6g}, {:.6g}, {:.6g}) m", i, nodes.position[0][i],
                           nodes.position[1][i], nodes.position[2][i]);
    }
    return fmt::format("node {} at (x, z) = ({:.6g}, {:.6g}) m", i, nodes.position[0][i],
                       nodes.position[1][i]);
}

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
                                             describe_node(nodes, i), c, nodes.velocity[c][i]));
            }
        }
        if (nodes.geometry() == GeometryKind::Axisymmetric && !(nodes.position[0][i] > 0.0)) {
            throw InputError(fmt::format(
                "{}: an axisymmetric node must have radius x > 0 (Eq. 4 and 9 are singular on the "
                "axis)",
                describe_node(nodes, i)));
        }
        const auto positive = [&](const std::vector<double>& field, const char* name) {
            if (!(field[i] > 0.0) || !std::isfinite(field[i])) {
                throw InputError(fmt::format("{}: {} is {} (must be positive and finite)",
                                             describe_node(nodes, i), name, field[i]));
            }
        };
        positive(nodes.mass, "mass");
        positive(nodes.volume, "volume");
        positive(nodes.size_weight, "size weight W (area or volume)");
        positive(nodes.diameter, "diameter");
        if (d == 3) {
            // B = F F^T is positive definite: a node made without it (all zero) would silently follow
            // its volume alone under the stretch rule.
            for (int c = 0; c < 3; ++c) positive(nodes.left_cauchy_green[c], "left Cauchy-Green tensor B (diagonal)");
        }
    }
}

void update_size_weights(NodeStore& nodes, std::size_t first, std::size_t last) {
    if (nodes.geometry() == GeometryKind::Axisymmetric) {
        for (std::size_t i = first; i < last; ++i) nodes.size_weight[i] = ring_section(nodes.volume[i], nodes.position[0][i]);
    } else {
        for (std::size_t i = first; i < last; ++i) nodes.size_weight[i] = nodes.volume[i];
    }
}

// --- checkpoints --------------------------------------------------------------------------

// (Also used by simulation.cpp and ghosts.cpp, declared in state_io.hpp.)
void write_rows(StateWriter& out, const CompressedRows& rows) {
    out.array(rows.offsets);
    out.array(rows.indices);
}

void read_rows(StateReader& in, CompressedRows& rows, std::size_t row_count, std::size_t index_limit) {
    in.array(rows.offsets);
    in.array(rows.indices);
    const bool any_count = row_count == std::numeric_limits<std::size_t>::max();
    if (rows.offsets.empty() || (!any_count && rows.offsets.size() != row_count + 1) || rows.offsets.front() != 0 ||
        rows.offsets.back() != rows.indices.size()) {
        in.fail("a neighbour list does not fit its rows (a damaged checkpoint)");
    }
    for (std::size_t i = 0; i + 1 < rows.offsets.size(); ++i) {
        if (rows.offsets[i] > rows.offsets[i + 1]) in.fail("a neighbour list's offsets decrease (a damaged checkpoint)");
    }
    for (const NodeIndex j : rows.indices) {
        if (j >= index_limit) in.fail("a neighbour list names a node that does not exist (a damaged checkpoint)");
    }
}

void NodeStore::write_state(StateWriter& out) const {
    out.tag("NODE");
    out.value<std::int32_t>(static_cast<std::int32_t>(geometry_));
    out.value<std::uint64_t>(size());
    // for_each_field only reads here.
    const_cast<NodeStore*>(this)->for_each_field([&](std::string_view, auto& field) { out.array(field); });
    write_rows(out, fixed_neighbours);
    write_rows(out, fixed_mirrors);
    out.array(fixed_mirror_planes);
}

void NodeStore::read_state(StateReader& in) {
    in.tag("NODE");
    if (in.value<std::int32_t>() != static_cast<std::int32_t>(geometry_)) in.fail("its nodes are of another geometry");
    const auto count = in.value<std::uint64_t>();
    if (count > 0xFFFFFFFFu) in.fail("its node count is out of range (a damaged checkpoint)");
    for_each_field([&](std::string_view, auto& field) {
        in.array(field);
        if (field.size() != count) in.fail("a node field has the wrong length (a damaged checkpoint)");
    });
    // A row per node, or none (node_store.hpp).
    for (CompressedRows* rows : {&fixed_neighbours, &fixed_mirrors}) {
        read_rows(in, *rows, std::numeric_limits<std::size_t>::max(), count);
        if (rows->rows() != 0 && rows->rows() != count) in.fail("the lattice lists do not fit the nodes (a damaged checkpoint)");
    }
    in.array(fixed_mirror_planes);
    if (fixed_mirror_planes.size() != fixed_mirrors.entries()) in.fail("the mirrored lattice lists are damaged");
}

}  // namespace gpa

namespace gpa {

void NodeStore::memory_use(MemoryUse& out) const {
    // for_each_field only reads here.
    const_cast<NodeStore*>(this)->for_each_field(
        [&](std::string_view name, auto& field) { add_memory(out, "nodes: " + std::string(name), allocated_bytes(field)); });
    add_memory(out, "nodes: fixed neighbours", allocated_bytes(fixed_neighbours.indices) + allocated_bytes(fixed_neighbours.offsets));
    add_memory(out, "nodes: fixed mirrors",
               allocated_bytes(fixed_mirrors.indices) + allocated_bytes(fixed_mirrors.offsets) + allocated_bytes(fixed_mirror_planes));
}

}  // namespace gpa
