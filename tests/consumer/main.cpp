// Embeds gpa: fills a plane-strain block, computes the paper's geometry factor, prints it.
#include <cstdio>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/neighbours.hpp"

int main() {
    gpa::NodeStore nodes(gpa::GeometryKind::PlaneStrain);
    gpa::LatticeBlock block;
    block.last = {7, 7, 1};
    gpa::fill_lattice(nodes, block);
    const auto lists = gpa::find_neighbours(nodes, 1.0, nodes.size());
    gpa::compute_velocity_gradient<gpa::PlaneStrain>(lists, gpa::WeightKind::Gpa, gpa::gradient_fields<2>(nodes, 1.0));
    const std::size_t centre = 3 * 7 + 3;
    std::printf("alpha_z=%.4f\n", nodes.alpha[1][centre]);
    return nodes.alpha[1][centre] > 0.6305 && nodes.alpha[1][centre] < 0.6307 ? 0 : 1;
}
