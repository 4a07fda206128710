#include "gpa/engine/fields.hpp"

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

void check_influence_distance(double a) {
    if (!(a >= min_influence_distance && a <= max_influence_distance)) {
        throw InputError(fmt::format(
            "influence distance a = {} is outside the range {}-{} the method is defined for "
            "(spec section 2)",
            a, min_influence_distance, max_influence_distance));
    }
}

namespace {
void check_dim(const NodeStore& nodes, int d) {
    if (nodes.dim() != d) {
        throw InputError(fmt::format("a {}D kernel was called on {} nodes", d, name_of(nodes.geometry())));
    }
}
}  // namespace

template <int D>
PairFields<D> pair_fields(const NodeStore& nodes, InfluenceDistance influence_distance) {
    check_dim(nodes, D);
    PairFields<D> p;
    for (int c = 0; c < D; ++c) p.position[c] = nodes.position[c].data();
    p.diameter = nodes.diameter.data();
    p.connectivity = nodes.connectivity.data();
    p.body = nodes.body.data();
    p.influence_distance = influence_distance.value();
    p.lattice_reach = lattice_weight_reach_for(p.influence_distance, D);
    return p;
}

template <int D>
GradientFields<D> gradient_fields(NodeStore& nodes, InfluenceDistance influence_distance) {
    GradientFields<D> g;
    g.pairs = pair_fields<D>(nodes, influence_distance);
    for (int c = 0; c < D; ++c) {
        g.velocity[c] = nodes.velocity[c].data();
        g.alpha[c] = nodes.alpha[c].data();
    }
    for (int c = 0; c < D * D; ++c) g.velocity_gradient[c] = nodes.velocity_gradient[c].data();
    for (int c = 0; c < (D == 3 ? 3 : 1); ++c) g.alpha_shear[c] = nodes.carries_shear_normalisation() ? nodes.alpha_shear[c].data() : nullptr;
    g.size_weight = nodes.size_weight.data();
    g.volumetric_strain_rate = nodes.volumetric_strain_rate.data();
    g.smallest_h = nodes.smallest_h.data();
    g.stable_length = nodes.stable_length.data();
    return g;
}

template <int D>
ForceFields<D> force_fields(NodeStore& nodes, InfluenceDistance influence_distance) {
    ForceFields<D> f;
    f.pairs = pair_fields<D>(nodes, influence_distance);
    f.volume = nodes.volume.data();
    f.size_weight = nodes.size_weight.data();
    for (int c = 0; c < D; ++c) {
        f.alpha[c] = nodes.alpha[c].data();
        f.velocity[c] = nodes.velocity[c].data();
        f.force[c] = nodes.force[c].data();
    }
    for (int c = 0; c < stress_components(D); ++c) f.deviatoric_stress[c] = nodes.deviatoric_stress[c].data();
    f.pressure = nodes.pressure.data();
    f.viscous_pressure = nodes.viscous_pressure.data();
    f.mass = nodes.mass.data();
    f.sound_speed = nodes.sound_speed.data();
    for (int c = 0; c < (D == 3 ? 3 : 1); ++c) f.alpha_shear[c] = nodes.carries_shear_normalisation() ? nodes.alpha_shear[c].data() : nullptr;
    f.hoop_count = nodes.size();
    return f;
}

template PairFields<2> pair_fields<2>(const NodeStore&, InfluenceDistance);
template PairFields<3> pair_fields<3>(const NodeStore&, InfluenceDistance);
template GradientFields<2> gradient_fields<2>(NodeStore&, InfluenceDistance);
template GradientFields<3> gradient_fields<3>(NodeStore&, InfluenceDistance);
template ForceFields<2> force_fields<2>(NodeStore&, InfluenceDistance);
template ForceFields<3> force_fields<3>(NodeStore&, InfluenceDistance);

}  // namespace gpa
