// Half and quarter models (issue 23, item 2; docs/scene-format.md, "[[plane]]"): a symmetry plane
// may cut a body, which is then filled on the plane's side only while the plane's ghosts continue
// it across. A half or quarter model must be the whole body's run restricted to its share: node for
// node to round-off, its length, footprint and peaks the whole body's, its energies a share of the
// whole's. Before the hourglass control paired the ghosts of symmetry planes (hourglass.hpp,
// ghost_continues) a 3D quarter Taylor bar differed from the full one by 3.4 m/s of 210 after 3 us.

#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

PlaneSpec symmetry_plane(int axis, double position = 0.0) {
    PlaneSpec p;
    p.name = axis == 0 ? "x = 0" : "y = 0";
    p.kind = PlaneKind::Symmetry;
    p.axis = axis;
    p.position = position;
    p.side = +1;
    return p;
}

// A copper bar on a rigid anvil at 190 m/s with the solver of scenes/taylor-copper-190-3d.toml:
// 3D, 6 nodes across the radius and 8 mm long; or its plane-strain section, 12 nodes across.
Scene copper_bar(GeometryKind geometry) { return testing::short_copper_bar(geometry, 6); }

// The same bar cut by the symmetry planes through its axis normal to `axes`: the body keeps its
// shape and origin, the planes take its other share away.
Scene cut(Scene s, std::initializer_list<int> axes) {
    for (int axis : axes) s.planes.push_back(symmetry_plane(axis));
    return s;
}

using Key = std::array<long long, 3>;
Key key_of(const NodeStore& n, std::size_t i) {
    Key k{0, 0, 0};
    for (int c = 0; c < n.dim(); ++c) k[c] = std::llround(n.initial_position[c][i] * 1e8);  // 10 nm: far below a spacing
    return k;
}

// Every node of `share` against the node of `whole` that started where it did: the largest
// difference of each field over the largest magnitude of that field in the whole.
std::map<std::string, double> node_differences(const Simulation& share, const Simulation& whole) {
    const NodeStore &a = share.nodes(), &b = whole.nodes();
    std::map<Key, std::size_t> index;
    for (std::size_t i = 0; i < whole.real_count(); ++i) index[key_of(b, i)] = i;
    std::map<std::string, double> difference, scale;
    const auto compare = [&](const std::string& name, double x, double y) {
        difference[name] = std::max(difference[name], std::abs(x - y));
        scale[name] = std::max(scale[name], std::abs(y));
    };
    for (std::size_t i = 0; i < share.real_count(); ++i) {
        const auto it = index.find(key_of(a, i));
        if (it == index.end()) {
            ADD_FAILURE() << "node " << i << " of the share has no node of the whole that started where it did";
            return {};
        }
        const std::size_t j = it->second;
        for (int c = 0; c < a.dim(); ++c) {
            compare("position", a.position[c][i], b.position[c][j]);
            compare("velocity", a.velocity[c][i], b.velocity[c][j]);
        }
        compare("plastic strain", a.plastic_strain[i], b.plastic_strain[j]);
        compare("pressure", a.pressure[i], b.pressure[j]);
        compare("internal energy", a.internal_energy[i], b.internal_energy[j]);
    }
    for (auto& [name, d] : difference) d /= scale[name] > 0.0 ? scale[name] : 1.0;
    return difference;
}

// Round-off, grown over the steps run here: measured at most 1e-13 of each field's scale after
// 150 steps. A pair missing across the plane or a force not mirrored shows at 1e-4 or more within
// a few steps (see the file's comment).
constexpr double round_off = 1e-9;

void expect_same_run(Simulation& share, Simulation& whole, int copies, int steps) {
    for (int k = 0; k < steps; ++k) {
        share.step();
        whole.step();
    }
    ASSERT_EQ(share.real_count() * static_cast<std::size_t>(copies), whole.real_count());
    for (const auto& [name, d] : node_differences(share, whole)) {
        std::printf("[ measured ] 1/%d model against the whole after %d steps: %s differs by %.2g of its scale\n", copies, steps,
                    name.c_str(), d);
        EXPECT_LT(d, round_off) << name;
    }
    const Totals &s = share.totals(), &w = whole.totals();
    // The whole body's widths from the share (measure.hpp), and its energies as a share.
    EXPECT_NEAR(s.length / w.length, 1.0, round_off);
    EXPECT_NEAR(s.footprint_diameter / w.footprint_diameter, 1.0, round_off);
    EXPECT_NEAR(s.footprint_narrowest / w.footprint_narrowest, 1.0, round_off);
    EXPECT_NEAR(s.footprint_widest / w.footprint_widest, 1.0, round_off);
    EXPECT_GT(w.footprint_diameter, 2.0 * whole.scene().bodies[0].radius * 1.05) << "the face has spread by 5 %";
    EXPECT_NEAR(copies * s.plastic_work / w.plastic_work, 1.0, round_off);
    EXPECT_GT(w.plastic_work, 0.0);
    EXPECT_NEAR(copies * s.kinetic_energy / w.kinetic_energy, 1.0, round_off);
    EXPECT_NEAR(io::run_metrics(share).at("plastic_work") / io::run_metrics(whole).at("plastic_work"), 1.0, round_off);
    share.measure_bodies();
    whole.measure_bodies();
    EXPECT_NEAR(share.totals().local.plastic_strain.value / whole.totals().local.plastic_strain.value, 1.0, round_off);
    EXPECT_NEAR(share.totals().local.plastic_strain.raw / whole.totals().local.plastic_strain.raw, 1.0, round_off);
    // The peaks count the model's own points, not their mirror images (summary.json, `local`).
    EXPECT_EQ(share.totals().local.plastic_strain.points, share.real_count());
    EXPECT_EQ(whole.totals().local.plastic_strain.points, whole.real_count());
    EXPECT_EQ(share.totals().local.plastic_strain.alone, 0u);
    EXPECT_EQ(symmetry_copies(share.scene(), 0), copies);
    EXPECT_EQ(symmetry_copies(whole.scene(), 0), 1);
}

TEST(SymmetryCut, AQuarterOfAThreeDTaylorBarIsTheWholeBarsQuadrantToRoundOff) {
    const Scene whole = copper_bar(GeometryKind::ThreeD);
    const Scene quarter = cut(whole, {0, 1});
    Simulation a(quarter, 2), b(whole, 2);
    expect_same_run(a, b, 4, 150);
}

TEST(SymmetryCut, HalfAPlaneStrainBarIsTheWholeBarsHalfToRoundOffUnderEitherConnectivity) {
    for (const ConnectivityMode mode : {ConnectivityMode::Variable, ConnectivityMode::Fixed}) {
        SCOPED_TRACE(mode == ConnectivityMode::Fixed ? "fixed" : "variable");
        Scene whole = copper_bar(GeometryKind::PlaneStrain);
        whole.solver.connectivity = mode;
        // Fixed lists continue across the plane (fill_lattice), and so do both forms of the hourglass control.
        if (mode == ConnectivityMode::Fixed) whole.solver.hourglass_stiffness = 0.05;
        const Scene half = cut(whole, {0});
        Simulation a(half, 2), b(whole, 2);
        expect_same_run(a, b, 2, 200);
        // The fold of the ghosts' control forces is serial, in ghost order: no thread dependence.
        Simulation one(half, 1);
        for (int k = 0; k < 200; ++k) one.step();
        EXPECT_TRUE(testing::node_bytes(one) == testing::node_bytes(a));
    }
}

// A trimmed 3D bar (the default fill) under fixed connectivity: its fixed lists continue across
// the planes from the cells' centres, which must stay those of the nodes' cells where slivers were
// merged away (fill_lattice).
TEST(SymmetryCut, AQuarterOfAFixedTrimmedThreeDBarIsTheWholeBarsQuadrantToRoundOff) {
    Scene whole = copper_bar(GeometryKind::ThreeD);
    whole.solver.connectivity = ConnectivityMode::Fixed;
    ASSERT_EQ(cell_fill(whole.bodies[0], whole.geometry), CellFill::Trimmed);
    const Scene quarter = cut(whole, {0, 1});
    Simulation a(quarter, 2), b(whole, 2);
    // Slivers were merged: some nodes hold more than a cell.
    const double cell = std::pow(whole.bodies[0].spacing, 3);
    std::size_t merged = 0;
    for (std::size_t i = 0; i < b.real_count(); ++i) merged += b.nodes().initial_volume[i] > cell * (1.0 + 1e-9);
    ASSERT_GT(merged, 0u);
    expect_same_run(a, b, 4, 100);
}

// A bar filled with rings (CellFill::Rings): the rings are their own mirror images across the
// planes through the axis, so the quarter is the whole bar's quadrant as a lattice's is.
TEST(SymmetryCut, AQuarterOfABarFilledWithRingsIsTheWholeBarsQuadrantToRoundOff) {
    Scene whole = copper_bar(GeometryKind::ThreeD);
    whole.solver.connectivity = ConnectivityMode::Variable;
    whole.bodies[0].fill = CellFill::Rings;
    const Scene quarter = cut(whole, {0, 1});
    Simulation a(quarter, 2), b(whole, 2);
    expect_same_run(a, b, 4, 150);
}

TEST(SymmetryCut, TheQuarterFillIsTheWholeFillsQuadrant) {
    const Scene whole = copper_bar(GeometryKind::ThreeD);
    const Scene quarter = cut(whole, {0, 1});
    const Simulation a(quarter, 1), b(whole, 1);
    std::size_t in_quadrant = 0;
    double mass = 0.0, whole_mass = 0.0;
    for (std::size_t i = 0; i < b.real_count(); ++i) {
        whole_mass += b.nodes().mass[i];
        if (b.nodes().position[0][i] > 0.0 && b.nodes().position[1][i] > 0.0) ++in_quadrant;
    }
    for (std::size_t i = 0; i < a.real_count(); ++i) {
        mass += a.nodes().mass[i];
        EXPECT_GT(a.nodes().position[0][i], 0.0);
        EXPECT_GT(a.nodes().position[1][i], 0.0);
    }
    EXPECT_EQ(a.real_count(), in_quadrant);
    EXPECT_EQ(4 * a.real_count(), b.real_count());
    EXPECT_NEAR(4.0 * mass / whole_mass, 1.0, 1e-13);
}

void expect_refused(const Scene& s, std::initializer_list<std::string> words) {
    try {
        validate_scene(s);
        ADD_FAILURE() << "the scene was accepted";
    } catch (const InputError& e) {
        for (const std::string& w : words) EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
    }
}

TEST(SymmetryCut, PlanesThatCannotCutABodyAreRefusedNamingPlaneAndBody) {
    const Scene bar = copper_bar(GeometryKind::PlaneStrain);
    const double spacing = bar.bodies[0].spacing;
    {
        // Between two cell faces: its ghosts would not continue the lattice.
        Scene s = bar;
        s.planes.push_back(symmetry_plane(0, 0.25 * spacing));
        s.planes.back().name = "mid";
        expect_refused(s, {"plane \"mid\"", "body \"bar\"", "cell face"});
    }
    {
        Scene s = cut(bar, {0});
        s.bodies[0].discretisation = Discretisation::Elements;
        expect_refused(s, {"body \"bar\"", "elements"});
    }
    {
        // In axisymmetric geometry a plane normal to x is a cylinder around the axis.
        Scene s = bar;
        s.geometry = GeometryKind::Axisymmetric;
        s.bodies[0].shape = ShapeKind::Cylinder;
        s.bodies[0].origin = {0.0, 0.0, 0.0};
        s.planes.push_back(symmetry_plane(0, 0.5 * s.bodies[0].radius));
        expect_refused(s, {"axisymmetric", "body \"bar\"", "normal to z"});
    }
    {
        // A rigid plane still may not cut a body.
        Scene s = bar;
        s.planes.push_back(symmetry_plane(0));
        s.planes.back().kind = PlaneKind::Rigid;
        expect_refused(s, {"wrong side", "body \"bar\""});
    }
    {
        // A body wholly behind a symmetry plane is not cut by it.
        Scene s = bar;
        s.planes.push_back(symmetry_plane(0, 2.0 * s.bodies[0].radius));
        expect_refused(s, {"wrong side", "body \"bar\""});
    }
    // Cut on a cell face, as the cases above but for the cause: valid.
    EXPECT_NO_THROW(validate_scene(cut(bar, {0})));
    EXPECT_NO_THROW(validate_scene(cut(copper_bar(GeometryKind::ThreeD), {0, 1})));
}

}  // namespace
}  // namespace gpa
