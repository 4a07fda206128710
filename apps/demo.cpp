#include "demo.hpp"

#include <chrono>
#include <cmath>
#include <random>

#include <fmt/format.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::app {

namespace {

PositionView view(const NodeStore& n) {
    PositionView v;
    v.dim = n.dim();
    for (int c = 0; c < n.dim(); ++c) v.component[c] = n.position[c].data();
    return v;
}

NodeStore block(GeometryKind g, int cells, double spacing, Connectivity c) {
    NodeStore n(g);
    LatticeBlock b;
    b.spacing = {spacing, spacing, spacing};
    b.last = {cells, cells, g == GeometryKind::ThreeD ? cells : 1};
    b.density = 7890.0;
    b.connectivity = c;
    b.lattice_neighbours = g == GeometryKind::ThreeD ? 26 : 8;
    fill_lattice(n, b);
    return n;
}

void paper_lattice() {
    NodeStore n = block(GeometryKind::PlaneStrain, 7, 1.0, Connectivity::Variable);
    for (std::size_t i = 0; i < n.size(); ++i) {
        n.deviatoric_stress[0][i] = n.deviatoric_stress[3][i] = n.pressure[i] = 1.0 / 3.0;
        n.deviatoric_stress[1][i] = -2.0 / 3.0;
    }
    const auto lists = find_neighbours(n, 1.0, n.size());
    compute_velocity_gradient<PlaneStrain>(lists, WeightKind::Gpa, gradient_fields<2>(n, 1.0));
    const std::size_t i = 3 * 7 + 3, above = 4 * 7 + 3, diagonal = 4 * 7 + 4;
    const auto f = force_fields<2>(n, 1.0);
    const auto sigma = cauchy_stress<PlaneStrain>(f.deviatoric_stress, f.pressure, nullptr, i);
    const Vec<2> alpha(n.alpha[0][i], n.alpha[1][i]);
    const auto push = [&](std::size_t j) {
        const auto p = f.pairs.pair<GpaWeight>(i, j);
        return pair_force(p, n.volume[i], n.size_weight[j], alpha.cwiseProduct(p.l).eval(), sigma, 0.0)[1];
    };
    fmt::print("The paper's lattice (plane strain, d = A = 1, a = 1, sigma_z = -1), interior node:\n");
    fmt::print("  neighbours {:d}, alpha_z = {:.4f} (paper 0.6306)\n", lists.row_size(i), n.alpha[1][i]);
    fmt::print("  force on the diagonal neighbour above {:.4f} (paper 0.0923), straight above {:.4f} (paper 0.3153)\n",
               push(diagonal), push(above));
    fmt::print("  net force from its own stress on the three above {:.4f} (paper 0.5000)\n\n",
               push(above) + push(diagonal) + push(diagonal - 2));
}

template <class G>
void patch_and_conservation(GeometryKind g) {
    constexpr int D = G::dim;
    const int cells = D == 3 ? 10 : 24;
    const double dx = 0.5e-3;
    NodeStore n = block(g, cells, dx, Connectivity::Variable);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Mat<D> grad;
    for (int a = 0; a < D; ++a) {
        for (int b = 0; b < D; ++b) grad(a, b) = 1e4 * u(rng);
    }
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (int a = 0; a < D; ++a) {
            double v = 10.0;
            for (int b = 0; b < D; ++b) v += grad(a, b) * n.position[b][i];
            n.velocity[a][i] = v;
        }
    }
    const auto lists = find_neighbours(n, 1.0, n.size());
    compute_velocity_gradient<G>(lists, WeightKind::Gpa, gradient_fields<D>(n, 1.0));
    double worst = 0.0;
    for (std::size_t i = 0; i < n.size(); ++i) {
        bool interior = true;
        for (int c = 0; c < D; ++c) {
            interior &= n.position[c][i] > 2.5 * dx && n.position[c][i] < (cells - 2.5) * dx;
        }
        if (!interior) continue;
        Mat<D> L;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < D; ++b) L(a, b) = n.velocity_gradient[a * D + b][i];
        }
        worst = std::max(worst, (L - grad).norm() / grad.norm());
    }
    // Random stresses: momentum and the energy identity.
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (int c = 0; c < stress_components(D); ++c) n.deviatoric_stress[c][i] = 1e8 * u(rng);
        n.pressure[i] = 1e8 * u(rng);
        for (int c = 0; c < D; ++c) n.velocity[c][i] = 100.0 * u(rng);
    }
    compute_velocity_gradient<G>(lists, WeightKind::Gpa, gradient_fields<D>(n, 1.0));
    compute_forces<G>(lists, make_slab_plan(lists, view(n)), WeightKind::Gpa, nullptr, force_fields<D>(n, 1.0), n.size());
    double momentum = 0.0, scale = 0.0, power = 0.0, stress_power = 0.0;
    for (std::size_t i = 0; i < n.size(); ++i) {
        const double p = n.pressure[i] + n.viscous_pressure[i];
        const auto s = [&](int a, int b) {
            if constexpr (D == 2) {
                return a == b ? n.deviatoric_stress[a][i] - p : n.deviatoric_stress[2][i];
            } else {
                static constexpr int off[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
                return n.deviatoric_stress[off[a][b]][i] - (a == b ? p : 0.0);
            }
        };
        for (int a = 0; a < D; ++a) {
            power += n.force[a][i] * n.velocity[a][i];
            for (int b = 0; b < D; ++b) stress_power -= n.volume[i] * s(a, b) * n.velocity_gradient[a * D + b][i];
        }
        if constexpr (G::axisymmetric) {
            stress_power -= n.volume[i] * (n.deviatoric_stress[3][i] - p) * n.velocity[0][i] / n.position[0][i];
            momentum += n.force[1][i];
        } else {
            momentum += n.force[0][i];
        }
        scale += std::abs(n.force[0][i]);
    }
    fmt::print("{:>13}: {:6d} nodes, {:5.2f} neighbours/node | patch test |L-G|/|G| = {:.1e} | "
               "sum F_{} / sum |F| = {:.1e} | (F.v + V sigma:D) / F.v = {:.1e}\n",
               name_of(g), n.size(), double(lists.entries()) / n.size(), worst, G::axisymmetric ? "z" : "x",
               momentum / scale, (power - stress_power) / power);
}

template <class G>
double time_step_phases(NodeStore& n, int threads, int repeats, CompressedRows& lists, double& search_s) {
    ThreadScope scope(threads);
    return scope.run([&] {
        const auto t0 = std::chrono::steady_clock::now();
        NeighbourScratch scratch;
        for (int r = 0; r < repeats; ++r) find_neighbours(n, 1.0, n.size(), lists, scratch);
        const auto t1 = std::chrono::steady_clock::now();
        const auto plan = make_slab_plan(lists, view(n));
        for (int r = 0; r < repeats; ++r) {
            compute_velocity_gradient<G>(lists, WeightKind::Gpa, gradient_fields<G::dim>(n, 1.0));
            compute_forces<G>(lists, plan, WeightKind::Gpa, nullptr, force_fields<G::dim>(n, 1.0), n.size());
        }
        const auto t2 = std::chrono::steady_clock::now();
        search_s = std::chrono::duration<double>(t1 - t0).count() / repeats;
        return std::chrono::duration<double>(t2 - t1).count() / repeats;
    });
}

}  // namespace

int run_demo(int threads, const std::filesystem::path& output) {
    fmt::print("gpa engine core demonstration (Johnson, Beissel & Stryk 2000)\n\n");
    paper_lattice();
    fmt::print("Affine velocity field on regular lattices (variable connectivity, a = 1), then random stresses:\n");
    patch_and_conservation<PlaneStrain>(GeometryKind::PlaneStrain);
    patch_and_conservation<Axisymmetric>(GeometryKind::Axisymmetric);
    patch_and_conservation<ThreeD>(GeometryKind::ThreeD);

    const int all = threads > 0 ? threads : hardware_threads();
    fmt::print("\nOne evaluation of search, gradient + forces on a 2D axisymmetric block of 300 x 300 nodes "
               "(one timing each; benchmarks/ measures properly):\n");
    NodeStore n = block(GeometryKind::Axisymmetric, 300, 1e-4, Connectivity::Variable);
    for (std::size_t i = 0; i < n.size(); ++i) {
        n.velocity[1][i] = -300.0 + 1e5 * n.position[1][i];
        n.pressure[i] = 1e8 * std::sin(1e4 * n.position[0][i]);
    }
    CompressedRows lists;
    for (int t : {1, all}) {
        double search = 0.0;
        const double kernels = time_step_phases<Axisymmetric>(n, t, 3, lists, search);
        fmt::print("  {} thread{}: search {:.1f} ms, gradient + forces {:.1f} ms ({:.2f} M node-updates/s)\n", t,
                   t == 1 ? " " : "s", 1e3 * search, 1e3 * kernels, n.size() / kernels / 1e6);
        if (all == 1) break;
    }
    if (!output.empty()) {
        std::filesystem::create_directories(output);
        const auto path = output / "demo.vtp";
        io::write_vtp(path, n, n.size());
        fmt::print("\nwrote {}\n", path.string());
    }
    return 0;
}

}  // namespace gpa::app
