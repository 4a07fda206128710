// Whole runs of the engine: energy and momentum balances, an elastic bar against a rigid plane,
// and thread independence.

#include <cmath>
#include <cstring>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

TEST(ElasticBar, ContactTimeAndReboundSpeed) {
    const double radius = 1e-3, length = 20e-3, speed = 10.0;
    auto scene = testing::elastic_bar_on_plane(radius, length, 5, speed);
    Simulation sim(scene, 2);
    const double c = std::sqrt(200e9 / 7800.0);
    double last_contact = 0.0;
    double mass = 0.0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) mass += sim.nodes().mass[i];
    while (!sim.finished()) {
        sim.step();
        if (sim.totals().planes.at(0).reaction != 0.0) last_contact = sim.time();
    }
    const double rebound = sim.totals().momentum[1] / mass;
    std::printf("[ measured ] contact %.4g us (2L/c %.4g us), rebound %.4g m/s, energy error %.3g, %zu steps\n",
                last_contact * 1e6, 2 * length / c * 1e6, rebound, sim.totals().energy_error, sim.steps());
}

}  // namespace
}  // namespace gpa
