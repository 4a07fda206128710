// 3D against 2D at matched spacing (issue 23; docs/validation.md, "3D: the impact face and the
// node diameter" and "The 3D fill"): the Taylor bars run to rest on 2 threads in both geometries at
// the same spacing. Long: labelled "slow".

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

struct Shape {
    double length = 0.0, footprint = 0.0, narrowest = 0.0, widest = 0.0, peak = 0.0;
};

// The element solver's balance closes to the integrator's order, not to round-off
// (docs/elements.md, "Rigid planes"; its own tests bound it at 1e-3): 3.4e-5 and 4.5e-5 measured on
// the bars of TheCopperAndSteelBarsAgreeWithTheElementsAtMatchedSpacing.
constexpr double element_energy_bound = 1e-3;

// The scene run to rest, the peaks averaged over two spacings in both geometries.
Shape run(Scene s, const std::string& label, double energy_bound = 1e-12) {
    s.output.peak_radius = 2.0 * s.bodies[0].spacing;
    Simulation sim(s, 2);
    while (!sim.finished()) sim.step();
    sim.measure_bodies();
    const auto& t = sim.totals();
    // Every option these runs use (rings and trimmed cells, the stretch diameters, the damping on
    // every node, symmetry planes through the body) books its work in the compatible update: the
    // balance closes to round-off over the whole run (about 1e-14 measured).
    EXPECT_LT(std::abs(t.energy_error), energy_bound) << label;
    const Shape out{t.length, t.footprint_diameter, t.footprint_narrowest, t.footprint_widest, t.local.plastic_strain.value};
    std::printf("[ measured ] %s: L %.4f mm, D %.4f mm (%.4f-%.4f), peak plastic strain %.4f, %zu nodes\n", label.c_str(),
                out.length * 1e3, out.footprint * 1e3, out.narrowest * 1e3, out.widest * 1e3, out.peak, sim.real_count());
    return out;
}

Scene scene_file(const std::string& file, double refine) {
    return io::refined(io::load_scene(std::filesystem::path(GPA_SOURCE_DIR) / "scenes" / file), refine);
}

Shape run(const std::string& file, double refine) { return run(scene_file(file, refine), file); }

// The quarter of a 3D bar standing on the anvil z = 0 with its axis on z: the symmetry planes x = 0
// and y = 0 cut it, and their ghosts continue it (docs/validation.md, "Half and quarter models": the
// quarter is the whole bar's quadrant to round-off).
Scene quarter_of(Scene s) { return testing::with_quarter_planes(std::move(s)); }

// The 2D scene with the solver of its 3D version: the hourglass damping on every node, the 3D
// default (solver.hourglass_nodes), so that the comparison measures the 3D discretisation alone.
Scene damped_everywhere(Scene s) {
    s.solver.hourglass_nodes = HourglassNodes::All;
    return s;
}

// The bounds for 3D against 2D at matched spacing: length within 1 %, footprint within 2 %,
// peak plastic strain within 10 %; and a round face (widest over narrowest width within 5 %: a face
// split into spokes along the lattice's rows is wider across its diagonals).
void expect_agreement(const Shape& solid, const Shape& plane) {
    EXPECT_NEAR(solid.length / plane.length, 1.0, 0.01);
    EXPECT_NEAR(solid.footprint / plane.footprint, 1.0, 0.02);
    EXPECT_NEAR(solid.peak / plane.peak, 1.0, 0.10);
    EXPECT_LT(solid.widest / solid.narrowest, 1.05);
}

// Measured (2026-12-05, trimmed fill): length +0.43 %, footprint -0.05 %, peak -1.4 %, widest over
// narrowest 1.011. This bar spreads least of the Taylor bars.
TEST(ThreeD, TheSteelBarAt343MetresPerSecondAgreesWithTwoDAtMatchedSpacing) {
    // scenes/taylor-steel-343.toml has 15 nodes across the radius, its 3D version 8: both to 10.
    // The scenes' own solver: the node diameter follows the stretch (the default).
    expect_agreement(run("taylor-steel-343-3d.toml", 10.0 / 8.0),
                     run(damped_everywhere(scene_file("taylor-steel-343.toml", 10.0 / 15.0)), "taylor-steel-343.toml"));
}

// The shipped 3D scenes of copper 190, steel 208 and the paper's cylinder (nodal viscosity) at
// their 8 nodes across the radius against the 2D scenes at the same spacing, the 3D ones as quarters.
// Measured (2026-12-05): copper length +0.01 %, footprint -1.2 %, peak +0.2 %; steel +0.04 %,
// +0.44 %, -1.0 %; widest over narrowest 1.027 and 1.018. The cylinder, filled with rings since
// 2026-12-07 (docs/validation.md, "3D: rings about the axis"): -0.06 %, +0.29 %, +3.8 %, 1.010
// (its cubic trimmed fill gave -0.37 %, +1.1 %, +3.8 %, 1.018). With the damping on the lattice
// regime alone the 3D footprints grow with refinement, to +8 % over 2D at 16 across
// (docs/validation.md, "The face pairs in the hoop direction").
TEST(ThreeD, TheCopperAndSteelBarsAndThePapersCylinderAgreeWithTwoDAtTheShippedSpacing) {
    expect_agreement(run(scene_file("taylor-copper-190-3d-quarter.toml", 1.0), "copper 190, 3D quarter"),
                     run(damped_everywhere(scene_file("taylor-copper-190.toml", 8.0 / 15.0)), "copper 190, 2D"));
    expect_agreement(run(quarter_of(scene_file("taylor-steel-208-3d.toml", 1.0)), "steel 208, 3D quarter"),
                     run(damped_everywhere(scene_file("taylor-steel-208.toml", 8.0 / 15.0)), "steel 208, 2D"));
    expect_agreement(run(quarter_of(scene_file("armco-cylinder-nodal-3d.toml", 1.0)), "Armco cylinder, 3D quarter"),
                     run(damped_everywhere(scene_file("armco-cylinder-nodal.toml", 8.0 / 20.0)), "Armco cylinder, 2D"));
}

// The element solver at the spacing of a particle run: the 2D scene with every body meshed from
// the same shapes (gpa study's variant discretisation=elements).
Scene as_elements(Scene s) {
    io::apply_variant(io::parse_variant("elements:discretisation=elements"), s);
    return s;
}

// A 3D quarter (`solid`) and the 2D scene at the same spacing (`plane`), run as particles with the
// 3D damping and as elements, against the bounds: against the elements length 1 %,
// footprint 2 %, peak plastic strain 10 %; against 2D expect_agreement.
void expect_agreement_with_elements(const std::string& label, double across, const Scene& solid_scene, const Scene& plane_scene) {
    const Shape solid = run(solid_scene, label + ", 3D quarter");
    const Shape elements = run(as_elements(plane_scene), label + ", elements", element_energy_bound);
    const Shape plane = run(damped_everywhere(plane_scene), label + ", 2D");
    std::printf("[ measured ] %s at %.0f across, 3D against elements: L %+.2f %%, D %+.2f %%, peak %+.1f %%; against 2D: "
                "L %+.2f %%, D %+.2f %%, peak %+.1f %%\n",
                label.c_str(), across, 100 * (solid.length / elements.length - 1), 100 * (solid.footprint / elements.footprint - 1),
                100 * (solid.peak / elements.peak - 1), 100 * (solid.length / plane.length - 1),
                100 * (solid.footprint / plane.footprint - 1), 100 * (solid.peak / plane.peak - 1));
    SCOPED_TRACE(label);
    EXPECT_NEAR(solid.length / elements.length, 1.0, 0.01);
    EXPECT_NEAR(solid.footprint / elements.footprint, 1.0, 0.02);
    EXPECT_NEAR(solid.peak / elements.peak, 1.0, 0.10);
    expect_agreement(solid, plane);
}

// The bounds against the elements at matched spacing (length 1 %, footprint 2 %, peak
// plastic strain 10 %), at 12 nodes across the radius of the 7.62 mm bars: 3D quarters, the 2D
// scene with the 3D damping and the element solver, all at the same spacing, the peaks averaged
// over the same radius (two spacings). At the shipped 8 across the 3D footprints are 2-4 % below
// the elements', and the 2D particles' with the same damping alike (docs/validation.md, "The
// default"): coarse spacing in the particle method, not the third dimension; from 12 across they
// are within the bound. The paper's cylinder has its own test below: under the scene's paper preset
// its 2D particle run with this damping is itself 1.9 % long against the elements at 12 across (3D
// 1.7 %), so the bound does not hold for the method in either geometry at that spacing
// (docs/validation.md).
TEST(ThreeD, TheCopperAndSteelBarsAgreeWithTheElementsAtMatchedSpacing) {
    const double across = 12.0;
    struct Case {
        const char* label;
        Scene solid, plane;
    };
    const Case cases[] = {
        {"copper 190", scene_file("taylor-copper-190-3d-quarter.toml", across / 8.0), scene_file("taylor-copper-190.toml", across / 15.0)},
        {"steel 208", quarter_of(scene_file("taylor-steel-208-3d.toml", across / 8.0)), scene_file("taylor-steel-208.toml", across / 15.0)},
    };
    for (const Case& c : cases) expect_agreement_with_elements(c.label, across, c.solid, c.plane);
}

// The paper's cylinder (nodal viscosity) against the elements at matched spacing, with the issue's
// bounds, at 20 nodes across the radius: the quarter of scenes/armco-cylinder-nodal-3d.toml (rings
// about the axis), the element solver and the 2D particles with the 3D damping, at the same spacing.
// Both particle runs take the Taylor preset (SPH-NSF weight, a = 1.3), with the 3D defaults
// otherwise. Under the scene's own paper preset the particles' length misses the bound in both
// geometries alike (3D +1.69 / +1.53 % at 12 / 16 across, 2D with the same damping +1.92 / +1.79 %).
// The cylinder is the Taylor test that flows farthest (D / D0 = 2), and the damping on every node
// resists its flow until the spacing is fine: measured 2026-12-07/08 against the elements, L +1.25 /
// +0.88 / +0.67 % and D -3.29 / -2.14 / -1.52 % at 12 / 16 / 20 across; at 20, peak plastic strain
// -5.1 %, and against 2D +0.25 %, -0.53 %, -0.1 %; about 300 s on 2 threads (docs/validation.md,
// "The paper's cylinder against the elements at matched spacing").
TEST(ThreeD, ThePapersCylinderAgreesWithTheElementsAtMatchedSpacingUnderTheTaylorPreset) {
    const double across = 20.0;
    const auto taylor = [](Scene s) {
        io::apply_variant(io::parse_variant("taylor:preset=taylor-bar"), s);
        return s;
    };
    expect_agreement_with_elements("Armco cylinder", across, taylor(quarter_of(scene_file("armco-cylinder-nodal-3d.toml", across / 8.0))),
                                   taylor(scene_file("armco-cylinder-nodal.toml", across / 20.0)));
}

// The quarter model of the copper bar (scenes/taylor-copper-190-3d-quarter.toml) against the full bar,
// node for node, through the step at which a node of the full bar first crosses one of the quarter's
// symmetry planes (step 407 of about 990: in the full bar two mirror nodes of the face pass each
// other). Until a symmetry plane stopped being a wall for the penetration guard, the quarter put
// that node back in front of the plane and differed from the full bar by 30 m/s from there on; the
// shorter runs of tests/test_symmetry.cpp see no node cross.
TEST(ThreeD, AQuarterOfTheCopperBarIsTheFullBarThroughANodeCrossingASymmetryPlane) {
    const std::filesystem::path dir = std::filesystem::path(GPA_SOURCE_DIR) / "scenes";
    // The cubic lattice of cells whose centres lie inside (CellFill::Centres) and the hourglass
    // damping on the lattice regime alone: with them two mirror nodes of the face pass each other at
    // step 407; with either the trimmed fill or the damping on every node (the 3D defaults) no node
    // crosses within 420 steps (the damping keeps the face's nodes from pairing up across the
    // planes). The guard's rule depends on neither.
    Scene quarter_scene = io::load_scene(dir / "taylor-copper-190-3d-quarter.toml");
    Scene full_scene = io::load_scene(dir / "taylor-copper-190-3d.toml");
    for (Scene* s : {&quarter_scene, &full_scene}) {
        s->bodies[0].fill = CellFill::Centres;
        s->solver.hourglass_nodes = HourglassNodes::Lattice;
    }
    Simulation quarter(quarter_scene, 2);
    Simulation full(full_scene, 2);
    using Key = std::array<long long, 3>;
    const auto key = [](const NodeStore& n, std::size_t i) {
        return Key{std::llround(n.initial_position[0][i] * 1e8), std::llround(n.initial_position[1][i] * 1e8),
                   std::llround(n.initial_position[2][i] * 1e8)};
    };
    int first_crossing = 0;
    for (int step = 1; step <= 420; ++step) {
        quarter.step();
        full.step();
        const NodeStore& n = full.nodes();
        for (std::size_t i = 0; i < full.real_count() && first_crossing == 0; ++i) {
            for (int c = 0; c < 2; ++c) {
                if (n.position[c][i] * n.initial_position[c][i] < 0.0) first_crossing = step;
            }
        }
    }
    std::printf("[ measured ] a node of the full bar first crosses a symmetry plane of the quarter at step %d\n", first_crossing);
    ASSERT_GT(first_crossing, 0) << "the run must cover a node crossing a plane";
    std::map<Key, std::size_t> index;
    for (std::size_t i = 0; i < full.real_count(); ++i) index[key(full.nodes(), i)] = i;
    double velocity = 0.0;
    for (std::size_t i = 0; i < quarter.real_count(); ++i) {
        const std::size_t j = index.at(key(quarter.nodes(), i));
        for (int c = 0; c < 3; ++c) velocity = std::max(velocity, std::abs(quarter.nodes().velocity[c][i] - full.nodes().velocity[c][j]));
    }
    std::printf("[ measured ] largest velocity difference after 420 steps: %.3g m/s\n", velocity);
    // Round-off: 1e-11 m/s measured at rest (about 990 steps); the guard's push gave 30 m/s.
    EXPECT_LT(velocity, 1e-6);
    EXPECT_NEAR(quarter.totals().footprint_diameter / full.totals().footprint_diameter, 1.0, 1e-9);
    EXPECT_NEAR(4.0 * quarter.totals().plastic_work / full.totals().plastic_work, 1.0, 1e-9);
}

}  // namespace
}  // namespace gpa
