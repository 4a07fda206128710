// The measurement rules of issue 13 (measure.hpp, docs/measurement.md): a body measured from its
// own base after it has left the plane, local peaks over a neighbourhood, the roughness of a field
// along the impact face; and the element reference (io/reference.hpp): the rule that makes a
// study's series a reference, its file, the outline distance and the ratios.

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"

namespace gpa {
namespace {

namespace fs = std::filesystem;

TEST(MeasureBase, ABodyOffThePlaneIsMeasuredFromItsUnderside) {
    // Two particle rows of cells 1 mm wide, 3 mm above the plane: a body that has lifted off.
    const auto pass = [](double base) {
        measure::Extent e;
        for (double x : {0.5, 1.5}) {
            measure::add_particle(e, 3.5 - base, x, 1.0, true);
            measure::add_particle(e, 4.5 - base, x, 1.0, true);
        }
        return e;
    };
    EXPECT_FALSE(pass(0.0).standing());  // nothing within a cell of the plane
    double base = -1.0;
    const measure::Extent e = measure::measure_extent(pass, &base);
    EXPECT_DOUBLE_EQ(base, 3.0);         // the lowest reach: 3.5 - 1/2
    EXPECT_DOUBLE_EQ(e.length(), 2.0);   // two rows of 1 mm, not 5 mm above the plane
    EXPECT_DOUBLE_EQ(e.footprint(), 4.0);  // the bottom row's radii 0.5 and 1.5 plus half a cell: a 4 mm disc
    // A body standing on the plane keeps the plane as its base.
    const auto standing = [](double b) {
        measure::Extent x;
        measure::add_particle(x, 0.5 - b, 0.5, 1.0, true);
        measure::add_particle(x, 1.5 - b, 0.5, 1.0, true);
        return x;
    };
    measure::measure_extent(standing, &base);
    EXPECT_EQ(base, 0.0);
    // Elements: the lowest node is the base.
    const auto elements = [](double b) {
        measure::Extent x;
        measure::add_element_node(x, 2.0 - b, 0.0, 1e-9, true);
        measure::add_element_node(x, 2.0 - b, 3.0, 1e-9, true);
        measure::add_element_node(x, 7.0 - b, 3.0, 1e-9, true);
        return x;
    };
    const measure::Extent el = measure::measure_extent(elements, &base);
    EXPECT_DOUBLE_EQ(base, 2.0);
    EXPECT_DOUBLE_EQ(el.length(), 5.0);
    EXPECT_DOUBLE_EQ(el.footprint(), 6.0);
}

// A face that has lifted off springs back dished: its middle lowest, its nodes further out a little
// higher, not level to round-off. From its underside an element node is on the face within half
// a spacing, as a particle whose centre lies within half a cell of the lowest centre; on the plane
// the tolerance stays at round-off (contact puts the nodes on it).
TEST(MeasureBase, ADishedUndersideOfElementsCountsTheNodesWithinHalfASpacing) {
    const double h = 1e-3;  // the body's mesh spacing
    // Radii 0, 1, 2, 3, 4 mm along the underside, raised 0, 1e-9, 0.1 h, 0.49 h and 0.51 h above the
    // lowest node, 5 mm above the plane; a top node 10 mm up.
    const std::array<double, 5> rise{0.0, 1e-9, 0.1 * h, 0.49 * h, 0.51 * h};
    const auto pass = [&](double b) {
        measure::Extent x;
        for (int k = 0; k < 5; ++k) {
            measure::add_element_node(x, 5e-3 + rise[static_cast<std::size_t>(k)] - b, k * 1e-3, measure::element_face_tolerance(h, b), true);
        }
        measure::add_element_node(x, 15e-3 - b, 0.0, measure::element_face_tolerance(h, b), true);
        return x;
    };
    double base = 0.0;
    const measure::Extent e = measure::measure_extent(pass, &base);
    EXPECT_DOUBLE_EQ(base, 5e-3);
    EXPECT_DOUBLE_EQ(e.length(), 10e-3);
    EXPECT_DOUBLE_EQ(e.footprint(), 6e-3);  // radii up to 3 mm; the node 0.51 h up is not on the face
    // The same underside standing on the plane: only the nodes on it to round-off (within 1e-6 h)
    // are on the face.
    double on_plane = -1.0;
    const auto standing = [&](double b) {
        measure::Extent x;
        for (int k = 0; k < 5; ++k) {
            measure::add_element_node(x, rise[static_cast<std::size_t>(k)] - b, k * 1e-3, measure::element_face_tolerance(h, b), true);
        }
        return x;
    };
    const measure::Extent s = measure::measure_extent(standing, &on_plane);
    EXPECT_EQ(on_plane, 0.0);
    EXPECT_DOUBLE_EQ(s.footprint(), 2e-3);  // radii 0 and 1 mm (the second 1e-9 above the plane)
}

TEST(MeasureBase, AnElasticBarThatBouncedOffKeepsItsLengthAndFootprint) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/elastic-bar.toml");
    s.bodies[0].spacing = 0.25e-3;  // 4 across the 1 mm radius: enough for a length
    s.stop.end_time = 50e-6;        // contact ends near 8 us; the bar then flies 40 us at ~10 m/s
    Simulation sim(s, 1);
    while (!sim.finished()) sim.step();
    const auto& t = sim.totals();
    std::printf("[ measured ] after lift-off: base %.4f mm above the plane, length %.4f mm, footprint %.4f mm\n",
                t.base_height * 1e3, t.length * 1e3, t.footprint_diameter * 1e3);
    // It has left: about 0.4 mm of air under it (10 m/s for 40 us), more than a cell.
    EXPECT_GT(t.base_height, 0.3e-3);
    // The body's own length: 20 mm, to the free vibration's strain v/c = 10 / 5064 = 0.2 % and a
    // fraction of a cell (0.25 mm = 1.25 % of the length) of the d/2 reach at its ends.
    EXPECT_NEAR(t.length, 20e-3, 0.01 * 20e-3);
    // Its base is the bar's end face, 2 mm across, to within one cell.
    EXPECT_NEAR(t.footprint_diameter, 2e-3, 0.25e-3);
}

TEST(LocalPeak, AUniformFieldIsItsOwnPeakAndASpikeIsAveraged) {
    std::vector<measure::FieldPoint> points;
    for (int i = 0; i < 20; ++i) {
        for (int k = 0; k < 20; ++k) {
            measure::FieldPoint p;
            p.position = {0.1 * i + 0.05, 0.1 * k + 0.05, 0.0};
            p.weight = 0.01;
            p.value = 1.0;
            points.push_back(p);
        }
    }
    const auto uniform = measure::local_peak(points, 0.25, 2);
    EXPECT_NEAR(uniform.value, 1.0, 1e-15);
    EXPECT_EQ(uniform.raw, 1.0);
    // One point at 11 whose 4 axis neighbours hold 2, among ones, equal weights: within 0.12 a
    // point has its 4 axis neighbours, so the mean centred on the spike is (11 + 4 x 2) / 5 = 3.8
    // (on a neighbour (2 + 11 + 3) / 5 = 3.2); the raw maximum stays 11.
    points[10 * 20 + 10].value = 11.0;
    for (int n : {9 * 20 + 10, 11 * 20 + 10, 10 * 20 + 9, 10 * 20 + 11}) points[n].value = 2.0;
    const auto spike = measure::local_peak(points, 0.12, 2);
    EXPECT_NEAR(spike.value, 3.8, 1e-13);
    EXPECT_EQ(spike.raw, 11.0);
    EXPECT_NEAR(spike.position[0], 1.05, 1e-15);
    EXPECT_NEAR(spike.position[1], 1.05, 1e-15);
    // A point of another body is not in the neighbourhood: alone in its body, it has no
    // neighbourhood mean and no part in the peak; it is still the largest single value.
    points[10 * 20 + 11].body = 1;
    points[10 * 20 + 11].value = 100.0;
    const auto with_lone = measure::local_peak(points, 0.12, 2);
    EXPECT_EQ(with_lone.alone, 1u);
    EXPECT_EQ(with_lone.raw, 100.0);
    // The spike's neighbourhood lost the point at (1.05, 1.15) (now of body 1): (11 + 3 x 2) / 4.
    EXPECT_NEAR(with_lone.value, 17.0 / 4.0, 1e-13);
    EXPECT_NEAR(with_lone.position[0], 1.05, 1e-15);
    EXPECT_NEAR(with_lone.position[1], 1.05, 1e-15);
    EXPECT_TRUE(with_lone.has_peak());
    EXPECT_THROW(measure::local_peak(points, 0.0, 2), std::invalid_argument);
    EXPECT_THROW(measure::local_peak(points, NAN, 2), std::invalid_argument);
}

TEST(LocalPeak, ADebrisNodeAloneIsNoNeighbourhoodAndMakesNoPeak) {
    // A block of 10 x 10 points at 1 (spacing 0.1), and one node of the same body flown 1 away
    // with the largest value, 7: within a radius of 0.2 it has no other point, so its "mean"
    // would be its own 7. The peak stays the block's 1; the largest single value is the node's.
    std::vector<measure::FieldPoint> points;
    for (int i = 0; i < 10; ++i) {
        for (int k = 0; k < 10; ++k) {
            measure::FieldPoint p;
            p.position = {0.1 * i, 0.1 * k, 0.0};
            p.weight = 0.01;
            p.value = 1.0;
            points.push_back(p);
        }
    }
    measure::FieldPoint debris;
    debris.position = {2.0, 0.5, 0.0};
    debris.weight = 0.01;
    debris.value = 7.0;
    points.push_back(debris);
    for (int dim : {2, 3}) {
        const auto peak = measure::local_peak(points, 0.2, dim);
        EXPECT_EQ(peak.points, 101u);
        EXPECT_EQ(peak.alone, 1u);
        EXPECT_NEAR(peak.value, 1.0, 1e-15) << dim;
        EXPECT_EQ(peak.raw, 7.0);
        EXPECT_EQ(peak.raw_position[0], 2.0);
        // A second node beside it (0.15 away): two points are a neighbourhood, mean (7 + 5) / 2.
        std::vector<measure::FieldPoint> pair = points;
        debris.position = {2.15, 0.5, 0.0};
        debris.value = 5.0;
        pair.push_back(debris);
        const auto two = measure::local_peak(pair, 0.2, dim);
        EXPECT_EQ(two.alone, 0u);
        EXPECT_NEAR(two.value, 6.0, 1e-15);
        debris.value = 7.0;
    }
    // Points all alone (spacing 1, radius 0.2): no neighbourhood anywhere, no peak (NaN), not
    // the largest single value passed off as a mean.
    std::vector<measure::FieldPoint> scattered(5);
    for (int k = 0; k < 5; ++k) {
        scattered[k].position = {1.0 * k, 0.0, 0.0};
        scattered[k].weight = 0.01;
        scattered[k].value = k;
    }
    const auto none = measure::local_peak(scattered, 0.2, 2);
    EXPECT_EQ(none.alone, 5u);
    EXPECT_FALSE(none.has_peak());
    EXPECT_TRUE(std::isnan(none.value));
    EXPECT_TRUE(std::isnan(none.position[0]));
    EXPECT_EQ(none.raw, 4.0);
}

TEST(LocalPeak, SeveralFieldsInOnePassAreEachFieldsOwnPeakExactly) {
    // Points of two bodies scattered over a square, two fields that peak in different places:
    // local_peaks must give, field by field, local_peak's numbers to the last bit (same sums in
    // the same order), in 2D and in 3D.
    for (int dim : {2, 3}) {
        std::vector<measure::FieldPoint> points;
        std::vector<double> a, b;
        std::uint64_t state = 12345;
        const auto uniform = [&] {
            state = state * 6364136223846793005ull + 1442695040888963407ull;
            return double(state >> 11) * 0x1.0p-53;
        };
        for (int k = 0; k < 3000; ++k) {
            measure::FieldPoint p;
            for (int c = 0; c < dim; ++c) p.position[c] = uniform() - 0.3;
            p.weight = 0.5 + uniform();
            p.body = k % 7 == 0 ? 1 : 0;
            points.push_back(p);
            a.push_back(std::exp(-8.0 * p.position[0] * p.position[0]) + 0.1 * uniform());
            b.push_back(p.position[1] + uniform());
        }
        const std::array<std::span<const double>, 2> fields{a, b};
        const auto both = measure::local_peaks(points, fields, 0.07, dim);
        ASSERT_EQ(both.size(), 2u);
        for (int f = 0; f < 2; ++f) {
            for (std::size_t q = 0; q < points.size(); ++q) points[q].value = f == 0 ? a[q] : b[q];
            const auto one = measure::local_peak(points, 0.07, dim);
            EXPECT_EQ(both[f].value, one.value);
            EXPECT_EQ(both[f].position, one.position);
            EXPECT_EQ(both[f].raw, one.raw);
            EXPECT_EQ(both[f].raw_position, one.raw_position);
            EXPECT_EQ(both[f].points, points.size());
            // A neighbourhood mean is a weighted mean of values: never above the largest one.
            EXPECT_LE(one.value, one.raw);
        }
        EXPECT_NE(both[0].position, both[1].position) << "the two fields peak in different places";
        // One point of another body a kilometre away: the cells of the points' box are then too
        // many for the counting sort, and the sorted, hashed grouping must give the same sums in
        // the same order (the far point, a body of its own far below every value, takes no part).
        std::vector<measure::FieldPoint> far = points;
        std::vector<double> far_a = a, far_b = b;
        measure::FieldPoint outlier;
        outlier.position = {1e3, 1e3, dim == 3 ? 1e3 : 0.0};
        outlier.weight = 1.0;
        outlier.body = 99;
        far.push_back(outlier);
        far_a.push_back(-1e300);
        far_b.push_back(-1e300);
        const std::array<std::span<const double>, 2> far_fields{far_a, far_b};
        const auto hashed = measure::local_peaks(far, far_fields, 0.07, dim);
        for (int f = 0; f < 2; ++f) {
            EXPECT_EQ(hashed[f].value, both[f].value);
            EXPECT_EQ(hashed[f].position, both[f].position);
            EXPECT_EQ(hashed[f].raw, both[f].raw);
        }
        const std::vector<double> short_field(points.size() - 1, 0.0);
        const std::array<std::span<const double>, 1> wrong{short_field};
        EXPECT_THROW(measure::local_peaks(points, wrong, 0.07, dim), std::invalid_argument);
    }
}

TEST(FaceRoughness, ALinearTrendIsSmoothAndAnAlternationIsNot) {
    const std::vector<double> x{3, 0, 2, 1, 4};  // any order: sorted by x inside
    std::vector<double> linear, alternating;
    for (double xi : x) {
        linear.push_back(1.0 + 0.5 * xi);
        alternating.push_back(1.0 + ((static_cast<int>(xi) % 2) ? 0.1 : -0.1));
    }
    EXPECT_NEAR(measure::face_roughness(x, linear), 0.0, 1e-15);
    EXPECT_NEAR(measure::face_roughness(x, alternating), 0.2, 1e-15);  // a +-0.1 alternation: 2 x 0.1
    EXPECT_EQ(measure::face_roughness(std::vector<double>{0, 1}, std::vector<double>{5, 7}), 0.0);
}

TEST(NodeDiameter, TheHoopStretchNeverShrinksTheSupport) {
    // A ring that has doubled its radius at constant volume.
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0, 0), std::sqrt(0.5));  // Eq. 3: shrinks
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0, 1), 1.0);              // volume: unchanged
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0, 2), std::sqrt(2.0));   // hoop: grows
    // Halved radius (a necking ring): Eq. 3 and the hoop rule agree.
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 2.0, 1.0, 2), node_diameter<Axisymmetric>(1.0, 0.0, 2.0, 1.0, 0));
    // The volume enters every rule alike; other geometries have no hoop stretch.
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.21, 1.0, 1.0, 2), 1.1);
    EXPECT_DOUBLE_EQ(node_diameter<PlaneStrain>(1.0, 0.21, 1.0, 2.0, 2), 1.1);
}

TEST(NodeDiameter, TheStretchRuleKeepsTheMostStretchedNeighboursInReach) {
    // A face spread by l = 2 radially and around the hoop and thinned 4 times axially (J = 1):
    // B = diag(l^2, l^2, 1 / l^4), its largest isochoric stretch is l, and the stretch rule makes
    // d = l d0, so that a neighbour at l s0 along the face is where s0 was on the initial lattice.
    const double l = 2.0;
    const std::array<double, 6> face{l * l, l * l, 1.0 / (l * l * l * l), 0.0, 0.0, 0.0};
    EXPECT_NEAR(largest_isochoric_stretch(face), l, 1e-14);
    EXPECT_DOUBLE_EQ(node_diameter<ThreeD>(1.0, 0.0, 0.0, 0.0, 3, largest_isochoric_stretch(face)), largest_isochoric_stretch(face));
    // A pure change of volume stretches nothing: the rule is the volume rule, d0 (V/V0)^(1/3).
    const double j = 0.729;  // V/V0, cube root 0.9
    const double c = std::cbrt(j * j);
    EXPECT_NEAR(largest_isochoric_stretch({c, c, c, 0.0, 0.0, 0.0}), 1.0, 1e-14);
    EXPECT_NEAR(node_diameter<ThreeD>(1.0, j - 1.0, 0.0, 0.0, 3, 1.0), 0.9, 1e-15);
    EXPECT_DOUBLE_EQ(node_diameter<ThreeD>(1.0, j - 1.0, 0.0, 0.0, 2, 5.0), node_diameter<ThreeD>(1.0, j - 1.0, 0.0, 0.0, 1));
    // The stretch does not depend on the axes: the face tensor turned by 30 degrees about z and
    // 50 about x gives the same l.
    const Eigen::Matrix3d turn = (Eigen::AngleAxisd(0.5236, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(0.8727, Eigen::Vector3d::UnitX())).toRotationMatrix();
    const Eigen::Matrix3d b = turn * Eigen::Vector3d(l * l, l * l, 1.0 / (l * l * l * l)).asDiagonal() * turn.transpose();
    EXPECT_NEAR(largest_isochoric_stretch({b(0, 0), b(1, 1), b(2, 2), b(1, 2), b(0, 2), b(0, 1)}), l, 1e-13);
    // In 2D the stretch rule is the hoop rule.
    EXPECT_DOUBLE_EQ(node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0, 3, 7.0), node_diameter<Axisymmetric>(1.0, 0.0, 1.0, 2.0, 2));
}

TEST(LeftCauchyGreen, AdvancesAsTheProductOfTheStepsStretches) {
    // A constant stretching L = diag(g, -g/4, -g/2): each step multiplies B's diagonal by
    // (1 + dt L_aa)^2 exactly, and B stays diagonal.
    const double g = 1e5, dt = 1e-8;
    const int steps = 400;
    Mat<3> L = Mat<3>::Zero();
    L.diagonal() << g, -0.25 * g, -0.5 * g;
    std::array<double, 6> b{1.0, 1.0, 1.0, 0.0, 0.0, 0.0};
    for (int n = 0; n < steps; ++n) advance_left_cauchy_green(b, L, dt);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(b[a], std::pow(1.0 + dt * L(a, a), 2 * steps), 1e-13 * b[a]) << a;
    for (int a = 3; a < 6; ++a) EXPECT_EQ(b[a], 0.0);
    // A spin W (skew) only turns F; the first-order step adds (dt w)^2 to B's diagonal in its plane
    // each time, (I + dt W)(I + dt W)^T = I + (w dt)^2 diag(1, 1, 0): after n steps
    // (1 + (w dt)^2)^n = 1.0004 here, a stretch of (1 + (w dt)^2)^(n/6) = 1 + 7e-5. That is the
    // integration's error under rotation, O(dt) over a fixed time.
    const double w = 1e5, x2 = (w * dt) * (w * dt);
    Mat<3> spin = Mat<3>::Zero();
    spin(0, 1) = -w;
    spin(1, 0) = w;
    std::array<double, 6> r{1.0, 1.0, 1.0, 0.0, 0.0, 0.0};
    for (int n = 0; n < steps; ++n) advance_left_cauchy_green(r, spin, dt);
    const double ulps = steps * 2.2e-16;  // one rounding per step
    EXPECT_NEAR(r[0], std::pow(1.0 + x2, steps), ulps);
    EXPECT_NEAR(r[1], std::pow(1.0 + x2, steps), ulps);
    EXPECT_EQ(r[2], 1.0);
    for (int a = 3; a < 6; ++a) EXPECT_EQ(r[a], 0.0) << a;
    EXPECT_NEAR(largest_isochoric_stretch(r), std::pow(1.0 + x2, steps / 6.0), ulps);
}

TEST(Footprint3D, TheMeanWidthOverDirectionsOfASquareFace) {
    // Cells of size d centred on an m x m square of side S = (m - 1) d on the plane z = 0, and one
    // above the face: in direction theta the face is S (|cos| + |sin|) + d wide.
    const double d = 1e-3;
    const int m = 7;
    const double side = (m - 1) * d;
    measure::Extent e;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) measure::add_particle_3d(e, 0.5 * d, i * d + 0.3, j * d - 2.0, d);
    measure::add_particle_3d(e, 5.0 * d, 50.0, 50.0, d);  // above the face: the length only
    double mean = 0.0;
    for (int k = 0; k < measure::footprint_directions; ++k) {
        const double theta = k * std::numbers::pi / measure::footprint_directions;
        const double expected = side * (std::abs(std::cos(theta)) + std::abs(std::sin(theta))) + d;
        EXPECT_NEAR(e.width(k), expected, 1e-12) << k;
        mean += expected / measure::footprint_directions;
    }
    EXPECT_NEAR(e.footprint(), mean, 1e-12);
    EXPECT_NEAR(e.footprint_narrowest(), side + d, 1e-12);                   // along an edge
    EXPECT_NEAR(e.footprint_widest(), side * std::sqrt(2.0) + d, 1e-12);     // across the diagonal (k = 9)
    EXPECT_NEAR(e.length(), 5.5 * d, 1e-15);
    // Merging two halves of the points gives the same extent as adding them all to one.
    measure::Extent left, right;
    for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j) measure::add_particle_3d(i < 3 ? left : right, 0.5 * d, i * d + 0.3, j * d - 2.0, d);
    left += right;
    for (int k = 0; k < measure::footprint_directions; ++k) EXPECT_EQ(left.width(k), e.width(k));
    // A reduction starts from an empty extent on either side of the merge.
    measure::Extent empty_first;
    empty_first += e;
    measure::Extent empty_second = e;
    empty_second += measure::Extent{};
    for (int k = 0; k < measure::footprint_directions; ++k) {
        EXPECT_EQ(empty_first.width(k), e.width(k)) << k;
        EXPECT_EQ(empty_second.width(k), e.width(k)) << k;
    }
    EXPECT_EQ(measure::Extent{}.footprint(), 0.0);
}

// --- the element reference ----------------------------------------------------------------

io::StudyReport series_of(const std::vector<double>& h, const std::vector<double>& length,
                          const std::vector<double>& footprint) {
    io::StudyReport r;
    r.scene_name = "synthetic";
    r.variants.push_back(io::parse_variant("elements:discretisation=elements"));
    for (std::size_t k = 0; k < h.size(); ++k) {
        io::StudyCase c;
        c.variant = c.series = "elements";
        c.cell_size = h[k];
        c.finished = true;
        c.metrics = {{"final_length", length[k]}, {"footprint_diameter", footprint[k]}};
        r.cases.push_back(c);
    }
    return r;
}

TEST(ElementReference, RichardsonWhenTheOrderIsSoundTheFinestWhenSettledNoneOtherwise) {
    // Length: f = 10 + h (first order) -> Richardson gives 10. Footprint: not monotone, within
    // 0.5 % -> the finest value with the spread as its uncertainty.
    const std::vector<double> h{0.4, 0.2, 0.1};
    auto report = series_of(h, {10.4, 10.2, 10.1}, {5.00, 5.02, 5.01});
    auto ref = io::reference_from_study(report, io::analyse_study(report), "elements", {});
    ASSERT_TRUE(ref.values.count("final_length"));
    EXPECT_EQ(ref.values["final_length"].kind, "richardson");
    EXPECT_NEAR(ref.values["final_length"].value, 10.0, 1e-12);
    EXPECT_NEAR(ref.values["final_length"].order, 1.0, 1e-12);
    EXPECT_NEAR(ref.values["final_length"].uncertainty, 0.1, 1e-12);
    ASSERT_TRUE(ref.values.count("footprint_diameter"));
    EXPECT_EQ(ref.values["footprint_diameter"].kind, "finest");
    EXPECT_EQ(ref.values["footprint_diameter"].value, 5.01);
    EXPECT_NEAR(ref.values["footprint_diameter"].uncertainty, 0.02, 1e-12);
    // A slow series (order 0.2) spread by 7 %: no reference, and the file says why.
    const double r2 = std::pow(2.0, 0.2);
    report = series_of(h, {10.0 + 3.0 * r2 * r2, 10.0 + 3.0 * r2, 13.0}, {5.0, 5.3, 4.7});
    ref = io::reference_from_study(report, io::analyse_study(report), "elements", {});
    EXPECT_FALSE(ref.values.count("final_length"));
    ASSERT_TRUE(ref.missing.count("final_length"));
    EXPECT_NE(ref.missing["final_length"].find("slowly"), std::string::npos) << ref.missing["final_length"];
    EXPECT_FALSE(ref.values.count("footprint_diameter"));  // not monotone, 12 % apart
    // Fewer than three resolutions: refused.
    report.cases.pop_back();
    EXPECT_THROW(io::reference_from_study(report, io::analyse_study(report), "elements", {}), InputError);
}

TEST(ElementReference, TheFileRoundTripsAndBadFilesAreNamed) {
    const std::vector<double> h{0.4, 0.2, 0.1};
    auto report = series_of(h, {10.4, 10.2, 10.1}, {5.00, 5.02, 5.01});
    report.scene_file = "scenes/x.toml";
    const auto ref = io::reference_from_study(report, io::analyse_study(report), "elements", {{0.0, 3.0}, {5.0, 2.0}, {10.0, 0.0}});
    const fs::path dir = fs::temp_directory_path() / "gpa_test_element_reference";
    fs::create_directories(dir);
    io::write_element_reference(dir / "ref.toml", ref);
    const auto back = io::read_element_reference(dir / "ref.toml");
    EXPECT_EQ(back.scene, "synthetic");
    EXPECT_EQ(back.variant, "elements:discretisation=elements");
    EXPECT_EQ(back.cell_sizes.size(), 3u);
    EXPECT_EQ(back.values.size(), ref.values.size());
    EXPECT_NEAR(back.values.at("final_length").value, 10.0, 1e-9);
    EXPECT_EQ(back.outline.size(), 3u);
    EXPECT_FALSE(back.commit.empty());
    EXPECT_EQ(back.date.size(), 10u);
    // A missing file and a bad kind are named.
    try {
        io::read_element_reference(dir / "none.toml");
        ADD_FAILURE() << "no error for a missing file";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("none.toml"), std::string::npos) << e.what();
    }
    {
        std::ifstream in(dir / "ref.toml");
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const auto at = text.find("kind = \"richardson\"");
        ASSERT_NE(at, std::string::npos);
        text.replace(at, 19, "kind = \"guess\"");
        std::ofstream(dir / "bad.toml") << text;
    }
    try {
        io::read_element_reference(dir / "bad.toml");
        ADD_FAILURE() << "no error for a bad kind";
    } catch (const InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("bad.toml"), std::string::npos) << what;
        EXPECT_NE(what.find("values.final_length.kind"), std::string::npos) << what;
    }
    fs::remove_all(dir);
}

TEST(ElementReference, OutlineDistanceAndRatios) {
    // Two cylinders 10 mm tall, radii 4 and 4.5 mm: 0.5 mm apart at every height.
    const std::vector<std::pair<double, double>> a{{0.0, 4.0}, {10.0, 4.0}}, b{{0.0, 4.5}, {10.0, 4.5}};
    EXPECT_NEAR(io::outline_distance(a, b), 0.5, 1e-12);
    EXPECT_NEAR(io::outline_distance(a, a), 0.0, 1e-15);
    EXPECT_TRUE(std::isnan(io::outline_distance(a, {})));
    // A cone against a cylinder: |r| differs by z / 10 on [0, 9.8]: mean 0.49.
    const std::vector<std::pair<double, double>> cone{{0.0, 4.0}, {10.0, 5.0}};
    EXPECT_NEAR(io::outline_distance(a, cone), 0.49, 1e-12);
    io::ElementReference ref;
    ref.values["final_length"].value = 20.0;
    ref.values["plastic_work"].value = 100.0;
    ref.outline = b;
    const auto r = io::compare_with_reference({{"final_length", 19.0}, {"plastic_work", 102.0}, {"footprint_diameter", 5.0}}, a, ref);
    EXPECT_DOUBLE_EQ(r.at("final_length"), 0.95);
    EXPECT_DOUBLE_EQ(r.at("plastic_work"), 1.02);
    EXPECT_FALSE(r.count("footprint_diameter"));  // the reference has none
    EXPECT_NEAR(r.at("outline_distance"), 0.5, 1e-12);
    // Peaks compare only over the same neighbourhood.
    ref.values["peak_plastic_strain"].value = 2.0;
    ref.peak_radius = 0.5e-3;
    EXPECT_DOUBLE_EQ(io::compare_with_reference({{"peak_plastic_strain", 1.8}, {"peak_radius", 0.5e-3}}, a, ref).at("peak_plastic_strain"), 0.9);
    EXPECT_FALSE(io::compare_with_reference({{"peak_plastic_strain", 1.8}, {"peak_radius", 0.7e-3}}, a, ref).count("peak_plastic_strain"));
    EXPECT_FALSE(io::compare_with_reference({{"peak_plastic_strain", 1.8}}, a, ref).count("peak_plastic_strain"));
}

}  // namespace
}  // namespace gpa
