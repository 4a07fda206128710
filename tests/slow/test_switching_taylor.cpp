// Automatic switching against all-variable connectivity on the Taylor scenes and the paper's
// Armco cylinder (issue: "the switched run's final length and footprint are within 1 % of the
// all-variable run's at the same resolution, and the difference at the finest is no larger than
// at the coarsest plus 0.2 %"). Each scene at 10, 15 and 20 nodes across the radius, run to the
// scene's own stop criterion. Long: labelled "slow".

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa {
namespace {

struct Shape {
    double length = 0.0, footprint = 0.0, plastic_work = 0.0, variable_fraction = 0.0;
};

Shape run(const std::string& scene_name, double spacing, ConnectivityMode mode) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/" + scene_name + ".toml");
    for (auto& b : s.bodies) {
        b.spacing = spacing;
        b.connectivity.reset();
    }
    s.solver.connectivity = mode;
    Simulation sim(s, 1);
    while (!sim.finished()) sim.step();
    const auto& t = sim.totals();
    return {t.length, t.footprint_diameter, t.plastic_work, static_cast<double>(t.variable_nodes) / static_cast<double>(t.real_nodes)};
}

void compare(const std::string& scene_name, double radius) {
    double first_length = 0.0, first_footprint = 0.0, last_length = 0.0, last_footprint = 0.0;
    for (int across : {10, 15, 20}) {
        const double spacing = radius / across;
        const Shape variable = run(scene_name, spacing, ConnectivityMode::Variable);
        const Shape automatic = run(scene_name, spacing, ConnectivityMode::Automatic);
        const double dl = automatic.length / variable.length - 1.0;
        const double dd = automatic.footprint / variable.footprint - 1.0;
        std::printf("[ measured ] %s, %d across: L %.4f / %.4f mm (%+.2f %%), D %.4f / %.4f mm (%+.2f %%), PW %.2f / %.2f J, "
                    "%.0f %% switched\n",
                    scene_name.c_str(), across, automatic.length * 1e3, variable.length * 1e3, 100 * dl, automatic.footprint * 1e3,
                    variable.footprint * 1e3, 100 * dd, automatic.plastic_work, variable.plastic_work, 100 * automatic.variable_fraction);
        // 1 %: the bound. Both runs share the lattice, the material and the stop rule, so
        // what remains is the method's own difference between the two connectivities.
        EXPECT_LT(std::abs(dl), 0.01) << scene_name << " length at " << across << " across";
        EXPECT_LT(std::abs(dd), 0.01) << scene_name << " footprint at " << across << " across";
        EXPECT_GT(automatic.variable_fraction, 0.05) << "nodes must switch for the comparison to mean anything";
        EXPECT_LT(automatic.variable_fraction, 0.95) << "nodes must stay fixed for the comparison to mean anything";
        if (across == 10) {
            first_length = dl;
            first_footprint = dd;
        }
        last_length = dl;
        last_footprint = dd;
    }
    // The difference does not grow with refinement (the issue: at most the coarsest's plus 0.2 %).
    EXPECT_LE(std::abs(last_length), std::abs(first_length) + 0.002) << scene_name;
    EXPECT_LE(std::abs(last_footprint), std::abs(first_footprint) + 0.002) << scene_name;
}

TEST(SwitchingAgainstVariable, OfhcCopper190) { compare("taylor-copper-190", 3.81e-3); }
TEST(SwitchingAgainstVariable, Steel4340At208) { compare("taylor-steel-208", 3.81e-3); }
TEST(SwitchingAgainstVariable, ArmcoCylinderNodalViscosity) { compare("armco-cylinder-nodal", 5.1e-3); }

}  // namespace
}  // namespace gpa
