#include "gpa/engine/stress.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <string>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/kernels.hpp"

namespace gpa {

template <class G>
Eigen::Matrix3d full_velocity_gradient(const NodeStore& nodes, std::size_t i) {
    constexpr int D = G::dim;
    Eigen::Matrix3d L = Eigen::Matrix3d::Zero();
    for (int a = 0; a < D; ++a) {
        for (int b = 0; b < D; ++b) L(a, b) = nodes.velocity_gradient[a * D + b][i];
    }
    if constexpr (G::axisymmetric) L(2, 2) = hoop_strain_rate(nodes.velocity[0][i], nodes.position[0][i]);
    return L;
}

namespace {

// Stress order of geometry.hpp <-> the materials' (xx, yy, zz, yz, xz, xy). In 2D the materials'
// axes are (x, z, out-of-plane), so the in-plane shear xz of the engine is their "xy".
template <int D>
materials::Sym3 to_material(const MaterialPointFields& f, std::size_t i) {
    const auto& s = f.deviatoric_stress;
    if constexpr (D == 2) {
        return {s[0][i], s[1][i], s[3][i], 0.0, 0.0, s[2][i]};
    } else {
        return {s[0][i], s[1][i], s[2][i], s[3][i], s[4][i], s[5][i]};
    }
}

template <int D>
void from_material(const MaterialPointFields& f, std::size_t i, const materials::Sym3& m) {
    const auto& s = f.deviatoric_stress;
    if constexpr (D == 2) {
        s[0][i] = m[0];
        s[1][i] = m[1];
        s[3][i] = m[2];
        s[2][i] = m[5];
    } else {
        for (int c = 0; c < 6; ++c) s[c][i] = m[c];
    }
}

constexpr std::size_t no_collapsed_node = std::numeric_limits<std::size_t>::max();

}  // namespace

namespace {

template <int D>
materials::PointState point_state(const MaterialPointFields& f, std::size_t i) {
    materials::PointState state;
    state.deviatoric_stress = to_material<D>(f, i);
    state.pressure = f.pressure[i];
    state.specific_internal_energy = f.internal_energy[i];
    state.plastic_strain = f.plastic_strain[i];
    state.plastic_strain_rate = f.plastic_strain_rate[i];
    state.temperature = f.temperature[i];
    state.damage = f.damage[i];
    state.failed = f.failed[i] != 0;
    return state;
}

}  // namespace

template <int D>
materials::PointResult advance_material_point(const MaterialPointFields& f, std::size_t i, const materials::PointModel& model,
                                              const materials::PointIncrement& increment) {
    materials::PointState state = point_state<D>(f, i);
    const materials::PointResult result = model.update(state, increment);
    if (result.fault != materials::PointFault::none) return result;  // the fields stay as they were
    from_material<D>(f, i, state.deviatoric_stress);
    f.pressure[i] = state.pressure;
    f.internal_energy[i] = state.specific_internal_energy;
    f.plastic_strain[i] = state.plastic_strain;
    f.plastic_strain_rate[i] = state.plastic_strain_rate;
    f.temperature[i] = state.temperature;
    f.damage[i] = state.damage;
    f.failed[i] = state.failed ? 1 : 0;
    f.sound_speed[i] = result.sound_speed;
    f.plastic_work[i] += result.plastic_work;
    f.viscous_work[i] += result.viscous_work;
    return result;
}

template <int D>
std::string point_fault_message(const MaterialPointFields& f, std::size_t i, const materials::PointModel& model,
                                const materials::PointIncrement& increment, const materials::PointResult& result) {
    return model.fault_message(point_state<D>(f, i), increment, result);
}

InitialPointState initial_material_point(const materials::Material& material, double density,
                                         double specific_internal_energy) {
    const auto eos = materials::evaluate_eos(material.eos, material.density, density, specific_internal_energy);
    const double k = std::max(eos.bulk_modulus, 0.0);
    return {eos.pressure, std::sqrt((k + 4.0 * material.shear_modulus / 3.0) / density)};
}

void FirstPointFailure::record(std::size_t index, std::string message) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (index < index_) {
        index_ = index;
        message_ = std::move(message);
    }
}

MaterialGroups group_by_material(const NodeStore& nodes, std::size_t real_count, std::size_t material_count) {
    MaterialGroups groups;
    if (real_count > 0 && std::all_of(nodes.material.begin(), nodes.material.begin() + static_cast<std::ptrdiff_t>(real_count),
                                      [&](std::int32_t m) { return m == nodes.material[0]; })) {
        groups.every_node_of = static_cast<std::size_t>(nodes.material[0]);
        return groups;
    }
    groups.members.assign(material_count, {});
    for (std::size_t i = 0; i < real_count; ++i) groups.members.at(static_cast<std::size_t>(nodes.material[i])).push_back(static_cast<NodeIndex>(i));
    return groups;
}

template <class G>
void update_stresses(NodeStore& nodes, std::size_t real_count, const std::vector<materials::Material>& materials,
                     const std::vector<std::vector<NodeIndex>>& groups, double dt, const StressPhaseOptions& options) {
    MaterialGroups g;
    g.members = groups;
    update_stresses<G>(nodes, real_count, materials, g, dt, options);
}

template <class G>
void update_stresses(NodeStore& nodes, std::size_t real_count, const std::vector<materials::Material>& materials,
                     const MaterialGroups& groups, double dt, const StressPhaseOptions& options) {
    constexpr int D = G::dim;
    std::atomic<std::size_t> collapsed{no_collapsed_node};
    FirstPointFailure failure;  // taken only when a point update reports a fault
    const MaterialPointFields fields = material_point_fields(nodes, stress_components(nodes.dim()));
    const std::size_t group_count = groups.every_node_of ? 1 : groups.members.size();
    for (std::size_t m = 0; m < group_count; ++m) {
        const std::size_t material = groups.every_node_of ? *groups.every_node_of : m;
        const materials::PointModel model(materials.at(material));  // the material's models, chosen once for its group
        const NodeIndex* members = groups.every_node_of ? nullptr : groups.members[m].data();  // null: node k is k
        const std::size_t count = groups.every_node_of ? real_count : groups.members[m].size();
        // 64 points per task: a point update takes some 0.1-0.5 us, so a task is tens of microseconds
        // and a body of 10^3 nodes still splits among the threads (each point is its own).
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 64), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const std::size_t i = members ? members[k] : k;
                if (i >= real_count) continue;
                const double rate = nodes.volumetric_strain_rate[i];
                const double density_old = nodes.mass[i] / nodes.volume[i];
                // Eq. 13: eps_v in the initial configuration, then V = V0 (1 + eps_v).
                const double eps_v = advance_volumetric_strain(nodes.volumetric_strain[i], rate, dt);
                const double volume = nodes.initial_volume[i] * (1.0 + eps_v);
                if (!(volume > 0.0) || !std::isfinite(volume)) {
                    std::size_t seen = collapsed.load();
                    while (i < seen && !collapsed.compare_exchange_weak(seen, i)) {
                    }
                    continue;
                }
                const double density_new = nodes.mass[i] / volume;
                // Eq. 36: nodal viscosity from this step's volumetric strain rate, limited to what
                // its explicit update over this step can carry (kernels.hpp, carried_viscosity_fraction).
                double q_new = 0.0;
                if (options.nodal_viscosity) {
                    const double h = nodes.smallest_h[i];
                    q_new = nodal_viscosity(rate, density_new, nodes.sound_speed[i], h, options.viscosity_linear,
                                            options.viscosity_quadratic);
                    if (q_new > 0.0) {
                        const double nu = nodal_viscosity_diffusivity(rate, nodes.sound_speed[i], h, options.viscosity_linear,
                                                                      options.viscosity_quadratic);
                        q_new *= carried_viscosity_fraction(nu, nodes.stable_length[i], dt);
                    }
                }
                materials::PointIncrement inc;
                inc.velocity_gradient = full_velocity_gradient<G>(nodes, i);
                inc.dt = dt;
                inc.density_old = density_old;
                inc.density_new = density_new;
                inc.viscous_pressure_old = nodes.viscous_pressure[i];
                inc.viscous_pressure_new = q_new;
                inc.energy_booked_by_caller = options.energy_booked_by_forces;
                inc.failure_enabled = options.failure;
                const materials::PointResult result = advance_material_point<D>(fields, i, model, inc);
                if (result.fault != materials::PointFault::none) {
                    failure.record(i, point_fault_message<D>(fields, i, model, inc, result));
                    continue;
                }
                nodes.volumetric_strain[i] = eps_v;
                nodes.volume[i] = volume;
                if constexpr (D == 3) {
                    if (options.left_cauchy_green) {
                        auto& field = nodes.left_cauchy_green;
                        std::array<double, 6> b;
                        for (int c = 0; c < 6; ++c) b[c] = field[c][i];
                        advance_left_cauchy_green(b, inc.velocity_gradient, dt);
                        for (int c = 0; c < 6; ++c) field[c][i] = b[c];
                    }
                }
                nodes.viscous_pressure[i] = q_new;
            }
        });
    }
    if (failure.any()) {
        const std::size_t i = failure.index();
        throw NumericalError(fmt::format("{}, material \"{}\", t-step {:.3g} s: {}", describe_node(nodes, i),
                                         materials.at(static_cast<std::size_t>(nodes.material[i])).name, dt, failure.message()),
                             i, "stress (material point update)");
    }
    if (const std::size_t i = collapsed.load(); i != no_collapsed_node) {
        throw NumericalError(fmt::format(
            "{} collapsed: its volume would become {:.3g} m^3 (volumetric strain "
            "rate {:.3g} 1/s over dt = {:.3g} s); the time step is too large or the node was crushed",
            describe_node(nodes, i), nodes.initial_volume[i] * (1.0 + advance_volumetric_strain(nodes.volumetric_strain[i], nodes.volumetric_strain_rate[i], dt)),
            nodes.volumetric_strain_rate[i], dt),
            i, "volume");
    }
}

void initialise_material_state(NodeStore& nodes, std::size_t real_count, const std::vector<materials::Material>& materials) {
    for (std::size_t i = 0; i < real_count; ++i) {
        const auto& m = materials.at(static_cast<std::size_t>(nodes.material[i]));
        const InitialPointState start = initial_material_point(m, nodes.mass[i] / nodes.volume[i], nodes.internal_energy[i]);
        nodes.pressure[i] = start.pressure;
        nodes.sound_speed[i] = start.sound_speed;
        nodes.temperature[i] = m.room_temperature;
    }
}

template void update_stresses<PlaneStrain>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                           const std::vector<std::vector<NodeIndex>>&, double, const StressPhaseOptions&);
template void update_stresses<Axisymmetric>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                            const std::vector<std::vector<NodeIndex>>&, double, const StressPhaseOptions&);
template void update_stresses<ThreeD>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                      const std::vector<std::vector<NodeIndex>>&, double, const StressPhaseOptions&);
template Eigen::Matrix3d full_velocity_gradient<PlaneStrain>(const NodeStore&, std::size_t);
template Eigen::Matrix3d full_velocity_gradient<Axisymmetric>(const NodeStore&, std::size_t);
template Eigen::Matrix3d full_velocity_gradient<ThreeD>(const NodeStore&, std::size_t);
template materials::PointResult advance_material_point<2>(const MaterialPointFields&, std::size_t, const materials::PointModel&,
                                                          const materials::PointIncrement&);
template materials::PointResult advance_material_point<3>(const MaterialPointFields&, std::size_t, const materials::PointModel&,
                                                          const materials::PointIncrement&);
template std::string point_fault_message<2>(const MaterialPointFields&, std::size_t, const materials::PointModel&,
                                            const materials::PointIncrement&, const materials::PointResult&);
template std::string point_fault_message<3>(const MaterialPointFields&, std::size_t, const materials::PointModel&,
                                            const materials::PointIncrement&, const materials::PointResult&);
template void update_stresses<PlaneStrain>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                           const MaterialGroups&, double, const StressPhaseOptions&);
template void update_stresses<Axisymmetric>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                            const MaterialGroups&, double, const StressPhaseOptions&);
template void update_stresses<ThreeD>(NodeStore&, std::size_t, const std::vector<materials::Material>&,
                                      const MaterialGroups&, double, const StressPhaseOptions&);

}  // namespace gpa
