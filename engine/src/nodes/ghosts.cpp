#include "gpa/engine/ghosts.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/state_io.hpp"
#include "reduce_grain.hpp"

namespace gpa {

namespace {

// Ghost k of [first, last) takes its source's value: field[real + k] = field[source[k]].
template <class T>
void copy_to_ghosts(T* field, const NodeIndex* source, std::size_t real_count, std::size_t first, std::size_t last) {
    for (std::size_t k = first; k != last; ++k) field[real_count + k] = field[source[k]];
}

std::array<double*, 3> vector_field(std::array<std::vector<double>, 3>& field) {
    return {field[0].data(), field[1].data(), field[2].data()};
}

}  // namespace

void mirror_stress(int dim, int axis, std::array<double, 6>& s) {
    if (dim == 2) {
        s[2] = -s[2];  // xz: one index along x or along z, whichever the normal is
        return;
    }
    // 3D order xx, yy, zz, yz, xz, xy
    switch (axis) {
        case 0: s[4] = -s[4]; s[5] = -s[5]; break;
        case 1: s[3] = -s[3]; s[5] = -s[5]; break;
        default: s[3] = -s[3]; s[4] = -s[4]; break;
    }
}

void GhostPlane::reflect_tensor(int dim, std::array<double, 6>& s) const {
    if (axis >= 0) {
        mirror_stress(dim, axis, s);
        return;
    }
    // H S H with H = I - 2 n n^T: S - 2 n (S n)^T - 2 (S n) n^T + 4 (n . S n) n n^T.
    const auto& n = normal;
    if (dim == 2) {
        const double sn0 = s[0] * n[0] + s[2] * n[1], sn1 = s[2] * n[0] + s[1] * n[1];
        const double nsn = n[0] * sn0 + n[1] * sn1;
        const auto entry = [&](double sij, int i, int j, double sni, double snj) {
            return sij - 2.0 * (n[i] * snj + sni * n[j]) + 4.0 * nsn * n[i] * n[j];
        };
        const double xx = entry(s[0], 0, 0, sn0, sn0), zz = entry(s[1], 1, 1, sn1, sn1), xz = entry(s[2], 0, 1, sn0, sn1);
        s[0] = xx, s[1] = zz, s[2] = xz;  // the out-of-plane component is unchanged
        return;
    }
    // 3D order xx, yy, zz, yz, xz, xy
    const double m[3][3] = {{s[0], s[5], s[4]}, {s[5], s[1], s[3]}, {s[4], s[3], s[2]}};
    double sn[3];
    for (int i = 0; i < 3; ++i) sn[i] = m[i][0] * n[0] + m[i][1] * n[1] + m[i][2] * n[2];
    const double nsn = n[0] * sn[0] + n[1] * sn[1] + n[2] * sn[2];
    const auto entry = [&](int i, int j) { return m[i][j] - 2.0 * (n[i] * sn[j] + sn[i] * n[j]) + 4.0 * nsn * n[i] * n[j]; };
    s = {entry(0, 0), entry(1, 1), entry(2, 2), entry(1, 2), entry(0, 2), entry(0, 1)};
}

bool perpendicular(const GhostPlane& a, const GhostPlane& b) {
    if (a.axis >= 0 && b.axis >= 0) return a.axis != b.axis;
    const auto n = a.unit_normal(), m = b.unit_normal();
    return std::abs(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) < 1e-9;
}

GhostSet::GhostSet(std::vector<GhostPlane> planes) : planes_(std::move(planes)) {
    if (planes_.size() > 8) throw InputError(fmt::format("at most 8 planes with ghosts, got {}", planes_.size()));
    // Every non-empty combination of planes with mutually perpendicular normals (corners and
    // edges): their reflections commute, and a corner ghost is the image across all of them. Planes
    // meeting at another angle (or parallel) are not combined; near such a corner each acts alone.
    for (unsigned m = 1; m < (1u << planes_.size()); ++m) {
        bool combines = true;
        for (std::size_t p = 0; p < planes_.size(); ++p) {
            for (std::size_t q = p + 1; q < planes_.size(); ++q) {
                if (((m >> p) & 1u) && ((m >> q) & 1u) && !perpendicular(planes_[p], planes_[q])) combines = false;
            }
        }
        if (combines) masks_.push_back(static_cast<std::uint8_t>(m));
    }
    std::stable_sort(masks_.begin(), masks_.end(), [](std::uint8_t a, std::uint8_t b) { return std::popcount(a) < std::popcount(b); });
    for (std::size_t p = 0; p < planes_.size(); ++p) {
        if (planes_[p].lift_off) lift_off_mask_ |= static_cast<std::uint8_t>(1u << p);
    }
}

void GhostSet::update_contacts(NodeStore& nodes, std::size_t real_count, bool initial) const {
    if (lift_off_mask_ == 0) return;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real_count, costly_node_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::uint8_t bits = nodes.plane_contact[i];
            for (std::size_t p = 0; p < planes_.size(); ++p) {
                if (!planes_[p].lift_off) continue;
                const auto bit = static_cast<std::uint8_t>(1u << p);
                const GhostPlane& plane = planes_[p];
                const double gap = plane.distance_of(nodes.position, i);
                const bool close = gap < 0.75 * nodes.diameter[i];
                if (initial) {
                    bits = close ? (bits | bit) : (bits & ~bit);
                } else if (bits & bit) {
                    // sigma_nn = s_nn - P - Q: tension (> 0) releases the node.
                    double s_nn = 0.0;
                    if (plane.axis >= 0) {
                        s_nn = nodes.deviatoric_stress[plane.axis][i];
                    } else {
                        std::array<double, 6> t{};
                        for (int c = 0; c < stress_components(nodes.dim()); ++c) t[c] = nodes.deviatoric_stress[c][i];
                        const auto& n = plane.normal;
                        s_nn = nodes.dim() == 2 ? t[0] * n[0] * n[0] + t[1] * n[1] * n[1] + 2.0 * t[2] * n[0] * n[1]
                                                : t[0] * n[0] * n[0] + t[1] * n[1] * n[1] + t[2] * n[2] * n[2] +
                                                      2.0 * (t[3] * n[1] * n[2] + t[4] * n[0] * n[2] + t[5] * n[0] * n[1]);
                    }
                    const double normal_stress = s_nn - nodes.pressure[i] - nodes.viscous_pressure[i];
                    if (normal_stress > 0.0 || !close) bits &= static_cast<std::uint8_t>(~bit);
                } else if (close && plane.side * plane.coordinate_of(nodes.velocity, i) < 0.0) {
                    bits |= bit;
                }
            }
            nodes.plane_contact[i] = bits;
        }
    });
}

void GhostSet::remove_pairs_without_contact(CompressedRows& lists, const NodeStore& nodes, std::size_t real_count) const {
    if (lift_off_mask_ == 0) return;
    std::size_t out = 0, start = 0;
    for (std::size_t i = 0; i < real_count; ++i) {
        const std::size_t end = lists.offsets[i + 1];
        for (std::size_t e = start; e < end; ++e) {
            const NodeIndex j = lists.indices[e];
            if (j >= real_count) {
                const std::size_t k = j - real_count;
                if (!allowed(nodes, i, mask_[k]) || !allowed(nodes, source_[k], mask_[k])) continue;
            }
            lists.indices[out++] = j;
        }
        start = end;
        lists.offsets[i + 1] = out;
    }
    lists.indices.resize(out);
}

std::vector<MirrorPlane> GhostSet::mirror_planes() const {
    std::vector<MirrorPlane> out;
    for (std::size_t p = 0; p < planes_.size(); ++p) {
        out.push_back({planes_[p].axis, planes_[p].position, planes_[p].side, static_cast<int>(p), planes_[p].normal});
    }
    return out;
}

std::size_t GhostSet::mask_slot(std::uint8_t mask) const {
    const auto it = std::find(masks_.begin(), masks_.end(), mask);
    if (it == masks_.end()) throw NumericalError(fmt::format("ghost mask {} combines planes with the same normal", mask));
    return static_cast<std::size_t>(it - masks_.begin());
}

std::int64_t GhostSet::ghost_of(NodeIndex node, std::size_t slot) const {
    const auto it = std::lower_bound(sources_sorted_.begin(), sources_sorted_.end(), node);
    if (it == sources_sorted_.end() || *it != node) return -1;
    return ghost_table_[static_cast<std::size_t>(it - sources_sorted_.begin()) * masks_.size() + slot];
}

void GhostSet::build(NodeStore& nodes, std::size_t real_count, GhostReach reach, bool keep_between_searches) {
    keep_between_searches_ = keep_between_searches;
    source_.clear();
    mask_.clear();
    slot_.clear();
    sources_sorted_.clear();
    ghost_table_.clear();
    table_real_count_ = real_count;
    if (planes_.empty()) {
        nodes.resize(real_count);
        return;
    }
    // Which (source, mask) pairs are needed: nodes near all planes of a mask, and both ends of
    // every mirrored lattice pair.
    std::vector<std::vector<std::uint8_t>> needed(masks_.size(), std::vector<std::uint8_t>(real_count, 0));
    for (std::size_t slot = 0; slot < masks_.size(); ++slot) {
        const std::uint8_t m = masks_[slot];
        auto& want = needed[slot];
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real_count, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                bool near = selectable(nodes, i, m);
                const double range = reach.of(nodes.diameter[i]);
                for (std::size_t p = 0; p < planes_.size() && near; ++p) {
                    if ((m >> p) & 1u) near = planes_[p].distance_of(nodes.position, i) < range;
                }
                want[i] = near;
            }
        });
    }
    for (std::size_t i = 0; i < nodes.fixed_mirrors.rows() && i < real_count; ++i) {
        if (nodes.connectivity[i] != Connectivity::Fixed) continue;
        for (std::size_t k = nodes.fixed_mirrors.offsets[i]; k < nodes.fixed_mirrors.offsets[i + 1]; ++k) {
            const std::uint8_t m = nodes.fixed_mirror_planes[k];
            const NodeIndex j = nodes.fixed_mirrors.indices[k];
            if (!selectable(nodes, i, m) || !selectable(nodes, j, m)) continue;
            const std::size_t slot = mask_slot(m);
            needed[slot][j] = 1;
            needed[slot][i] = 1;
        }
    }
    if (real_count * (masks_.size() + 1) > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
        throw InputError(fmt::format("{} nodes: too many for the ghost index (32-bit)", real_count));
    }
    for (std::size_t slot = 0; slot < masks_.size(); ++slot) {
        for (std::size_t i = 0; i < real_count; ++i) {
            if (!needed[slot][i]) continue;
            source_.push_back(static_cast<NodeIndex>(i));
            mask_.push_back(masks_[slot]);
            slot_.push_back(static_cast<std::uint8_t>(slot));
        }
    }
    std::vector<std::vector<std::uint8_t>>().swap(needed);
    sources_sorted_ = source_;
    std::sort(sources_sorted_.begin(), sources_sorted_.end());
    sources_sorted_.erase(std::unique(sources_sorted_.begin(), sources_sorted_.end()), sources_sorted_.end());
    ghost_table_.assign(sources_sorted_.size() * masks_.size(), -1);
    for (std::size_t k = 0; k < source_.size(); ++k) {
        const auto row = static_cast<std::size_t>(std::lower_bound(sources_sorted_.begin(), sources_sorted_.end(), source_[k]) -
                                                  sources_sorted_.begin());
        ghost_table_[row * masks_.size() + slot_[k]] = static_cast<std::int32_t>(real_count + k);
    }
    nodes.resize(real_count + source_.size());
    update(nodes, real_count);
    refresh(nodes, real_count);
}

void GhostSet::update(NodeStore& nodes, std::size_t real_count) const {
    const int dim = nodes.dim();
    const std::size_t ghosts = source_.size();
    if (nodes.size() != real_count + ghosts) {
        throw NumericalError(fmt::format("GhostSet::update: {} nodes for {} real and {} ghosts", nodes.size(), real_count, ghosts));
    }
    // Field by field, each copied in a loop of its own (copy_to_ghosts): one loop over every field
    // would load each field's address again after every byte it stores (a byte may alias anything).
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ghosts, ghost_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        mirror_to_ghosts(vector_field(nodes.position), dim, real_count, r.begin(), r.end(), Mirrored::Point);
        mirror_to_ghosts(vector_field(nodes.velocity), dim, real_count, r.begin(), r.end(), Mirrored::Vector);
        mirror_to_ghosts(vector_field(nodes.initial_position), dim, real_count, r.begin(), r.end(), Mirrored::Point);
        if (nodes.carries_reference_positions()) {
            mirror_to_ghosts(vector_field(nodes.reference_position), dim, real_count, r.begin(), r.end(), Mirrored::Point);
        }
        const NodeIndex* source = source_.data();
        copy_to_ghosts(nodes.mass.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.volume.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.initial_volume.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.size_weight.data(), source, real_count, r.begin(), r.end());  // across the axis A_j > 0 stays
        copy_to_ghosts(nodes.diameter.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.initial_diameter.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.connectivity.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.body.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.id.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.material.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.failed.data(), source, real_count, r.begin(), r.end());
    });
}

void GhostSet::mirror_vector_field(const std::array<double*, 3>& field, int dim, std::size_t real_count) const {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, source_.size(), ghost_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        mirror_to_ghosts(field, dim, real_count, r.begin(), r.end(), Mirrored::Vector);
    });
}

void GhostSet::mirror_to_ghosts(const std::array<double*, 3>& field, int dim, std::size_t real_count, std::size_t first,
                                std::size_t last, Mirrored kind) const {
    const std::array<double*, 3> f = field;  // the addresses in registers, not reloaded after each store
    const NodeIndex* source = source_.data();
    const std::uint8_t* mask = mask_.data();
    for (std::size_t k = first; k != last; ++k) {
        const std::size_t s = source[k];
        std::array<double, 3> x{0, 0, 0};
        for (int c = 0; c < dim; ++c) x[c] = f[c][s];
        for (std::size_t p = 0; p < planes_.size(); ++p) {
            if (!((mask[k] >> p) & 1u)) continue;
            if (kind == Mirrored::Point) {
                planes_[p].reflect_point(x);
            } else {
                planes_[p].reflect_vector(x);
            }
        }
        for (int c = 0; c < dim; ++c) f[c][real_count + k] = x[c];
    }
}

GhostReach GhostSet::pair_reach(const NodeStore& nodes, std::size_t real_count, double influence_distance, double margin) const {
    const double a = influence_distance;
    const double deepest = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, real_count, costly_node_grain), -std::numeric_limits<double>::infinity(),
        [&](const tbb::blocked_range<std::size_t>& r, double acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                for (const GhostPlane& p : planes_) acc = std::max(acc, a * nodes.diameter[i] - p.distance_of(nodes.position, i));
            }
            return acc;
        },
        [](double x, double y) { return std::max(x, y); });
    // A non-finite diameter or position: every node near a plane gets its ghosts (the phases report it).
    if (!std::isfinite(deepest)) return GhostReach{std::numeric_limits<double>::infinity(), 0.0};
    return GhostReach{deepest + margin, a};
}

bool GhostSet::covers(const NodeStore& nodes, std::size_t real_count, GhostReach reach) const {
    if (planes_.empty()) return true;
    if (table_real_count_ != real_count) return false;
    const std::size_t slots = masks_.size();
    for (std::size_t slot = 0; slot < slots; ++slot) {
        const std::uint8_t m = masks_[slot];
        const bool missing = tbb::parallel_reduce(
            tbb::blocked_range<std::size_t>(0, real_count, costly_node_grain), false,
            [&](const tbb::blocked_range<std::size_t>& r, bool found) {
                // The sources of the range walked alongside its nodes (both ascending).
                auto source = std::lower_bound(sources_sorted_.begin(), sources_sorted_.end(), static_cast<NodeIndex>(r.begin()));
                for (std::size_t i = r.begin(); i != r.end() && !found; ++i) {
                    while (source != sources_sorted_.end() && *source < i) ++source;
                    const bool has_ghost = source != sources_sorted_.end() && *source == i &&
                                           ghost_table_[static_cast<std::size_t>(source - sources_sorted_.begin()) * slots + slot] >= 0;
                    if (has_ghost || !selectable(nodes, i, m)) continue;
                    bool near = true;
                    const double range = reach.of(nodes.diameter[i]);
                    for (std::size_t p = 0; p < planes_.size() && near; ++p) {
                        if ((m >> p) & 1u) near = planes_[p].distance_of(nodes.position, i) < range;
                    }
                    found = near;
                }
                return found;
            },
            [](bool x, bool y) { return x || y; });
        if (missing) return false;
    }
    return true;
}

double GhostSet::mirrored_displacement_bound(const NodeStore& nodes, std::size_t real_count,
                                             const std::array<std::vector<double>, 3>& reference) const {
    const int dim = nodes.dim();
    double bound = 0.0;
    for (const std::uint8_t m : masks_) {
        // The middle of the displacements of this combination's sources, normal parts zeroed.
        std::array<double, 3> lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
        bool any = false;
        for (std::size_t k = 0; k < source_.size(); ++k) {
            if (mask_[k] != m) continue;
            any = true;
            for (int c = 0; c < dim; ++c) {
                const double u = nodes.position[c][source_[k]] - reference[c][source_[k]];
                lo[c] = std::min(lo[c], u);
                hi[c] = std::max(hi[c], u);
            }
        }
        if (!any) continue;
        std::array<double, 3> middle{0, 0, 0};
        for (int c = 0; c < dim; ++c) middle[c] = 0.5 * (lo[c] + hi[c]);
        for (std::size_t p = 0; p < planes_.size(); ++p) {  // the parts along the (perpendicular) normals removed
            if (!((m >> p) & 1u)) continue;
            if (planes_[p].axis >= 0) {
                middle[planes_[p].axis] = 0.0;
                continue;
            }
            const auto& n = planes_[p].normal;
            const double along = n[0] * middle[0] + n[1] * middle[1] + n[2] * middle[2];
            for (int c = 0; c < 3; ++c) middle[c] -= along * n[c];
        }
        double largest = 0.0;
        for (std::size_t k = 0; k < source_.size(); ++k) {
            if (mask_[k] != m) continue;
            double u2 = 0.0;
            for (int c = 0; c < dim; ++c) {
                const double u = nodes.position[c][source_[k]] - reference[c][source_[k]] - middle[c];
                u2 += u * u;
            }
            largest = std::max(largest, u2);
        }
        bound = std::max(bound, 2.0 * std::sqrt(largest));
    }
    return bound;
}

void GhostSet::refresh(NodeStore& nodes, std::size_t real_count) const {
    const int dim = nodes.dim();
    const int comps = stress_components(dim);
    // The normalisation is a symmetric tensor too. Across an aligned plane its diagonal (alpha) is
    // unchanged and its off-diagonal entries (alpha_shear) flip like the shear stresses. Across an
    // oblique one it is H A H; the per-direction normalisation, which keeps the diagonal only (its
    // alpha_shear is zero), takes the diagonal of H A H: the frame-dependence of that normalisation
    // (docs/orientation.md, "Oblique planes in the step").
    // (A store without alpha_shear, dropped for the per-direction normalisation: the diagonal alone.)
    const int first_shear = dim == 2 ? 2 : 3, shears = !nodes.carries_shear_normalisation() ? 0 : (dim == 2 ? 1 : 3);
    std::array<double*, 6> stress{}, normalisation{};
    for (int c = 0; c < comps; ++c) stress[c] = nodes.deviatoric_stress[c].data();
    for (int c = 0; c < dim; ++c) normalisation[c] = nodes.alpha[c].data();
    for (int c = 0; c < shears; ++c) normalisation[first_shear + c] = nodes.alpha_shear[c].data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, source_.size(), ghost_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        // Field by field, as in update().
        mirror_tensors_to_ghosts(stress, comps, dim, real_count, r.begin(), r.end());
        mirror_tensors_to_ghosts(normalisation, first_shear + shears, dim, real_count, r.begin(), r.end());
        const NodeIndex* source = source_.data();
        copy_to_ghosts(nodes.pressure.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.viscous_pressure.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.sound_speed.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.volume.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.damage.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.failed.data(), source, real_count, r.begin(), r.end());
        copy_to_ghosts(nodes.smallest_h.data(), source, real_count, r.begin(), r.end());
    });
}

void GhostSet::mirror_tensors_to_ghosts(const std::array<double*, 6>& field, int components, int dim, std::size_t real_count,
                                        std::size_t first, std::size_t last) const {
    // A symmetric tensor in NodeStore order, its entries beyond `components` zero (and not stored),
    // mirrored across every plane of the ghost's mask.
    const std::array<double*, 6> f = field;
    const NodeIndex* source = source_.data();
    const std::uint8_t* mask = mask_.data();
    for (std::size_t k = first; k != last; ++k) {
        const std::size_t s = source[k];
        std::array<double, 6> t{};
        for (int c = 0; c < components; ++c) t[c] = f[c][s];
        for (std::size_t p = 0; p < planes_.size(); ++p) {
            if ((mask[k] >> p) & 1u) planes_[p].reflect_tensor(dim, t);
        }
        for (int c = 0; c < components; ++c) f[c][real_count + k] = t[c];
    }
}

const CompressedRows& GhostSet::resolved_fixed_mirrors(const NodeStore& nodes, std::size_t real_count) {
    resolved_.offsets.assign(1, 0);
    resolved_.indices.clear();
    // No rows where the nodes have no mirrored lattice neighbours (node_store.hpp): every row
    // reads as empty (CompressedRows::row_or_empty), and there is no offset per node to keep.
    if (nodes.fixed_mirrors.rows() == 0) {
        resolved_.offsets.shrink_to_fit();
        return resolved_;
    }
    for (std::size_t i = 0; i < real_count; ++i) {
        const bool fixed = nodes.connectivity[i] == Connectivity::Fixed;  // variable nodes find their ghosts by search
        for (std::size_t k = nodes.fixed_mirrors.offsets[i]; fixed && k < nodes.fixed_mirrors.offsets[i + 1]; ++k) {
            const std::uint8_t m = nodes.fixed_mirror_planes[k];
            const NodeIndex j = nodes.fixed_mirrors.indices[k];
            if (!selectable(nodes, i, m) || !selectable(nodes, j, m)) continue;  // not touching a lift-off plane
            const std::int64_t g = ghost_of(j, mask_slot(m));
            if (g < 0) throw NumericalError(fmt::format("node {}: its mirrored lattice neighbour has no ghost", i));
            resolved_.indices.push_back(static_cast<NodeIndex>(g));
        }
        resolved_.offsets.push_back(resolved_.indices.size());
    }
    return resolved_;
}

void GhostSet::append_ghost_rows(CompressedRows& lists, std::size_t real_count) const {
    const std::size_t ghosts = source_.size();
    if (lists.rows() != real_count) {
        throw NumericalError(fmt::format("append_ghost_rows: {} rows for {} real nodes", lists.rows(), real_count));
    }
    // Ghost centre mirror(s, S) gets real j for every entry mirror(j, S) of s's list. Only a node
    // with ghosts of its own can list a ghost (it is then within reach of the same planes), so
    // only those rows are read. A ghost row takes entries from its own source's row only, so both
    // passes below run over the sources in parallel without two writing one place, and a row's
    // entries keep the order of its source's row whatever the threads.
    // The ghost rows an entry goes to: s's own ghost across the planes of the ghost it lists, looked
    // up in the source's row of the ghost table (a slot per combination of planes), by the entry's slot.
    const std::size_t slots = masks_.size();
    if (ghost_table_.size() != sources_sorted_.size() * slots) {
        throw NumericalError(fmt::format("append_ghost_rows: a ghost table of {} entries for {} sources", ghost_table_.size(),
                                         sources_sorted_.size()));
    }
    constexpr std::size_t grain = 256;  // sources per task
    const tbb::blocked_range<std::size_t> all_sources(0, sources_sorted_.size(), grain);
    std::vector<std::size_t> count(ghosts + 1, 0);  // count[t + 1] for ghost t
    std::atomic<std::size_t> first_missing{std::numeric_limits<std::size_t>::max()};  // the smallest source at fault
    tbb::parallel_for(all_sources, [&](const tbb::blocked_range<std::size_t>& r) {
        // The arrays' addresses and each row's end as locals: a store to count[] or next[] may
        // alias the offsets, so the loop would load them again after every entry.
        const NodeIndex* const indices = lists.indices.data();
        const std::uint8_t* const slot_of = slot_.data();
        std::size_t* const counts = count.data();
        // Slots of this task's own that the entries which count nothing add 0 to, the next of them
        // for each entry (below).
        constexpr std::size_t spare = 8;
        std::array<std::size_t, spare> nothing{};
        for (std::size_t q = r.begin(); q != r.end(); ++q) {
            const NodeIndex s = sources_sorted_[q];
            const std::int32_t* const ghost_of = ghost_table_.data() + q * slots;
            const std::size_t last = lists.offsets[s + 1];
            bool missing = false;
            // Without a branch on whether an entry is a ghost, which no predictor guesses (about a
            // quarter of a source's entries are): an entry that counts nothing adds 0 to one of
            // the task's spare slots. One slot for them all made each addition wait for the last
            // one's store; spare slots in the shared count bounced their cache line between the
            // threads (docs/performance.md section 5 has the figures).
            for (std::size_t e = lists.offsets[s]; e < last; ++e) {
                const NodeIndex j = indices[e];
                const bool ghost = j >= real_count;
                const std::int32_t t = ghost_of[slot_of[ghost ? j - real_count : 0]];
                const bool counted = ghost && t >= 0;
                missing |= ghost && t < 0;
                *(counted ? counts + (static_cast<std::size_t>(t) - real_count + 1) : nothing.data() + e % spare) += counted;
            }
            if (missing) {
                std::size_t seen = first_missing.load();
                while (s < seen && !first_missing.compare_exchange_weak(seen, s)) {
                }
            }
        }
    });
    if (const std::size_t s = first_missing.load(); s != std::numeric_limits<std::size_t>::max()) {
        throw NumericalError(fmt::format("node {} lists a ghost whose mirror pair is missing (the ghost range is too short)", s));
    }
    const std::size_t base = lists.entries();
    resize_with_slack(lists.offsets, real_count + ghosts + 1);
    for (std::size_t k = 0; k < ghosts; ++k) {
        count[k + 1] += count[k];
        lists.offsets[real_count + k + 1] = base + count[k + 1];
    }
    resize_with_slack(lists.indices, base + count[ghosts], per_entry_slack);
    std::vector<std::size_t> next(ghosts);
    for (std::size_t k = 0; k < ghosts; ++k) next[k] = base + count[k];
    tbb::parallel_for(all_sources, [&](const tbb::blocked_range<std::size_t>& r) {
        NodeIndex* const indices = lists.indices.data();
        const std::uint8_t* const slot_of = slot_.data();
        const NodeIndex* const sources = source_.data();
        std::size_t* const place = next.data();
        for (std::size_t q = r.begin(); q != r.end(); ++q) {
            const NodeIndex s = sources_sorted_[q];
            const std::int32_t* const ghost_of = ghost_table_.data() + q * slots;
            const std::size_t last = lists.offsets[s + 1];
            // (Here the branch stays: without it, every real entry would add 0 to one place, a chain
            // of loads and stores through memory that costs more than the guesses it misses.)
            for (std::size_t e = lists.offsets[s]; e < last; ++e) {
                const NodeIndex j = indices[e];
                if (j < real_count) continue;
                const auto t = static_cast<std::size_t>(ghost_of[slot_of[j - real_count]]) - real_count;
                indices[place[t]++] = sources[j - real_count];
            }
        }
    });
}

const std::uint8_t* GhostSet::continuing_flags() {
    std::uint8_t planes = 0;
    for (std::size_t p = 0; p < planes_.size(); ++p) {
        if (planes_[p].continues_body) planes |= static_cast<std::uint8_t>(1u << p);
    }
    if (planes == 0) return nullptr;
    continues_.resize(source_.size());
    for (std::size_t k = 0; k < source_.size(); ++k) continues_[k] = (mask_[k] & ~planes) == 0 ? 1 : 0;
    return continues_.data();
}

void GhostSet::save_forces(const NodeStore& nodes, std::size_t real_count) {
    for (int c = 0; c < nodes.dim(); ++c) {
        saved_force_[c].assign(nodes.force[c].begin() + static_cast<std::ptrdiff_t>(real_count),
                               nodes.force[c].begin() + static_cast<std::ptrdiff_t>(real_count + source_.size()));
    }
}

void GhostSet::fold_forces(NodeStore& nodes, std::size_t real_count) const {
    const int dim = nodes.dim();
    for (std::size_t k = 0; k < source_.size(); ++k) {
        if (continues_.size() != source_.size() || !continues_[k]) continue;
        const std::size_t g = real_count + k, s = source_[k];
        std::array<double, 3> change{0, 0, 0};
        for (int c = 0; c < dim; ++c) change[c] = nodes.force[c][g] - saved_force_[c][k];
        for (std::size_t p = 0; p < planes_.size(); ++p) {
            if ((mask_[k] >> p) & 1u) planes_[p].reflect_vector(change);
        }
        for (int c = 0; c < dim; ++c) {
            nodes.force[c][s] += change[c];
            nodes.force[c][g] = saved_force_[c][k];
        }
    }
}

std::vector<double> GhostSet::normal_reactions(const NodeStore& nodes, std::size_t real_count) const {
    std::vector<double> reaction(planes_.size(), 0.0);
    for (std::size_t k = 0; k < source_.size(); ++k) {
        for (std::size_t p = 0; p < planes_.size(); ++p) {
            if ((mask_[k] >> p) & 1u) {
                reaction[p] -= planes_[p].side * planes_[p].coordinate_of(nodes.force, real_count + k);
            }
        }
    }
    return reaction;
}

template <class IO, class Self>
void GhostSet::state_fields(IO& io, Self& self, std::size_t real_count, std::size_t node_count) {
    io.tag("GHST");
    io.expect(self.planes_.size(), "its planes are not the scene's");
    io.expect(self.masks_.size(), "its planes are not the scene's");
    io.field(self.source_);
    io.field(self.mask_);
    io.field(self.slot_);
    io.field(self.sources_sorted_);
    io.field(self.table_real_count_);
    io.field(self.ghost_table_);
    io.field(self.keep_between_searches_);
    io.field(self.resolved_.offsets);
    io.field(self.resolved_.indices);
    if constexpr (IO::reading) self.check_restored(io, real_count, node_count);
}

void GhostSet::write_state(StateWriter& out) const { state_fields(out, *this, 0, 0); }
void GhostSet::read_state(StateReader& in, std::size_t real_count, std::size_t node_count) { state_fields(in, *this, real_count, node_count); }

// What a checkpoint's ghosts must satisfy (read_state, once every field is read).
void GhostSet::check_restored(StateReader& in, std::size_t real_count, std::size_t node_count) const {
    const std::size_t ghosts = source_.size();
    if (mask_.size() != ghosts || slot_.size() != ghosts || real_count + ghosts != node_count) {
        in.fail("its ghosts do not match its nodes (a damaged checkpoint)");
    }
    for (std::size_t k = 0; k < ghosts; ++k) {
        if (source_[k] >= real_count || slot_[k] >= masks_.size()) in.fail("a ghost has no source (a damaged checkpoint)");
    }
    for (std::size_t q = 0; q < sources_sorted_.size(); ++q) {
        if (sources_sorted_[q] >= real_count) in.fail("a ghost source does not exist (a damaged checkpoint)");
        if (q > 0 && !(sources_sorted_[q - 1] < sources_sorted_[q])) in.fail("the ghost sources are out of order (a damaged checkpoint)");
    }
    // The table: one row per source, its entries -1 or a ghost of that source across that
    // combination, and every ghost in its place (ghost_of then finds each ghost, and only ghosts).
    if (ghost_table_.size() != sources_sorted_.size() * masks_.size() || (!source_.empty() && table_real_count_ != real_count)) {
        in.fail("a ghost table has the wrong length (a damaged checkpoint)");
    }
    std::size_t listed = 0;
    for (std::size_t e = 0; e < ghost_table_.size(); ++e) {
        const std::int32_t g = ghost_table_[e];
        if (g == -1) continue;
        const std::size_t k = static_cast<std::size_t>(g) - real_count;
        if (g < 0 || static_cast<std::size_t>(g) < real_count || k >= ghosts || source_[k] != sources_sorted_[e / masks_.size()] ||
            slot_[k] != e % masks_.size()) {
            in.fail("a ghost table names a node that is not that ghost (a damaged checkpoint)");
        }
        ++listed;
    }
    if (listed != ghosts) in.fail("a ghost table leaves out some ghosts (a damaged checkpoint)");
    if (resolved_.offsets.empty() || resolved_.offsets.back() != resolved_.indices.size()) {
        in.fail("the resolved mirror lists are damaged");
    }
    for (const NodeIndex g : resolved_.indices) {
        if (g >= node_count) in.fail("a resolved mirror names a node that does not exist");
    }
}

void GhostSet::memory_use(MemoryUse& out) const {
    add_memory(out, "ghosts: index per plane combination", allocated_bytes(ghost_table_));
    add_memory(out, "ghosts: sources", allocated_bytes(source_) + allocated_bytes(mask_) + allocated_bytes(slot_) +
                                           allocated_bytes(sources_sorted_));
    add_memory(out, "ghosts: resolved lattice mirrors", allocated_bytes(resolved_.indices) + allocated_bytes(resolved_.offsets));
}

}  // namespace gpa
