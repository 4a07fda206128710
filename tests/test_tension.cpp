// Tension (docs/tension.md): the stiffness form of the hourglass control (kernels.hpp,
// hourglass_stiffness) and hollow spheres and rings (BodySpec::inner_radius).
//
// The stiffness must leave every affine map of the lattice alone (rigid motion, rotation, uniform
// stretch of any size), push back on the lattice's odd-even displacement, conserve momentum, and be
// the gradient of its potential U_i = k_i sum_j w_j |e_ij|^2 / (2 sum_k w_k), so that the energy it
// takes in is given back. A run with it closes its energy balance and is bit-identical on 1 and 2
// threads.

#include <cmath>
#include <random>
#include <string>

#include <Eigen/LU>
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/hourglass.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "support/lattices.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

constexpr double lattice_spacing = 1e-3, wave_speed = 5000.0, stiffness_coefficient = 0.05;

NodeStore fixed_lattice(GeometryKind g) {
    testing::LatticeOptions o;
    o.geometry = g;
    o.cells = g == GeometryKind::ThreeD ? 5 : 8;
    o.spacing = lattice_spacing;
    o.connectivity = Connectivity::Fixed;
    o.density = 7800.0;
    NodeStore nodes = testing::make_lattice(o);
    for (auto& s : nodes.sound_speed) s = wave_speed;
    return nodes;
}

struct Stiffness {
    std::vector<std::array<double, 3>> force;  // per node
    std::vector<double> power;                 // per centre
};

// The stiffness forces alone (damping off: C_hg = 0), on `threads` threads, with the power taken at
// the nodes' velocities.
Stiffness stiffness_forces(NodeStore& nodes, const CompressedRows& lists, int threads = 1) {
    const int dim = nodes.dim();
    for (int c = 0; c < dim; ++c) std::fill(nodes.force[c].begin(), nodes.force[c].end(), 0.0);
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes.smallest_h[i] = nodes.diameter[i];
    std::vector<double> damping(nodes.size(), 0.0);
    Stiffness out;
    out.power.assign(nodes.size(), 0.0);
    const PositionView x{dim, {nodes.position[0].data(), nodes.position[1].data(), dim == 3 ? nodes.position[2].data() : nullptr}};
    const auto plan = make_slab_plan(lists, x);
    ThreadScope scope(threads);
    scope.run([&] {
        if (dim == 2) {
            apply_hourglass_control<2>(lists, plan, hourglass_fields<2>(nodes, 0.1, damping.data(), stiffness_coefficient, out.power.data()),
                                       nodes.size(), 0.0);
        } else {
            apply_hourglass_control<3>(lists, plan, hourglass_fields<3>(nodes, 0.1, damping.data(), stiffness_coefficient, out.power.data()),
                                       nodes.size(), 0.0);
        }
    });
    for (double p : damping) EXPECT_EQ(p, 0.0) << "C_hg = 0: no damping";
    out.force.resize(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int c = 0; c < 3; ++c) out.force[i][c] = c < dim ? nodes.force[c][i] : 0.0;
    }
    return out;
}

// U = sum_i k_i min_F sum_j w_j |dx_j - F dX_j|^2 / (2 sum_j w_j), written out from its definition
// (docs/tension.md) with Eigen's general solver, not the engine's kernels.
double potential(const NodeStore& n, const CompressedRows& lists) {
    const int dim = n.dim();
    double total = 0.0;
    for (std::size_t i = 0; i < n.size(); ++i) {
        Eigen::MatrixXd moment = Eigen::MatrixXd::Zero(dim, dim), difference = Eigen::MatrixXd::Zero(dim, dim);
        double weight = 0.0;
        for (NodeIndex j : lists.row(i)) {
            Eigen::VectorXd X(dim), x(dim);
            for (int p = 0; p < dim; ++p) {
                X[p] = n.initial_position[p][j] - n.initial_position[p][i];
                x[p] = n.position[p][j] - n.position[p][i];
            }
            const double w = 1.0 / X.squaredNorm();
            moment += w * X * X.transpose();
            difference += w * x * X.transpose();
            weight += w;
        }
        const Eigen::MatrixXd map = moment.transpose().lu().solve(difference.transpose()).transpose();
        double sum = 0.0;
        for (NodeIndex j : lists.row(i)) {
            Eigen::VectorXd X(dim), x(dim);
            for (int p = 0; p < dim; ++p) {
                X[p] = n.initial_position[p][j] - n.initial_position[p][i];
                x[p] = n.position[p][j] - n.position[p][i];
            }
            sum += (x - map * X).squaredNorm() / X.squaredNorm();
        }
        const double k = stiffness_coefficient * n.mass[i] * wave_speed * wave_speed / (n.initial_diameter[i] * n.initial_diameter[i]);
        total += 0.5 * k * sum / weight;
    }
    return total;
}

double largest(const Stiffness& s) {
    double f = 0.0;
    for (const auto& v : s.force) f = std::max({f, std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
    return f;
}

class HourglassStiffness : public ::testing::TestWithParam<GeometryKind> {};

// A large affine map (a rotation by 0.6 rad, stretches of 1.8 and 0.7, a shear, a translation)
// leaves no non-affine part: the forces are round-off of those of a random displacement of a tenth
// of a spacing. (Axisymmetric: the map keeps x > 0, as a real one must.)
TEST_P(HourglassStiffness, EveryAffineMapOfTheLatticeFeelsNothing) {
    const GeometryKind g = GetParam();
    NodeStore nodes = fixed_lattice(g);
    const auto lists = find_neighbours(nodes, 1.0, nodes.size());
    const int dim = nodes.dim();
    Eigen::MatrixXd F = Eigen::MatrixXd::Identity(dim, dim);
    const double c = std::cos(0.6), s = std::sin(0.6);
    Eigen::MatrixXd rotation = Eigen::MatrixXd::Identity(dim, dim);
    rotation(0, dim - 1) = -s;
    rotation(dim - 1, 0) = s;
    rotation(0, 0) = rotation(dim - 1, dim - 1) = c;
    Eigen::MatrixXd stretch = Eigen::MatrixXd::Identity(dim, dim);
    stretch(0, 0) = 0.7;
    stretch(dim - 1, dim - 1) = 1.8;
    stretch(0, dim - 1) = 0.2;
    F = g == GeometryKind::Axisymmetric ? stretch : Eigen::MatrixXd(rotation * stretch);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        for (int p = 0; p < dim; ++p) {
            double v = p == 0 ? 0.0 : 3e-3;
            for (int q = 0; q < dim; ++q) v += F(p, q) * nodes.initial_position[q][i];
            nodes.position[p][i] = v;
        }
    }
    const double affine = largest(stiffness_forces(nodes, lists));
    NodeStore noisy = fixed_lattice(g);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-0.1 * lattice_spacing, 0.1 * lattice_spacing);
    for (int p = 0; p < dim; ++p) {
        for (auto& x : noisy.position[p]) x += u(rng);
    }
    const double scale = largest(stiffness_forces(noisy, lists));
    ASSERT_GT(scale, 0.0);
    // The fit is exact for an affine map: what is left is the round-off of positions of ~1e-2 m
    // differenced to ~1e-3 m offsets, ~1e-13 of them, against displacements of 1e-4 m.
    EXPECT_LT(affine, 1e-9 * scale) << name_of(g);
}

// The odd-even displacement (alternate rows moved up and down by a tenth of a spacing) gives the
// strain rates nothing to see (test_hourglass.cpp) but meets the stiffness: every interior node is
// pushed back against its displacement. The forces are equal and opposite (momentum).
TEST_P(HourglassStiffness, PushesBackOnTheOddEvenDisplacementAndConservesMomentum) {
    const GeometryKind g = GetParam();
    NodeStore nodes = fixed_lattice(g);
    const auto lists = find_neighbours(nodes, 1.0, nodes.size());
    const int dim = nodes.dim(), vertical = dim - 1;
    const double delta = 0.1 * lattice_spacing;
    std::vector<double> moved(nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const auto row = static_cast<long>(std::floor(nodes.initial_position[vertical][i] / lattice_spacing));
        moved[i] = row % 2 == 0 ? delta : -delta;
        nodes.position[vertical][i] += moved[i];
    }
    const auto s = stiffness_forces(nodes, lists);
    std::size_t interior = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const double z = nodes.initial_position[vertical][i];
        if (z < 1.5 * lattice_spacing || z > 6.5 * lattice_spacing) continue;  // rows with a row on each side
        ++interior;
        EXPECT_LT(s.force[i][vertical] * moved[i], 0.0) << name_of(g) << " node " << i;
    }
    ASSERT_GT(interior, 0u);
    for (int p = 0; p < dim; ++p) {
        double sum = 0.0, scale = 0.0;
        for (const auto& f : s.force) {
            sum += f[p];
            scale += std::abs(f[p]);
        }
        // Sums of a few hundred terms of either sign: a few ulps of their magnitude.
        EXPECT_NEAR(sum, 0.0, 1e-13 * scale) << name_of(g) << " component " << p;
    }
}

// The forces are minus the gradient of U, checked by central differences of U written out in the
// test; and the power the driver reports, summed, is -dU/dt for the nodes' velocities. So what the
// stiffness takes in while the mode grows it gives back when it shrinks.
TEST_P(HourglassStiffness, IsTheGradientOfItsPotential) {
    const GeometryKind g = GetParam();
    NodeStore nodes = fixed_lattice(g);
    const auto lists = find_neighbours(nodes, 1.0, nodes.size());
    const int dim = nodes.dim();
    std::mt19937_64 rng(8);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int p = 0; p < dim; ++p) {
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            nodes.position[p][i] += 0.15 * lattice_spacing * u(rng);
            nodes.velocity[p][i] = 10.0 * u(rng);
        }
    }
    const auto s = stiffness_forces(nodes, lists);
    // Central differences with a step of 1e-5 spacing: truncation ~ step^2 U''' ~ 1e-10 of the
    // force, round-off ~ 1e-16 U / step ~ 1e-9 of it.
    const double h = 1e-8;
    double worst = 0.0;
    const double scale = largest(s);
    for (std::size_t i = 0; i < nodes.size(); i += 7) {
        for (int p = 0; p < dim; ++p) {
            const double x = nodes.position[p][i];
            nodes.position[p][i] = x + h;
            const double up = potential(nodes, lists);
            nodes.position[p][i] = x - h;
            const double down = potential(nodes, lists);
            nodes.position[p][i] = x;
            worst = std::max(worst, std::abs(-(up - down) / (2.0 * h) - s.force[i][p]));
        }
    }
    EXPECT_LT(worst, 1e-6 * scale) << name_of(g);
    // dU/dt = sum_i grad_i U . v_i = - sum_i F_i . v_i = - (reported power).
    double power = 0.0, check = 0.0, magnitude = 0.0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        power += s.power[i];
        for (int p = 0; p < dim; ++p) {
            check += s.force[i][p] * nodes.velocity[p][i];
            magnitude += std::abs(s.force[i][p] * nodes.velocity[p][i]);
        }
    }
    EXPECT_NEAR(power, check, 1e-12 * magnitude) << name_of(g);
}

std::string geometry_name(const ::testing::TestParamInfo<GeometryKind>& param) {
    return param.param == GeometryKind::PlaneStrain ? "PlaneStrain" : param.param == GeometryKind::Axisymmetric ? "Axisymmetric" : "ThreeD";
}

INSTANTIATE_TEST_SUITE_P(Geometries, HourglassStiffness,
                         ::testing::Values(GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD),
                         geometry_name);

// A fixed bar pulled at both ends with the stiffness on: the energy balance closes to round-off
// (the stiffness's work is booked as internal energy, hourglass_energy), and the run is
// bit-identical on 1 and 2 threads.
TEST(HourglassStiffnessRun, APulledBarBooksTheStiffnessWorkAndIsBitIdenticalOnOneAndTwoThreads) {
    auto scene = testing::pulled_elastic_bar(GeometryKind::Axisymmetric, 1e-3, 8e-3, 4, 20.0, 0.2e-6, 0.3);
    scene.bodies[0].connectivity = ConnectivityMode::Fixed;
    scene.solver.hourglass_stiffness = 0.05;
    scene.solver.smoothing = SmoothingMode::Tension;
    scene.solver.viscosity = ViscosityKind::Nodal;
    scene.stop = {};
    scene.stop.max_steps = 300;
    Simulation one(scene, 1), two(scene, 2);
    double worst = 0.0;
    for (int k = 0; k < 300; ++k) {
        one.step();
        two.step();
        worst = std::max(worst, std::abs(one.totals().energy_error));
    }
    EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
    EXPECT_EQ(one.totals().hourglass_energy, two.totals().hourglass_energy);
    // The stiffness has worked (the grip's corner rows deform non-affinely) ...
    EXPECT_NE(one.totals().hourglass_energy, 0.0);
    // ... and the compatible energy update books every force's work at the velocities it acts
    // with: round-off over 300 steps.
    EXPECT_LT(worst, 1e-12);
}

// The rubber rings of scenes/rubber-rings.toml, coarsened (2 mm, 5 nodes across the wall) and
// started 0.1 mm apart so that they meet within the first steps: contact pairs between the bodies,
// the hourglass stiffness and the nodal viscosity all act, and two runs on 1 and 2 threads agree bit
// for bit.
TEST(HourglassStiffnessRun, CollidingRingsAreBitIdenticalOnOneAndTwoThreads) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/rubber-rings.toml");
    for (auto& b : s.bodies) {
        b.spacing = 2e-3;
        b.origin[0] = b.origin[0] > 0.0 ? 40.05e-3 : -40.05e-3;
    }
    s.stop = {};
    s.stop.max_steps = 150;
    Simulation one(s, 1), two(s, 2);
    for (int k = 0; k < 150; ++k) {
        one.step();
        two.step();
    }
    one.measure_bodies();
    EXPECT_GT(one.totals().hourglass_energy, 0.0);
    EXPECT_LT(one.totals().bodies[0].centre_velocity[0], s.bodies[0].velocity[0]) << "the rings have not met";
    EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
}

// Hollow spheres: the nodes of a ring (plane strain), a hollow sphere on the axis and in 3D lie
// at cell centres between the two radii, and as many of them as the wall's area or volume holds.
TEST(InnerRadius, FillsTheWallBetweenTheTwoRadii) {
    for (const GeometryKind g : {GeometryKind::PlaneStrain, GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        SCOPED_TRACE(std::string(name_of(g)));
        Scene s;
        s.geometry = g;
        s.materials.push_back(testing::elastic_material("rubber", 1010.0, 1e7, 0.3975));
        BodySpec ring;
        ring.name = "ring";
        ring.shape = ShapeKind::Sphere;
        ring.material = "rubber";
        ring.origin = {g == GeometryKind::Axisymmetric ? 0.0 : 5e-3, 2e-3, 1e-3};
        ring.radius = 40e-3;
        ring.inner_radius = 30e-3;
        ring.spacing = g == GeometryKind::ThreeD ? 2.5e-3 : 1e-3;
        s.bodies.push_back(ring);
        s.stop.end_time = 1e-6;
        validate_scene(s);
        NodeStore nodes(g);
        add_body_nodes(nodes, s, 0, {});
        const int dim = dimension_of(g);
        double inner = INFINITY, outer = 0.0;
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            double q = 0.0;
            for (int p = 0; p < dim; ++p) q += std::pow(nodes.position[p][i] - ring.origin[static_cast<std::size_t>(p)], 2);
            inner = std::min(inner, std::sqrt(q));
            outer = std::max(outer, std::sqrt(q));
        }
        EXPECT_GE(inner, 30e-3);
        EXPECT_LT(outer, 40e-3);
        // Cell centres in the wall: the count is the wall's measure over a cell's, to within the
        // cells the two circles (spheres) cut, about their perimeters (areas) over the spacing.
        const double d = ring.spacing;
        double expected = 0.0, cut = 0.0;
        if (g == GeometryKind::PlaneStrain) {
            expected = M_PI * (40e-3 * 40e-3 - 30e-3 * 30e-3) / (d * d);
            cut = 2.0 * M_PI * (40e-3 + 30e-3) / d;
        } else if (g == GeometryKind::Axisymmetric) {
            expected = 0.5 * M_PI * (40e-3 * 40e-3 - 30e-3 * 30e-3) / (d * d);  // the half disc x > 0
            cut = M_PI * (40e-3 + 30e-3) / d;
        } else {
            expected = 4.0 / 3.0 * M_PI * (std::pow(40e-3, 3) - std::pow(30e-3, 3)) / (d * d * d);
            cut = 4.0 * M_PI * (40e-3 * 40e-3 + 30e-3 * 30e-3) / (d * d);
        }
        EXPECT_NEAR(static_cast<double>(nodes.size()), expected, 0.5 * cut) << nodes.size();
    }
}

TEST(InnerRadius, ImpossibleWallsAreRefusedNamingTheBody) {
    const auto refusal = [](double inner, ShapeKind shape, double spacing_) -> std::string {
        Scene s;
        s.geometry = GeometryKind::PlaneStrain;
        s.materials.push_back(testing::elastic_material("rubber", 1010.0, 1e7, 0.3975));
        BodySpec b;
        b.name = "ring";
        b.shape = shape;
        b.material = "rubber";
        b.radius = 40e-3;
        b.length = shape == ShapeKind::Sphere ? 0.0 : 10e-3;
        b.inner_radius = inner;
        b.spacing = spacing_;
        s.bodies.push_back(b);
        s.stop.end_time = 1e-6;
        try {
            validate_scene(s);
        } catch (const InputError& e) {
            return e.what();
        }
        return "accepted";
    };
    EXPECT_EQ(refusal(30e-3, ShapeKind::Sphere, 1e-3), "accepted");
    EXPECT_NE(refusal(-30e-3, ShapeKind::Sphere, 1e-3).find("body \"ring\" (body[0]).inner_radius = -0.03 must be a length >= 0"),
              std::string::npos)
        << refusal(-30e-3, ShapeKind::Sphere, 1e-3);
    EXPECT_NE(refusal(40e-3, ShapeKind::Sphere, 1e-3).find("inner_radius = 0.04 m must be less than its radius (0.04 m)"),
              std::string::npos)
        << refusal(40e-3, ShapeKind::Sphere, 1e-3);
    EXPECT_NE(refusal(30e-3, ShapeKind::Cylinder, 1e-3).find("inner_radius applies to a sphere only"), std::string::npos)
        << refusal(30e-3, ShapeKind::Cylinder, 1e-3);
    EXPECT_NE(refusal(30e-3, ShapeKind::Sphere, 6e-3).find("puts fewer than 2 nodes across its wall"), std::string::npos)
        << refusal(30e-3, ShapeKind::Sphere, 6e-3);
}

}  // namespace
}  // namespace gpa
