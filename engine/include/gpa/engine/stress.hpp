#pragma once
// The stress phase (spec sections 3, 4 and 6): per real node, the volumetric strain (Eq. 13),
// volume and density, nodal artificial viscosity (Eq. 36), and the material point update
// (Jaumann rate, strength, equation of state, energy, temperature, damage).

#include <array>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpa/engine/node_store.hpp"
#include "gpa/materials/material.hpp"

namespace gpa {

struct StressPhaseOptions {
    bool nodal_viscosity = true;
    double viscosity_linear = 0.2;
    double viscosity_quadratic = 4.0;
    bool failure = false;
    // The engine books the stress work after the velocity update (compatible energy): the point
    // update keeps e and reads its pressure from the EOS at the new density.
    bool energy_booked_by_forces = false;
    // 3D: advance each node's B = F F^T (NodeStore::left_cauchy_green), for the stretch rule of the
    // node diameter.
    bool left_cauchy_green = false;
};

// The real nodes of each material, for update_stresses: `members[m]` lists the nodes of material m
// (each node in exactly one list), or, where every node [0, real_count) is of one material (most
// scenes), `every_node_of` names it and there are no lists (4 bytes per node).
struct MaterialGroups {
    std::vector<std::vector<NodeIndex>> members;
    std::optional<std::size_t> every_node_of;
};

// The groups of nodes [0, real_count) by their material (NodeStore::material).
MaterialGroups group_by_material(const NodeStore& nodes, std::size_t real_count, std::size_t material_count);

// Advances nodes [0, real_count) over dt from the velocity gradient of the gradient phase. The
// models of each material are chosen once for its group (materials::PointModel). Throws
// NumericalError naming the node when a volume collapses (V <= 0) or a point update reports a fault
// (the smallest such node, after the loop, with the update's words; that node is left as it was).
// Each node's update is its own, so how the nodes are grouped changes no result.
template <class G>
void update_stresses(NodeStore& nodes, std::size_t real_count, const std::vector<materials::Material>& materials,
                     const MaterialGroups& groups, double dt, const StressPhaseOptions& options);
// The same with a list of the nodes of each material, `groups[m]`.
template <class G>
void update_stresses(NodeStore& nodes, std::size_t real_count, const std::vector<materials::Material>& materials,
                     const std::vector<std::vector<NodeIndex>>& groups, double dt, const StressPhaseOptions& options);

// The 3D velocity gradient a 2D node sees: (x, z, out-of-plane) with L_theta_theta = u/x in
// axisymmetric geometry (Eq. 9) and no out-of-plane motion in plane strain.
template <class G>
Eigen::Matrix3d full_velocity_gradient(const NodeStore& nodes, std::size_t i);

// Initial sound speed, pressure from the initial volumetric strain, and temperature of the
// nodes of each material (before the first step).
void initialise_material_state(NodeStore& nodes, std::size_t real_count,
                               const std::vector<materials::Material>& materials);

// --- the material point update shared by particle nodes and element triangles -------------
//
// Particle nodes (NodeStore) and the triangles of element bodies (elements.hpp) keep the same
// material state as structure-of-arrays fields; both present them as MaterialPointFields, so that
// both go through one update (advance_material_point, with the PointModel of the material) and
// one start state (initial_material_point). What differs is only how each finds its velocity
// gradient, densities and viscous pressure (spec section 3 for nodes, docs/elements.md for
// elements).

// Pointers to the state arrays of a set of material points. Stress components in the 2D or 3D
// order of geometry.hpp (2D: xx, zz, xz, out-of-plane; 3D: xx, yy, zz, yz, xz, xy).
struct MaterialPointFields {
    std::array<double*, 6> deviatoric_stress{};
    double* pressure = nullptr;
    double* internal_energy = nullptr;  // specific, J/kg
    double* plastic_strain = nullptr;
    double* plastic_strain_rate = nullptr;  // 1/s, where the Johnson-Cook return starts (materials::PointState)
    double* temperature = nullptr;
    double* damage = nullptr;
    std::uint8_t* failed = nullptr;
    double* sound_speed = nullptr;
    double* plastic_work = nullptr;  // accumulated specific plastic work, J/kg
    double* viscous_work = nullptr;  // accumulated specific viscous work, J/kg
};

// The fields of any store that names them so (NodeStore, ElementPoints), with `components`
// stress components (stress_components(dim)).
template <class Store>
MaterialPointFields material_point_fields(Store& store, int components) {
    MaterialPointFields f;
    for (int c = 0; c < components; ++c) f.deviatoric_stress[static_cast<std::size_t>(c)] = store.deviatoric_stress[static_cast<std::size_t>(c)].data();
    f.pressure = store.pressure.data();
    f.internal_energy = store.internal_energy.data();
    f.plastic_strain = store.plastic_strain.data();
    f.plastic_strain_rate = store.plastic_strain_rate.data();
    f.temperature = store.temperature.data();
    f.damage = store.damage.data();
    f.failed = store.failed.data();
    f.sound_speed = store.sound_speed.data();
    f.plastic_work = store.plastic_work.data();
    f.viscous_work = store.viscous_work.data();
    return f;
}

// Advances point i over the increment with the material's point update (materials::PointModel,
// made once per material group) and writes the new state back (deviator, pressure, energy, plastic
// strain, temperature, damage, failure, sound speed, and the plastic and viscous work added to their
// totals). D is the dimension of the stress order. Never throws: a point the update cannot advance
// comes back with its PointResult::fault set and its fields untouched, for the caller to record
// (point_fault_message) and report after its loop.
template <int D>
materials::PointResult advance_material_point(const MaterialPointFields& f, std::size_t i, const materials::PointModel& model,
                                              const materials::PointIncrement& increment);

// The words for a fault of advance_material_point at point i (whose fields it left untouched).
template <int D>
std::string point_fault_message(const MaterialPointFields& f, std::size_t i, const materials::PointModel& model,
                                const materials::PointIncrement& increment, const materials::PointResult& result);

// The state of an unloaded point at `density`: pressure from the equation of state at e = 0 and
// the longitudinal sound speed sqrt((K + 4 G / 3) / rho) (K floored at 0).
struct InitialPointState {
    double pressure = 0.0;
    double sound_speed = 0.0;
};
InitialPointState initial_material_point(const materials::Material& material, double density,
                                         double specific_internal_energy = 0.0);

// The first failure of a parallel loop over points: the smallest index and its message, so that
// the error reported does not depend on the thread count.
class FirstPointFailure {
public:
    void record(std::size_t index, std::string message);
    bool any() const { return index_ != none; }
    std::size_t index() const { return index_; }
    const std::string& message() const { return message_; }
    static constexpr std::size_t none = static_cast<std::size_t>(-1);

private:
    std::mutex mutex_;
    std::size_t index_ = none;
    std::string message_;
};

}  // namespace gpa
