// Bodies and planes in any orientation (issue 23, item 2; docs/orientation.md). A scene turned as a
// whole (rotated_scene: bodies with their lattices, planes, velocities) must give the run of the
// upright scene seen in turned axes. With the frame-invariant normalisation (the moment matrix)
// nothing of the method is taken in the global frame, so the turned run is the upright one turned,
// node for node, to round-off; with the paper's per-direction geometry factors it is not, and the
// tests record by how much. The planes' reflections, the turned lattices and the measurement
// across an oblique plane are what these runs exercise.

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/node_set.hpp"
#include "gpa/engine/orientation.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

constexpr double pi = std::numbers::pi;

TEST(Orientation, RotationsAreOrthonormalAndTurnTensorsAsTheyTurnVectors) {
    const Rotation r = rotation_about({1.0, -2.0, 0.5}, 0.7);
    EXPECT_FALSE(rotation_problem(r, 3).has_value());
    const Rotation back = compose(transpose(r), r);
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(back[k], identity_rotation[k], 1e-15);
    // The axis stays put; a quarter turn about z takes x to y.
    const auto axis = turn(r, {1.0, -2.0, 0.5});
    EXPECT_NEAR(axis[0], 1.0, 1e-15);
    EXPECT_NEAR(axis[1], -2.0, 1e-15);
    EXPECT_NEAR(axis[2], 0.5, 1e-15);
    const auto y = turn(rotation_about({0, 0, 3}, pi / 2), {1, 0, 0});
    EXPECT_NEAR(y[0], 0.0, 1e-16);
    EXPECT_NEAR(y[1], 1.0, 1e-16);
    // sigma = t t^T turns into (R t)(R t)^T.
    const std::array<double, 3> t{0.3, -0.4, 1.2};
    const auto rt = turn(r, t);
    const auto s = rotate_tensor(r, {t[0] * t[0], t[1] * t[1], t[2] * t[2], t[1] * t[2], t[0] * t[2], t[0] * t[1]}, 3);
    const std::array<double, 6> expected{rt[0] * rt[0], rt[1] * rt[1], rt[2] * rt[2], rt[1] * rt[2], rt[0] * rt[2], rt[0] * rt[1]};
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(s[k], expected[k], 1e-15);
    // Plane strain: the out-of-plane component stays.
    const auto s2 = rotate_tensor(rotation_in_plane(0.4), {1.0, 2.0, 0.5, 7.0, 0, 0}, 2);
    EXPECT_EQ(s2[3], 7.0);
    EXPECT_NEAR(s2[0] + s2[1], 3.0, 1e-15);  // the trace
    // Not rotations.
    Rotation mirror = identity_rotation;
    mirror[0] = -1.0;
    EXPECT_TRUE(rotation_problem(mirror, 3).has_value());
    Rotation skew = identity_rotation;
    skew[1] = 0.1;
    EXPECT_TRUE(rotation_problem(skew, 3).has_value());
    EXPECT_TRUE(rotation_problem(rotation_about({1, 0, 0}, 0.3), 2).has_value());  // turns the out-of-plane y
    EXPECT_THROW(rotation_about({0, 0, 0}, 1.0), InputError);
}

TEST(Orientation, AnObliquePlaneReflectsPointsVectorsAndTensorsAsTheAlignedOnesDo) {
    // An "oblique" plane along a coordinate axis reflects exactly as the aligned plane does.
    for (int dim : {2, 3}) {
        for (int axis = 0; axis < dim; ++axis) {
            GhostPlane aligned, general;
            aligned.axis = axis;
            aligned.position = general.position = 0.3;
            general.axis = -1;
            general.normal[static_cast<std::size_t>(axis)] = 1.0;
            std::array<double, 6> a{1.0, 2.0, 3.0, 0.4, 0.5, 0.6}, b = a;
            if (dim == 2) a[4] = a[5] = b[4] = b[5] = 0.0;
            aligned.reflect_tensor(dim, a);
            general.reflect_tensor(dim, b);
            for (int k = 0; k < 6; ++k) EXPECT_NEAR(a[k], b[k], 1e-15) << dim << "D axis " << axis << " entry " << k;
            std::array<double, 3> x{0.1, 0.7, dim == 3 ? -0.2 : 0.0}, y = x;
            aligned.reflect_point(x);
            general.reflect_point(y);
            for (int k = 0; k < 3; ++k) EXPECT_NEAR(x[k], y[k], 1e-15);
        }
    }
    // An oblique plane: a point on it stays, reflecting twice gives back the point, the vector and
    // the tensor; the reflected tensor is H S H.
    GhostPlane p;
    p.axis = -1;
    const double l = std::sqrt(1.0 + 4.0 + 0.25);
    p.normal = {1.0 / l, -2.0 / l, 0.5 / l};
    p.position = 0.02;
    std::array<double, 3> on{0.02 * p.normal[0], 0.02 * p.normal[1], 0.02 * p.normal[2]};
    const auto kept = on;
    p.reflect_point(on);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(on[k], kept[k], 1e-17);
    std::array<double, 6> s{1.0, -2.0, 3.0, 0.4, -0.5, 0.6};
    const auto s0 = s;
    p.reflect_tensor(3, s);
    Rotation h{};
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) h[3 * i + j] = (i == j ? 1.0 : 0.0) - 2.0 * p.normal[i] * p.normal[j];
    }
    const auto hsh = rotate_tensor(h, s0, 3);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(s[k], hsh[k], 1e-14);
    p.reflect_tensor(3, s);
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(s[k], s0[k], 1e-14);
}

// A copper bar on a rigid anvil at 190 m/s (the solver of scenes/taylor-copper-190-3d.toml, 8 mm
// long): in 3D a quarter model cut by the symmetry planes x = 0 and y = 0 with 5 nodes across the
// radius, or in plane strain a whole section with 10 across.
Scene copper_bar(GeometryKind geometry, Normalisation normalisation) {
    Scene s = testing::short_copper_bar(geometry, 5);
    if (geometry == GeometryKind::ThreeD) {
        for (int axis : {0, 1}) {
            PlaneSpec p;
            p.name = axis == 0 ? "x-symmetry" : "y-symmetry";
            p.kind = PlaneKind::Symmetry;
            p.axis = axis;
            s.planes.push_back(p);
        }
    }
    s.solver.normalisation = normalisation;
    return s;
}

struct Differences {
    double position = 0.0, velocity = 0.0, plastic_strain = 0.0, pressure = 0.0;
};

// Each node of the turned run against the node of the upright one filled in the same place (the
// lattice is filled in the body's own axes, in the same order: the same NodeStore::id; the runs
// sort their nodes in space, each its own way), its vectors turned back: the largest difference
// over the largest magnitude of each field.
Differences node_differences(const Simulation& turned_run, const Simulation& upright, const Rotation& r) {
    const NodeStore &a = turned_run.nodes(), &b_store = upright.nodes();
    const int d = a.dim();
    std::vector<std::size_t> of_id(upright.real_count());
    for (std::size_t j = 0; j < upright.real_count(); ++j) of_id.at(b_store.id[j]) = j;
    Differences diff, scale;
    for (std::size_t i = 0; i < upright.real_count(); ++i) {
        const std::size_t j = of_id.at(a.id[i]);
        const auto b_of = [&](const auto& field) { return field[j]; };
        std::array<double, 3> x{0, 0, 0}, v{0, 0, 0};
        for (int c = 0; c < d; ++c) x[c] = a.position[c][i], v[c] = a.velocity[c][i];
        x = turn_back(r, x);
        v = turn_back(r, v);
        for (int c = 0; c < d; ++c) {
            diff.position = std::max(diff.position, std::abs(x[c] - b_of(b_store.position[c])));
            scale.position = std::max(scale.position, std::abs(b_of(b_store.position[c])));
            diff.velocity = std::max(diff.velocity, std::abs(v[c] - b_of(b_store.velocity[c])));
            scale.velocity = std::max(scale.velocity, std::abs(b_of(b_store.velocity[c])));
        }
        diff.plastic_strain = std::max(diff.plastic_strain, std::abs(a.plastic_strain[i] - b_of(b_store.plastic_strain)));
        scale.plastic_strain = std::max(scale.plastic_strain, std::abs(b_of(b_store.plastic_strain)));
        diff.pressure = std::max(diff.pressure, std::abs(a.pressure[i] - b_of(b_store.pressure)));
        scale.pressure = std::max(scale.pressure, std::abs(b_of(b_store.pressure)));
    }
    return {diff.position / scale.position, diff.velocity / scale.velocity, diff.plastic_strain / scale.plastic_strain,
            diff.pressure / scale.pressure};
}

struct Turned {
    Differences nodes;
    double length, footprint, plastic_work;  // turned over upright, less 1
    double energy_error_turned = 0.0, energy_error_upright = 0.0;
};

Turned run_both(const Scene& upright_scene, const Rotation& r, int steps) {
    const Scene turned_scene = rotated_scene(upright_scene, r);
    Simulation turned_run(turned_scene, 2), upright(upright_scene, 2);
    EXPECT_EQ(turned_run.real_count(), upright.real_count());
    for (int k = 0; k < steps; ++k) {
        turned_run.step();
        upright.step();
    }
    const Totals &a = turned_run.totals(), &b = upright.totals();
    EXPECT_GT(b.plastic_work, 0.0);
    EXPECT_GT(b.footprint_diameter, 2.0 * upright_scene.bodies[0].radius * 1.03) << "the face has spread by 3 %";
    return {node_differences(turned_run, upright, r), a.length / b.length - 1.0, a.footprint_diameter / b.footprint_diameter - 1.0,
            a.plastic_work / b.plastic_work - 1.0, a.energy_error, b.energy_error};
}

void print(const char* what, const Turned& t) {
    std::printf("[ measured ] %s: nodes differ by position %.2g, velocity %.2g, plastic strain %.2g, pressure %.2g of their "
                "scales; length %+.3g %%, footprint %+.3g %%, plastic work %+.3g %%\n",
                what, t.nodes.position, t.nodes.velocity, t.nodes.plastic_strain, t.nodes.pressure, 100 * t.length,
                100 * t.footprint, 100 * t.plastic_work);
    std::printf("[ measured ]   energy error %.3g turned, %.3g upright\n", t.energy_error_turned, t.energy_error_upright);
}

// Round-off, grown over the steps run here (a turned run sums its pairs in another order). A
// reflection that is not the mirror image, a lattice filled across the wrong face or a push not
// along the normal shows at 1e-3 or more within a few steps.
constexpr double round_off = 1e-8;

TEST(Orientation, ATurnedQuarterTaylorBarIsTheUprightRunTurnedWithTheMomentMatrix) {
    // An arbitrary turn: the anvil and both symmetry planes become oblique planes, and the
    // symmetry planes cut the turned body along its own lattice.
    const Rotation r = rotation_about({0.3, -0.5, 0.8}, 0.9);
    const Turned t = run_both(copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix), r, 120);
    print("3D quarter bar turned, moment matrix", t);
    EXPECT_LT(t.nodes.position, round_off);
    EXPECT_LT(t.nodes.velocity, round_off);
    EXPECT_LT(t.nodes.plastic_strain, round_off);
    EXPECT_LT(t.nodes.pressure, round_off);
    // The measures (the footprint is the mean width over 36 directions in the anvil's plane, whose
    // in-plane axes turn differently from the bar's: the bound of 0.5 %).
    EXPECT_LT(std::abs(t.length), 1e-9);
    EXPECT_LT(std::abs(t.footprint), 5e-3);
    EXPECT_LT(std::abs(t.plastic_work), 1e-8);
}

TEST(Orientation, ATurnedQuarterTaylorBarRecordsThePerDirectionNormalisationsFrameDependence) {
    const Rotation r = rotation_about({0.3, -0.5, 0.8}, 0.9);
    const Turned t = run_both(copper_bar(GeometryKind::ThreeD, Normalisation::PerDirection), r, 120);
    print("3D quarter bar turned, per-direction factors", t);
    // The paper's factors are taken along the global axes: the turned bar is another run.
    EXPECT_GT(t.nodes.velocity, 1e-4);
}

TEST(Orientation, APlaneStrainBarOnATiltedAnvilIsTheUprightRunTurned) {
    const Rotation r = rotation_in_plane(0.5);
    const Turned moment = run_both(copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix), r, 200);
    print("plane-strain bar turned by 0.5 rad, moment matrix", moment);
    EXPECT_LT(moment.nodes.position, round_off);
    EXPECT_LT(moment.nodes.velocity, round_off);
    EXPECT_LT(moment.nodes.plastic_strain, round_off);
    EXPECT_LT(std::abs(moment.length), 1e-9);
    EXPECT_LT(std::abs(moment.footprint), 1e-9);  // one width across in 2D: no directions to sample
    EXPECT_LT(std::abs(moment.plastic_work), 1e-8);
    // Results do not depend on the thread count on oblique planes either.
    const Scene tilted = rotated_scene(copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix), r);
    Simulation one(tilted, 1), two(tilted, 2);
    for (int k = 0; k < 200; ++k) {
        one.step();
        two.step();
    }
    EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(two));
    const Turned per_direction = run_both(copper_bar(GeometryKind::PlaneStrain, Normalisation::PerDirection), r, 200);
    print("plane-strain bar turned by 0.5 rad, per-direction factors", per_direction);
    EXPECT_GT(per_direction.nodes.velocity, 1e-4);
}

TEST(Orientation, ATiltedAnvilWithFrictionPushesAndHoldsAlongItsNormal) {
    // Coulomb friction in the plane and the plane's reaction on an oblique anvil, which the bar
    // strikes obliquely (a sideways velocity).
    Scene upright = copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix);
    upright.planes[0].friction_static = upright.planes[0].friction_dynamic = 0.2;
    upright.bodies[0].velocity = {60.0, -190.0, 0.0};
    const Rotation r = rotation_in_plane(-0.8);
    const Turned t = run_both(upright, r, 300);
    print("plane-strain bar turned by -0.8 rad, oblique strike with friction, moment matrix", t);
    EXPECT_LT(t.nodes.position, round_off);
    EXPECT_LT(t.nodes.velocity, round_off);
    EXPECT_LT(t.nodes.plastic_strain, round_off);
    EXPECT_LT(std::abs(t.length), 1e-9);
    EXPECT_LT(std::abs(t.plastic_work), 1e-8);
    Simulation turned_run(rotated_scene(upright, r), 2), upright_run(upright, 2);
    for (int k = 0; k < 300; ++k) {
        turned_run.step();
        upright_run.step();
    }
    const auto& a = turned_run.totals().planes.at(0);
    const auto& b = upright_run.totals().planes.at(0);
    EXPECT_GT(b.friction_work, 0.0);
    EXPECT_NEAR(a.friction_work / b.friction_work, 1.0, round_off);
    EXPECT_NEAR(a.impulse / b.impulse, 1.0, round_off);
}

TEST(Orientation, ATiltedAnvilWithLiftOffReleasesAlongItsNormal) {
    // Contact that may open: sigma_nn and the normal velocity decide it along the oblique normal.
    // Those are yes-or-no decisions on values that pass through zero, which round-off can tip a
    // step earlier or later. Measured after 300 steps: a head-on strike turned by -0.8 rad is the
    // upright run to round-off (velocities within 1e-13 of their scale), while a turn of 1e-14 rad,
    // which changes nothing but the rounding, differs by 2 % of the velocity scale (first between
    // 150 and 200 steps), as does an oblique strike at either angle. The same scene with its anvil
    // written as an oblique plane of normal (0, 1) (the oblique code path, no turn at all) stays
    // within 1e-14 of the aligned run: the oblique path is right, and the spread is the contact
    // decisions'. The measures differ by 2e-5 (length, footprint) and 2e-4 (plastic work); 1e-3
    // bounds them.
    Scene upright = copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix);
    upright.planes[0].lift_off = true;
    for (const bool oblique_strike : {false, true}) {
        upright.bodies[0].velocity = {oblique_strike ? 60.0 : 0.0, -190.0, 0.0};
        for (const double angle : {-0.8, 1e-14}) {
            const Turned t = run_both(upright, rotation_in_plane(angle), 300);
            std::printf("[ measured ] %s strike, turned by %g rad:\n", oblique_strike ? "oblique" : "head-on", angle);
            print("plane-strain bar on a tilted anvil with lift-off, moment matrix", t);
            EXPECT_LT(std::abs(t.length), 1e-3);
            EXPECT_LT(std::abs(t.footprint), 1e-3);
            EXPECT_LT(std::abs(t.plastic_work), 1e-3);
        }
    }
}

TEST(Orientation, TheEnergyClosesOnObliquePlanesWithTheMomentMatrixAndAWarningSaysSoOtherwise) {
    // Under the moment matrix the ghosts across an oblique plane are exact mirror images, and the
    // turned run's energy closes as the upright one's does; under the per-direction factors they
    // are not (docs/orientation.md), and scene_warnings names the plane and the remedy.
    const Rotation r = rotation_in_plane(0.5);
    const Turned moment = run_both(copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix), r, 200);
    EXPECT_LT(std::abs(moment.energy_error_turned), 1e-12);
    EXPECT_LT(std::abs(moment.energy_error_upright), 1e-12);
    const Turned per_direction = run_both(copper_bar(GeometryKind::PlaneStrain, Normalisation::PerDirection), r, 200);
    print("plane-strain bar turned by 0.5 rad, per-direction factors", per_direction);
    EXPECT_LT(std::abs(per_direction.energy_error_upright), 1e-12);
    EXPECT_GT(std::abs(per_direction.energy_error_turned), 1e-4);  // measured -0.0052
    const auto warned = [](const Scene& s) {
        for (const std::string& w : scene_warnings(s)) {
            if (w.find("moment-matrix") != std::string::npos && w.find("plane \"anvil\"") != std::string::npos) return true;
        }
        return false;
    };
    EXPECT_TRUE(warned(rotated_scene(copper_bar(GeometryKind::PlaneStrain, Normalisation::PerDirection), r)));
    EXPECT_FALSE(warned(rotated_scene(copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix), r)));
    EXPECT_FALSE(warned(copper_bar(GeometryKind::PlaneStrain, Normalisation::PerDirection)));  // upright: aligned planes
}

TEST(Orientation, ATurnedFixedLatticeContinuesAcrossPlanesAlongItsAxes) {
    // Fixed connectivity: the turned lattice's mirrored lattice neighbours (lattice_mirror_planes)
    // across the turned anvil and symmetry planes, in the body's own axes.
    Scene upright = copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix);
    upright.solver.connectivity = ConnectivityMode::Fixed;
    upright.solver.hourglass_stiffness = 0.05;
    const Turned t = run_both(upright, rotation_about({-0.2, 0.9, 0.4}, 2.1), 100);
    print("3D quarter bar turned, fixed connectivity, moment matrix", t);
    EXPECT_LT(t.nodes.position, round_off);
    EXPECT_LT(t.nodes.velocity, round_off);
    EXPECT_LT(std::abs(t.plastic_work), 1e-8);
}

TEST(Orientation, AQuarterTurnKeepsPlanesAligned) {
    // cos(pi/2) is 6e-17, not 0: the turned normals are snapped to the axes they lie along.
    const Scene s = rotated_scene(copper_bar(GeometryKind::ThreeD, Normalisation::PerDirection), rotation_about({0, 0, 1}, pi / 2));
    ASSERT_EQ(s.planes.size(), 3u);
    EXPECT_EQ(s.planes[0].axis, 2);  // the anvil, normal to z
    EXPECT_EQ(s.planes[1].axis, 1);  // x = 0 turned onto y = 0
    EXPECT_EQ(s.planes[2].axis, 0);  // y = 0 turned onto x = 0, its side flipped
    EXPECT_EQ(s.planes[2].side, -1);
    EXPECT_NO_THROW(validate_scene(s));
}

TEST(Orientation, TurnedImportedNodesAreCheckedWhereTheyAre) {
    // Two imported nodes along x, turned a quarter about z: they lie along y. A box where they now
    // are overlaps them; one where they would have been does not.
    auto set = std::make_shared<NodeSet>();
    set->positions = {{1e-3, 0, 0}, {2e-3, 0, 0}};
    set->sizes = {1e-9, 1e-9};
    Scene s = copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix);
    s.planes.clear();
    BodySpec nodes;
    nodes.name = "nodes";
    nodes.shape = ShapeKind::Nodes;
    nodes.material = s.bodies[0].material;
    nodes.node_set = std::make_shared<NodeSetShape>(set, 3);
    nodes.origin = {0.0, 0.0, 20e-3};
    nodes.rotation = rotation_about({0, 0, 1}, pi / 2);
    BodySpec box;
    box.name = "box";
    box.shape = ShapeKind::Box;
    box.material = s.bodies[0].material;
    box.spacing = 1e-3;
    box.size = {2e-3, 4e-3, 2e-3};
    s.bodies = {nodes, box};
    s.bodies[1].origin = {-1e-3, 0.5e-3, 19e-3};  // around (0, 1..2 mm, 20 mm): where the turned nodes are
    try {
        validate_scene(s);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("overlaps"), std::string::npos) << e.what();
    }
    s.bodies[1].origin = {0.5e-3, -1e-3, 21.5e-3};  // around where they would have been, clear of the turned ones
    s.bodies[1].size = {4e-3, 2e-3, 2e-3};
    EXPECT_NO_THROW(validate_scene(s));
}

TEST(Orientation, WhatCannotTurnIsRefused) {
    Scene axisymmetric = copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix);
    axisymmetric.geometry = GeometryKind::Axisymmetric;
    EXPECT_THROW(rotated_scene(axisymmetric, rotation_in_plane(0.1)), InputError);
    Scene bar = copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix);
    Rotation mirror = identity_rotation;
    mirror[8] = -1.0;
    EXPECT_THROW(rotated_scene(bar, mirror), InputError);
    // A symmetry plane that cuts a turned body across its lattice.
    Scene oblique = bar;
    oblique.bodies[0].rotation = rotation_about({0, 0, 1}, 0.3);
    try {
        validate_scene(oblique);
        ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("obliquely to its lattice"), std::string::npos) << e.what();
    }
    const auto refused = [](const Scene& scene, const std::string& words) {
        try {
            validate_scene(scene);
            ADD_FAILURE() << "accepted; expected: " << words;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    // A plane's normal must be a unit vector, of the scene's dimension.
    Scene bad = bar;
    bad.planes[0].axis = -1;
    bad.planes[0].normal = {0.0, 0.0, 2.0};
    refused(bad, "must be a finite unit vector");
    Scene flat = copper_bar(GeometryKind::PlaneStrain, Normalisation::MomentMatrix);
    flat.planes[0].axis = -1;
    flat.planes[0].normal = {0.0, 1.0 / std::sqrt(1.49), 0.7 / std::sqrt(1.49)};
    refused(flat, "third component");
    // Symmetry planes of one body at 60 degrees (a box standing in the corner, touching both): no
    // set of mirror copies.
    Scene wedge = bar;
    wedge.bodies[0].shape = ShapeKind::Box;
    wedge.bodies[0].size = {3e-3, 3e-3, 8e-3};
    wedge.planes[2].axis = -1;
    wedge.planes[2].normal = {std::cos(pi / 3), std::sin(pi / 3), 0.0};
    refused(wedge, "parallel or perpendicular");
    // A fixed lattice turned against an aligned anvil.
    Scene fixed = copper_bar(GeometryKind::ThreeD, Normalisation::MomentMatrix);
    fixed.planes.resize(1);
    fixed.solver.connectivity = ConnectivityMode::Fixed;
    fixed.bodies[0].rotation = rotation_about({1, 0, 0}, 0.3);
    fixed.bodies[0].origin[2] = 2e-3;  // clear of the anvil
    refused(fixed, "oblique to its lattice");
    fixed.solver.connectivity = ConnectivityMode::Variable;
    EXPECT_NO_THROW(validate_scene(fixed));
}

}  // namespace
}  // namespace gpa
