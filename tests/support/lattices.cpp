#include "support/lattices.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace gpa::testing {

NodeStore make_lattice(const LatticeOptions& o) {
    NodeStore nodes(o.geometry);
    LatticeBlock b;
    const int dim = dimension_of(o.geometry);
    b.origin = {o.x_origin, 0.0, 0.0};
    b.spacing = {o.spacing, o.spacing, o.spacing};
    b.first = {0, 0, 0};
    b.last = {o.cells, o.cells, dim == 3 ? o.cells : 1};
    b.density = o.density;
    b.connectivity = o.connectivity;
    b.lattice_neighbours = o.lattice_neighbours ? o.lattice_neighbours : (dim == 3 ? 26 : 8);
    b.stencil_reach = o.stencil_reach;
    fill_lattice(nodes, b);
    return nodes;
}

void jitter(NodeStore& nodes, double amplitude, double spacing, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-amplitude * spacing, amplitude * spacing);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int c = 0; c < nodes.dim(); ++c) nodes.position[c][i] += u(rng);
    }
    update_size_weights(nodes, 0, nodes.size());
}

void vary_diameters(NodeStore& nodes, double spread, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(1.0 - spread, 1.0 + spread);
    for (auto& d : nodes.diameter) d *= u(rng);
}

void randomise_state(NodeStore& nodes, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int comps = stress_components(nodes.dim());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int c = 0; c < comps; ++c) nodes.deviatoric_stress[c][i] = u(rng);
        for (int c = 0; c < nodes.dim(); ++c) nodes.velocity[c][i] = u(rng);
        nodes.pressure[i] = u(rng);
        nodes.viscous_pressure[i] = 0.5 * (1.0 + u(rng));
        nodes.sound_speed[i] = 2.0 + u(rng);
    }
}

double distance_to_boundary(const NodeStore& nodes, const LatticeOptions& o, std::size_t i) {
    const double lo = 0.0, hi = o.cells * o.spacing;
    double d = 1e300;
    for (int c = 0; c < nodes.dim(); ++c) {
        const double lo_c = c == 0 ? o.x_origin : lo;
        const double hi_c = c == 0 ? o.x_origin + hi : hi;
        d = std::min({d, nodes.position[c][i] - lo_c, hi_c - nodes.position[c][i]});
    }
    return d;  // with x_origin = 0 the lower x edge is the axis
}

void set_uniaxial_stress_z(NodeStore& nodes, double sigma_z) {
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        nodes.deviatoric_stress[0][i] = -sigma_z / 3.0;
        nodes.deviatoric_stress[1][i] = 2.0 * sigma_z / 3.0;
        nodes.deviatoric_stress[2][i] = 0.0;
        nodes.deviatoric_stress[3][i] = -sigma_z / 3.0;
        nodes.pressure[i] = -sigma_z / 3.0;
    }
}

std::size_t node_at(const NodeStore& nodes, double x, double z) {
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (nodes.position[0][i] == x && nodes.position[1][i] == z) return i;
    }
    throw std::out_of_range("node_at: no node at " + std::to_string(x) + ", " + std::to_string(z));
}

}  // namespace gpa::testing
