// The zero-energy mode of lattice stencils and its control (kernels.hpp, hourglass.hpp; spec
// section 2, "[spec] Hourglass control"): the mode the control exists for, and what the control
// must leave alone (affine motion), conserve (momentum) and do (only dissipate).

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <fmt/format.h>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/hourglass.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "support/lattices.hpp"

namespace gpa {
namespace {

constexpr double a = 1.0;

struct Case {
    GeometryKind geometry;
    Connectivity connectivity;
};

std::string name(const Case& c) {
    return fmt::format("{} {}", name_of(c.geometry), c.connectivity == Connectivity::Fixed ? "fixed" : "variable");
}

std::vector<Case> cases() {
    std::vector<Case> out;
    for (auto g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        out.push_back({g, Connectivity::Fixed});
        out.push_back({g, Connectivity::Variable});
    }
    return out;
}

NodeStore body(const Case& c, double jitter) {
    testing::LatticeOptions o;
    o.geometry = c.geometry;
    o.cells = c.geometry == GeometryKind::ThreeD ? 6 : 10;
    o.spacing = 1e-3;
    o.connectivity = c.connectivity;
    o.density = 7800.0;
    NodeStore nodes = testing::make_lattice(o);
    if (jitter > 0.0) testing::jitter(nodes, jitter, o.spacing, 11);
    for (auto& s : nodes.sound_speed) s = 5000.0;
    return nodes;
}

struct Evaluated {
    NodeStore nodes;
    CompressedRows lists;
    std::vector<double> power;
};

// The control's forces alone (force zeroed first), with C_hg = 0.1, on `threads` threads.
Evaluated control(NodeStore nodes, int threads = 1) {
    Evaluated e{std::move(nodes), {}, {}};
    e.lists = find_neighbours(e.nodes, a, e.nodes.size());
    for (int c = 0; c < e.nodes.dim(); ++c) std::fill(e.nodes.force[c].begin(), e.nodes.force[c].end(), 0.0);
    for (std::size_t i = 0; i < e.nodes.size(); ++i) e.nodes.smallest_h[i] = a * e.nodes.diameter[i];
    e.power.assign(e.nodes.size(), 0.0);
    const int dim = e.nodes.dim();
    const PositionView x{dim, {e.nodes.position[0].data(), e.nodes.position[1].data(), dim == 3 ? e.nodes.position[2].data() : nullptr}};
    const auto plan = make_slab_plan(e.lists, x);
    ThreadScope scope(threads);
    scope.run([&] {
        if (dim == 2) {
            apply_hourglass_control<2>(e.lists, plan, hourglass_fields<2>(e.nodes, 0.1, e.power.data()), e.nodes.size(), 0.1);
        } else {
            apply_hourglass_control<3>(e.lists, plan, hourglass_fields<3>(e.nodes, 0.1, e.power.data()), e.nodes.size(), 0.1);
        }
    });
    return e;
}

double largest_force(const NodeStore& n) {
    double f = 0.0;
    for (int c = 0; c < n.dim(); ++c) {
        for (double v : n.force[c]) f = std::max(f, std::abs(v));
    }
    return f;
}

class Hourglass : public ::testing::TestWithParam<Case> {};

// The cause: velocities that alternate from one lattice row to the next give every interior node
// of a regular lattice a zero velocity gradient (Eq. 7-8 sum +z and -z neighbours that cancel), so
// no strain rate, no stress and no restoring force meets them. The control pushes back: its
// forces do not vanish, and they only take energy out.
TEST_P(Hourglass, TheOddEvenModeHasNoStrainRateButMeetsTheControl) {
    const Case c = GetParam();
    NodeStore nodes = body(c, 0.0);
    const int dim = nodes.dim();
    const int vertical = dim - 1;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const auto row = static_cast<long>(std::floor(nodes.position[vertical][i] / 1e-3));
        nodes.velocity[vertical][i] = (row % 2 == 0) ? 10.0 : -10.0;
    }
    const auto lists = find_neighbours(nodes, a, nodes.size());
    dispatch_geometry(c.geometry, [&](auto g) {
        using G = decltype(g);
        compute_velocity_gradient<G>(lists, WeightKind::Gpa, gradient_fields<G::dim>(nodes, a));
    });
    testing::LatticeOptions o;
    o.geometry = c.geometry;
    o.cells = c.geometry == GeometryKind::ThreeD ? 6 : 10;
    o.spacing = 1e-3;
    std::size_t interior = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        if (testing::distance_to_boundary(nodes, o, i) < 1.6e-3) continue;
        ++interior;
        for (int k = 0; k < dim * dim; ++k) {
            EXPECT_NEAR(nodes.velocity_gradient[k][i], 0.0, 1e-9) << name(c) << " node " << i << " component " << k;
        }
    }
    ASSERT_GT(interior, 0u);
    const auto e = control(nodes);
    EXPECT_GT(largest_force(e.nodes), 0.0) << name(c);
    double dissipated = 0.0, largest = 0.0;
    for (double p : e.power) largest = std::max(largest, std::abs(p));
    for (std::size_t i = 0; i < e.nodes.size(); ++i) {
        // <= 0 up to round-off (nodes the mode leaves affine, such as a bottom row whose stencil
        // sees only two rows, get a round-off power of either sign).
        EXPECT_LE(e.power[i], 1e-12 * largest) << name(c) << " node " << i;
        dissipated -= e.power[i];
    }
    EXPECT_GT(dissipated, 0.0) << name(c);
}

// Affine motion (translation, uniform strain, rotation) feels nothing, on jittered lattices too:
// the fit around every centre is exact for it.
TEST_P(Hourglass, LeavesEveryAffineVelocityFieldAlone) {
    const Case c = GetParam();
    NodeStore nodes = body(c, 0.2);
    const int dim = nodes.dim();
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    double g[3][3], v0[3];
    for (int p = 0; p < 3; ++p) {
        v0[p] = 50.0 * u(rng);
        for (int q = 0; q < 3; ++q) g[p][q] = 1e4 * u(rng);
    }
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int p = 0; p < dim; ++p) {
            double v = v0[p];
            for (int q = 0; q < dim; ++q) v += g[p][q] * nodes.position[q][i];
            nodes.velocity[p][i] = v;
        }
    }
    const auto e = control(nodes);
    // The scale: the same lattice with random velocities as large as the affine field's pair
    // differences (|G| spacing ~ 10 m/s). The fit is exact up to round-off, ~1e-15 of that.
    NodeStore noisy = nodes;
    for (int p = 0; p < dim; ++p) {
        for (auto& v : noisy.velocity[p]) v = 10.0 * u(rng);
    }
    const double scale = largest_force(control(noisy).nodes);
    ASSERT_GT(scale, 0.0);
    EXPECT_LT(largest_force(e.nodes), 1e-10 * scale) << name(c);
}

// Equal and opposite pair forces: the sum over all nodes vanishes to round-off; and the power the
// driver reports is the dissipation -kappa sum_j w_j |e_ij|^2 / sum_j w_j, computed here from the
// definitions without the engine's kernels.
TEST_P(Hourglass, ConservesMomentumAndReportsItsDissipation) {
    const Case c = GetParam();
    NodeStore nodes = body(c, 0.15);
    testing::randomise_state(nodes, 9);
    for (int p = 0; p < nodes.dim(); ++p) {
        for (auto& v : nodes.velocity[p]) v *= 100.0;
    }
    for (auto& s : nodes.sound_speed) s = 5000.0;
    const auto e = control(nodes);
    const auto& n = e.nodes;
    const int dim = n.dim();
    for (int p = 0; p < dim; ++p) {
        double sum = 0.0, scale = 0.0;
        for (double f : n.force[p]) {
            sum += f;
            scale += std::abs(f);
        }
        EXPECT_NEAR(sum, 0.0, 1e-13 * scale) << name(c) << " component " << p;
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < n.size(); ++i) {
        Eigen::MatrixXd moment = Eigen::MatrixXd::Zero(dim, dim), difference = Eigen::MatrixXd::Zero(dim, dim);
        double weight = 0.0;
        std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> pairs;
        std::vector<double> w;
        for (NodeIndex j : e.lists.row(i)) {
            Eigen::VectorXd r(dim), dv(dim);
            for (int p = 0; p < dim; ++p) {
                r[p] = n.position[p][j] - n.position[p][i];
                dv[p] = n.velocity[p][j] - n.velocity[p][i];
            }
            const double wj = n.size_weight[j] / r.squaredNorm();
            moment += wj * r * r.transpose();
            difference += wj * dv * r.transpose();
            weight += wj;
            pairs.push_back({r, dv});
            w.push_back(wj);
        }
        const Eigen::MatrixXd fit = difference * moment.inverse();
        double sum = 0.0;
        for (std::size_t k = 0; k < pairs.size(); ++k) sum += w[k] * (pairs[k].second - fit * pairs[k].first).squaredNorm();
        const double kappa = 0.1 * n.mass[i] * n.sound_speed[i] / n.smallest_h[i];
        const double expected = -kappa * sum / weight;
        worst = std::max(worst, std::abs(e.power[i] - expected) / std::abs(expected));
    }
    EXPECT_LT(worst, 1e-9) << name(c);
}

// The driver scatters by colours: the same bits on 1 and 2 threads.
TEST_P(Hourglass, IsBitIdenticalOnOneAndTwoThreads) {
    const Case c = GetParam();
    NodeStore nodes = body(c, 0.15);
    testing::randomise_state(nodes, 21);
    for (auto& s : nodes.sound_speed) s = 5000.0;
    const auto one = control(nodes, 1), two = control(nodes, 2);
    for (int p = 0; p < nodes.dim(); ++p) {
        EXPECT_EQ(std::memcmp(one.nodes.force[p].data(), two.nodes.force[p].data(), nodes.size() * sizeof(double)), 0);
    }
    EXPECT_EQ(std::memcmp(one.power.data(), two.power.data(), nodes.size() * sizeof(double)), 0);
}

// The energy booking (compatible update) takes the power of the force pass's control forces at
// other velocities. It makes them again from the fits the force pass kept (KeptFit) instead of
// fitting again: the same powers, bit for bit, as a fresh fit gives, for the damping and the
// stiffness form, with centres that have no control (past the lattice regime) among them.
TEST_P(Hourglass, TheBookingPassMakesTheSameForcesFromTheKeptFits) {
    const Case c = GetParam();
    NodeStore nodes = body(c, 0.0);
    nodes.initial_position = nodes.position;  // the stiffness form measures against these
    testing::jitter(nodes, 0.15, 1e-3, 5);
    testing::randomise_state(nodes, 17);
    for (auto& s : nodes.sound_speed) s = 5000.0;
    for (std::size_t i = 0; i < nodes.size(); i += 7) nodes.plastic_strain[i] = 0.5;  // past the 0.1 below
    const std::size_t n = nodes.size();
    const int dim = nodes.dim();
    const auto lists = find_neighbours(nodes, a, n);
    for (std::size_t i = 0; i < n; ++i) nodes.smallest_h[i] = a * nodes.diameter[i];
    const PositionView x{dim, {nodes.position[0].data(), nodes.position[1].data(), dim == 3 ? nodes.position[2].data() : nullptr}};
    const auto plan = make_slab_plan(lists, x);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::array<std::vector<double>, 3> other;  // the velocities the booking takes the power at
    for (int p = 0; p < dim; ++p) {
        other[p].resize(n);
        for (auto& v : other[p]) v = u(rng);
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const auto run = [&]<int D>() {
        // The kept fits start as NaN: the force pass must write every centre's scale.
        std::array<std::vector<double>, 1 + D * D> damping_store, stiffness_store;
        for (auto& v : damping_store) v.assign(n, nan);
        for (auto& v : stiffness_store) v.assign(n, nan);
        std::vector<double> damping(n), stiffness(n);
        auto f = hourglass_fields<D>(nodes, 0.1, damping.data(), 0.05, stiffness.data());
        f.damping_fit.scale = damping_store[0].data();
        f.stiffness_fit.scale = stiffness_store[0].data();
        for (int k = 0; k < D * D; ++k) {
            f.damping_fit.matrix[k] = damping_store[k + 1].data();
            f.stiffness_fit.matrix[k] = stiffness_store[k + 1].data();
        }
        apply_hourglass_control<D>(lists, plan, f, n, 0.1);
        for (int c2 = 0; c2 < D; ++c2) {
            f.force[c2] = nullptr;
            f.power_velocity[c2] = other[c2].data();
        }
        std::size_t kept = 0, without = 0;
        std::vector<HourglassPower> fitted(n);
        for (std::size_t i = 0; i < n; ++i) {
            const bool controlled = nodes.connectivity[i] == Connectivity::Fixed || nodes.plastic_strain[i] < 0.1;
            if (controlled) {
                ++kept;
            } else {
                ++without;
                EXPECT_EQ(damping_store[0][i], 0.0) << "centre " << i << " has no control: its scale says so";
            }
            auto fresh = f;
            fresh.use_kept_fits = false;
            auto reuse = f;
            reuse.use_kept_fits = true;
            const HourglassPower a_fresh = hourglass_centre<D>(lists.row(i), i, fresh, n, 0.1);
            const HourglassPower a_kept = hourglass_centre<D>(lists.row(i), i, reuse, n, 0.1);
            fitted[i] = a_fresh;
            ASSERT_EQ(std::memcmp(&a_fresh.damping, &a_kept.damping, sizeof(double)), 0)
                << "centre " << i << ": " << a_fresh.damping << " fitted again, " << a_kept.damping << " from the kept fit";
            ASSERT_EQ(std::memcmp(&a_fresh.stiffness, &a_kept.stiffness, sizeof(double)), 0)
                << "centre " << i << ": " << a_fresh.stiffness << " fitted again, " << a_kept.stiffness << " from the kept fit";
            if (controlled) {
                EXPECT_NE(a_kept.damping, 0.0) << "centre " << i;
            }
            if (controlled && nodes.connectivity[i] == Connectivity::Fixed) {
                EXPECT_NE(a_kept.stiffness, 0.0) << "centre " << i;
            }
        }
        EXPECT_GT(kept, 0u);
        if (c.connectivity == Connectivity::Variable) {
            EXPECT_GT(without, 0u);
        }
        // The booking pass itself (compute_stress_power) takes the damping's power in its own walk
        // of each row (KeptDampingPower): the same powers again, bit for bit.
        auto booking = f;
        booking.use_kept_fits = true;
        std::vector<double> booked_damping(n, nan), booked_stiffness(n, nan), stress_power(n), viscous_power(n);
        booking.power = booked_damping.data();
        booking.stiffness_power = booked_stiffness.data();
        const auto forces = force_fields<D>(nodes, a);
        std::array<const double*, D> w{};
        for (int c2 = 0; c2 < D; ++c2) w[c2] = other[c2].data();
        if constexpr (D == 3) {
            compute_stress_power<ThreeD>(lists, WeightKind::Gpa, forces, w, n, stress_power.data(), viscous_power.data(), &booking, 0.1);
        } else if (c.geometry == GeometryKind::Axisymmetric) {
            compute_stress_power<Axisymmetric>(lists, WeightKind::Gpa, forces, w, n, stress_power.data(), viscous_power.data(), &booking,
                                               0.1);
        } else {
            compute_stress_power<PlaneStrain>(lists, WeightKind::Gpa, forces, w, n, stress_power.data(), viscous_power.data(), &booking,
                                              0.1);
        }
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_EQ(std::memcmp(&fitted[i].damping, &booked_damping[i], sizeof(double)), 0)
                << "centre " << i << ": " << fitted[i].damping << " fitted again, " << booked_damping[i] << " from the booking pass";
            ASSERT_EQ(std::memcmp(&fitted[i].stiffness, &booked_stiffness[i], sizeof(double)), 0)
                << "centre " << i << ": " << fitted[i].stiffness << " fitted again, " << booked_stiffness[i] << " from the booking pass";
        }
    };
    if (dim == 2) {
        run.template operator()<2>();
    } else {
        run.template operator()<3>();
    }
}

// Variable nodes are controlled only in the lattice regime (plastic strain below the threshold).
TEST(Hourglass, SparesVariableNodesPastTheLatticeRegime) {
    NodeStore nodes = body({GeometryKind::PlaneStrain, Connectivity::Variable}, 0.15);
    testing::randomise_state(nodes, 4);
    for (auto& s : nodes.sound_speed) s = 5000.0;
    for (auto& ep : nodes.plastic_strain) ep = 0.5;  // past the 0.1 the helper passes
    const auto e = control(nodes);
    EXPECT_EQ(largest_force(e.nodes), 0.0);
}

INSTANTIATE_TEST_SUITE_P(AllGeometries, Hourglass, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& param_info) {
                             std::string s = name(param_info.param);
                             for (char& ch : s) {
                                 if (ch == ' ') ch = '_';
                             }
                             return s;
                         });

}  // namespace
}  // namespace gpa
