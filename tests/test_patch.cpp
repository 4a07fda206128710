// Patch tests (spec section 3): the normalised velocity gradient is exact for affine fields on
// complete, symmetric neighbourhoods, and component by component (v_a varying along x_b alone)
// on any neighbourhood.

#include <cmath>
#include <random>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/neighbours.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

using testing::LatticeOptions;

// Case: a geometry, a connectivity (fixed lattice lists or a variable search) and a weight.
struct PatchCase {
    GeometryKind geometry;
    Connectivity connectivity;
    WeightKind weight;
    double influence_distance;
    int lattice_neighbours;  // fixed connectivity only
    // Fixed connectivity only: beyond the stencil, every lattice node within this many d0 (the
    // default stencil of a body with a > 1 takes 2 a: bodies.cpp, LatticeBlock::stencil_reach).
    double stencil_reach = 0.0;
};

std::string case_name(const PatchCase& c) {
    return fmt::format("{} {} {} a={} n={}{}", name_of(c.geometry),
                       c.connectivity == Connectivity::Fixed ? "fixed" : "variable",
                       c.weight == WeightKind::Gpa ? "GPA" : "SPH-NSF", c.influence_distance, c.lattice_neighbours,
                       c.stencil_reach > 0.0 ? fmt::format(" reach={}", c.stencil_reach) : std::string());
}

void PrintTo(const PatchCase& c, std::ostream* os) { *os << case_name(c); }

std::vector<PatchCase> all_cases() {
    std::vector<PatchCase> cases;
    for (auto g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        const bool three = g == GeometryKind::ThreeD;
        for (int n : three ? std::vector<int>{6, 18, 26} : std::vector<int>{4, 8}) {
            cases.push_back({g, Connectivity::Fixed, WeightKind::Gpa, 1.0, n});
        }
        // The default stencil of the Taylor scenes' fixed nodes: SPH-NSF at a = 1.3, the box and
        // every lattice node within 2 a d0 (20 neighbours in 2D, 80 in 3D).
        cases.push_back({g, Connectivity::Fixed, WeightKind::SphNsf, 1.3, three ? 26 : 8, 2.6});
        for (double a : {0.8, 1.0, 1.5}) {
            cases.push_back({g, Connectivity::Variable, WeightKind::Gpa, a, 0});
            cases.push_back({g, Connectivity::Variable, WeightKind::SphNsf, a, 0});
        }
    }
    return cases;
}

LatticeOptions options_for(const PatchCase& c) {
    LatticeOptions o;
    o.geometry = c.geometry;
    o.cells = c.geometry == GeometryKind::ThreeD ? 9 : 14;
    o.spacing = 0.5;
    // Axisymmetric: the lattice starts at the axis, so the first column sits at dx/2.
    o.x_origin = c.geometry == GeometryKind::PlaneStrain ? -1.5 : 0.0;
    o.connectivity = c.connectivity;
    o.lattice_neighbours = c.lattice_neighbours;
    o.stencil_reach = c.stencil_reach;
    return o;
}

template <class G>
void compute_gradient(NodeStore& nodes, const PatchCase& c) {
    const auto lists = find_neighbours(nodes, c.influence_distance, nodes.size());
    compute_velocity_gradient<G>(lists, c.weight, gradient_fields<G::dim>(nodes, c.influence_distance));
}

template <int D>
using Mat = Eigen::Matrix<double, D, D>;

template <class G>
void run_regular_lattice_patch(const PatchCase& c) {
    constexpr int D = G::dim;
    const auto o = options_for(c);
    NodeStore nodes = testing::make_lattice(o);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 3; ++trial) {
        Mat<D> G_;
        Eigen::Matrix<double, D, 1> v0;
        for (int a = 0; a < D; ++a) {
            v0[a] = u(rng);
            for (int b = 0; b < D; ++b) G_(a, b) = u(rng);
        }
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            for (int a = 0; a < D; ++a) {
                double v = v0[a];
                for (int b = 0; b < D; ++b) v += G_(a, b) * nodes.position[b][i];
                nodes.velocity[a][i] = v;
            }
        }
        compute_gradient<G>(nodes, c);
        const double radius_of_influence = 2.0 * c.influence_distance * o.spacing;
        const double tol = 1e-12 * G_.norm();
        std::size_t checked = 0;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            if (testing::distance_to_boundary(nodes, o, i) <= radius_of_influence) continue;
            ++checked;
            for (int a = 0; a < D; ++a) {
                for (int b = 0; b < D; ++b) {
                    ASSERT_NEAR(nodes.velocity_gradient[a * D + b][i], G_(a, b), tol)
                        << case_name(c) << " node " << i << " L_" << a << b;
                }
            }
        }
        ASSERT_GT(checked, 8u) << case_name(c) << ": too few interior nodes to test";
    }
    if (c.stencil_reach > 0.0) {
        // The stencil is the one meant: an interior fixed node pairs with the lattice nodes within
        // 2.6 d0, 20 in 2D (4 at 1, 4 at sqrt 2, 4 at 2, 8 at sqrt 5 spacings) and 80 in 3D.
        const auto lists = find_neighbours(nodes, c.influence_distance, nodes.size());
        const std::size_t expected = D == 3 ? 80 : 20;
        std::size_t interior = 0;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            if (testing::distance_to_boundary(nodes, o, i) <= 2.0 * c.influence_distance * o.spacing) continue;
            ++interior;
            ASSERT_EQ(lists.row_size(i), expected) << case_name(c) << " node " << i;
        }
        ASSERT_GT(interior, 8u);
    }
    if constexpr (G::axisymmetric) {
        // Eq. 12 with the hoop rate: u = g_xx x is physical at the axis, so u/x = g_xx exactly and
        // eps_v_dot = D_xx + D_zz + u/x = 2 g_xx + g_zz.
        const double g_xx = 0.37, g_zz = -0.81, g_zx = 0.23, w0 = 0.4;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            nodes.velocity[0][i] = g_xx * nodes.position[0][i];
            nodes.velocity[1][i] = w0 + g_zx * nodes.position[0][i] + g_zz * nodes.position[1][i];
        }
        compute_gradient<G>(nodes, c);
        const double tol = 1e-12 * std::hypot(g_xx, g_zz, g_zx);
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            if (testing::distance_to_boundary(nodes, o, i) <= 2.0 * c.influence_distance * o.spacing) continue;
            ASSERT_NEAR(nodes.volumetric_strain_rate[i], 2.0 * g_xx + g_zz, tol) << case_name(c) << " node " << i;
        }
    }
}

template <class G>
void run_jittered_lattice_patch(const PatchCase& c) {
    constexpr int D = G::dim;
    const auto o = options_for(c);
    NodeStore nodes = testing::make_lattice(o);
    testing::jitter(nodes, 0.2, o.spacing, 11);
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const auto lists = find_neighbours(nodes, c.influence_distance, nodes.size());
    const auto fields = gradient_fields<D>(nodes, c.influence_distance);
    // The paper's patch test (a = b) and its off-diagonal companions: v_a = v0 + g x_b; the other
    // components carry random affine fields, which must not leak into L_ab.
    for (int a = 0; a < D; ++a) {
        for (int b = 0; b < D; ++b) {
            const double g = u(rng), v0 = u(rng);
            Mat<D> other;
            for (int p = 0; p < D; ++p) {
                for (int q = 0; q < D; ++q) other(p, q) = u(rng);
            }
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                for (int p = 0; p < D; ++p) {
                    double v = 0.0;
                    for (int q = 0; q < D; ++q) v += other(p, q) * nodes.position[q][i];
                    nodes.velocity[p][i] = v;
                }
                nodes.velocity[a][i] = v0 + g * nodes.position[b][i];
            }
            compute_velocity_gradient<G>(lists, c.weight, fields);
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                ASSERT_NEAR(nodes.velocity_gradient[a * D + b][i], g, 1e-12 * std::abs(g))
                    << case_name(c) << " node " << i << " L_" << a << b;
            }
        }
    }
    // Not asserted: the whole gradient of a general affine field on the jittered lattice, whose
    // error comes from the off-diagonal moments the diagonal normalisation ignores.
    Mat<D> G_;
    for (int p = 0; p < D; ++p) {
        for (int q = 0; q < D; ++q) G_(p, q) = u(rng);
    }
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int p = 0; p < D; ++p) {
            double v = 0.0;
            for (int q = 0; q < D; ++q) v += G_(p, q) * nodes.position[q][i];
            nodes.velocity[p][i] = v;
        }
    }
    compute_velocity_gradient<G>(lists, c.weight, fields);
    double worst = 0.0, sum = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (testing::distance_to_boundary(nodes, o, i) <= 2.0 * c.influence_distance * o.spacing + 0.2 * o.spacing) continue;
        Mat<D> L;
        for (int p = 0; p < D; ++p) {
            for (int q = 0; q < D; ++q) L(p, q) = nodes.velocity_gradient[p * D + q][i];
        }
        const double e = (L - G_).norm() / G_.norm();
        worst = std::max(worst, e);
        sum += e;
        ++count;
    }
    std::printf("[ measured ] %-44s jittered 0.2 dx, general affine field: |L - G|/|G| mean %.3g, max %.3g (%zu interior nodes)\n",
                case_name(c).c_str(), count ? sum / count : 0.0, worst, count);
}

class Patch : public ::testing::TestWithParam<PatchCase> {};

TEST_P(Patch, RegularLatticeWholeGradientIsExactInTheInterior) {
    const auto c = GetParam();
    dispatch_geometry(c.geometry, [&](auto g) { run_regular_lattice_patch<decltype(g)>(c); });
}

TEST_P(Patch, JitteredLatticeComponentwiseIsExactEverywhere) {
    const auto c = GetParam();
    dispatch_geometry(c.geometry, [&](auto g) { run_jittered_lattice_patch<decltype(g)>(c); });
}

INSTANTIATE_TEST_SUITE_P(AllGeometriesAndWeights, Patch, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<PatchCase>& param_info) {
                             std::string s = case_name(param_info.param);
                             for (char& ch : s) {
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             }
                             return s;
                         });

}  // namespace
}  // namespace gpa

namespace gpa {
namespace {

// The full moment-matrix normalisation (spec section 7) is exact for every affine field on any
// neighbourhood whose moment matrix is invertible: here every node of a jittered lattice,
// edges and corners included.
TEST(PatchMomentMatrix, WholeGradientIsExactEverywhereOnAJitteredLattice) {
    for (auto g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        dispatch_geometry(g, [&](auto tag) {
            using G = decltype(tag);
            constexpr int D = G::dim;
            testing::LatticeOptions o;
            o.geometry = g;
            o.cells = D == 3 ? 7 : 12;
            o.spacing = 0.5;
            NodeStore nodes = testing::make_lattice(o);
            testing::jitter(nodes, 0.2, o.spacing, 21);
            std::mt19937_64 rng(8);
            std::uniform_real_distribution<double> u(-1.0, 1.0);
            Eigen::Matrix<double, D, D> grad;
            for (int a = 0; a < D; ++a) {
                for (int b = 0; b < D; ++b) grad(a, b) = u(rng);
            }
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                for (int a = 0; a < D; ++a) {
                    double v = 0.3;
                    for (int b = 0; b < D; ++b) v += grad(a, b) * nodes.position[b][i];
                    nodes.velocity[a][i] = v;
                }
            }
            const auto lists = find_neighbours(nodes, 1.0, nodes.size());
            auto f = gradient_fields<D>(nodes, 1.0);
            f.full_normalisation = true;
            compute_velocity_gradient<G>(lists, WeightKind::Gpa, f);
            for (std::size_t i = 0; i < nodes.size(); ++i) {
                for (int a = 0; a < D; ++a) {
                    for (int b = 0; b < D; ++b) {
                        ASSERT_NEAR(nodes.velocity_gradient[a * D + b][i], grad(a, b), 1e-12 * grad.norm())
                            << name_of(g) << " node " << i << " L_" << a << b;
                    }
                }
            }
        });
    }
}

}  // namespace
}  // namespace gpa
