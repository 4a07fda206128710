// 3D against 2D at matched spacing (issue 23; docs/validation.md, "3D: the impact face and the
// node diameter"): the 4340 steel bar at 343 m/s, 10 nodes across its radius in both geometries,
// run to rest on 2 threads. Long: labelled "slow".

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"

namespace gpa {
namespace {

struct Shape {
    double length = 0.0, footprint = 0.0, narrowest = 0.0, widest = 0.0, peak = 0.0;
};

// The scene at 10 nodes across the radius, the peaks averaged over the same radius in both
// geometries (two spacings).
Shape run(const std::string& file, double refine) {
    Scene s = io::refined(io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/" + file), refine);
    s.output.peak_radius = 2.0 * s.bodies[0].spacing;
    Simulation sim(s, 2);
    while (!sim.finished()) sim.step();
    sim.measure_bodies();
    const auto& t = sim.totals();
    const Shape out{t.length, t.footprint_diameter, t.footprint_narrowest, t.footprint_widest, t.local.plastic_strain.value};
    std::printf("[ measured ] %s: L %.4f mm, D %.4f mm (%.4f-%.4f), peak plastic strain %.4f, %zu nodes\n", file.c_str(),
                out.length * 1e3, out.footprint * 1e3, out.narrowest * 1e3, out.widest * 1e3, out.peak, sim.real_count());
    return out;
}

// The bounds for 3D against 2D at matched spacing: length within 1 %, footprint within 2 %,
// peak plastic strain within 10 %. Measured (docs/validation.md): length +0.14 %, footprint +1.2 %
// (the volume rule of 3D node diameters: +3.6 %), peak -1.2 %. This bar spreads least of the
// Taylor bars; copper 190 and steel 208 are still 4-5 % wide of 2D, which this test does not claim.
TEST(ThreeD, TheSteelBarAt343MetresPerSecondAgreesWithTwoDAtMatchedSpacing) {
    // scenes/taylor-steel-343.toml has 15 nodes across the radius, its 3D version 8: both to 10.
    // The scenes' own solver: the node diameter follows the stretch (the default).
    const Shape plane = run("taylor-steel-343.toml", 10.0 / 15.0);
    const Shape solid = run("taylor-steel-343-3d.toml", 10.0 / 8.0);
    EXPECT_NEAR(solid.length / plane.length, 1.0, 0.01);
    EXPECT_NEAR(solid.footprint / plane.footprint, 1.0, 0.02);
    EXPECT_NEAR(solid.peak / plane.peak, 1.0, 0.10);
    // The face is round: its widest and narrowest widths within 5 % (measured 3.4 %; a face split
    // into spokes along the lattice's rows is wider across its diagonals).
    EXPECT_LT(solid.widest / solid.narrowest, 1.05);
}

}  // namespace
}  // namespace gpa
