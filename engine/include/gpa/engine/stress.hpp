#pragma once
// The stress phase (spec sections 3, 4 and 6): per real node, the volumetric strain (Eq. 13),
// volume and density, nodal artificial viscosity (Eq. 36), and the material point update
// (Jaumann rate, strength, equation of state, energy, temperature, damage).

#include <cstddef>
#include <span>
#include <vector>

#include "gpa/engine/node_store.hpp"
#include "gpa/materials/material.hpp"

namespace gpa {

struct StressPhaseOptions {
    bool nodal_viscosity = true;
    double viscosity_linear = 0.2;
    double viscosity_quadratic = 4.0;
    bool failure = false;
};

// Advances nodes [0, real_count) over dt from the velocity gradient of the gradient phase.
// `groups[m]` lists the nodes of material m (each node in exactly one group); the material's
// models are dispatched once per group. Throws NumericalError naming the node when a volume
// collapses (V <= 0) or a state stops being finite.
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

}  // namespace gpa
