// gpa_impact_study: one projectile-and-target run at a chosen resolution, with what the issue-10
// studies report (docs/validation.md, scripts/impact_study.sh): crater, residual velocity,
// perforation, the spall layer near the axis, energy, steps and wall time.
//
//   gpa_impact_study SCENE --spacing MM [--projectile-spacing MM] [--speed M/S]
//                    [--connectivity variable|automatic|fixed] [--end US] [--threads N]
//
// The first body of the scene is the target, the second the projectile. --speed sets the
// projectile's speed along -z and puts it one spacing above the target.
//
// The spall layer: the target's nodes within the projectile's radius of the axis, grouped by their
// row in the initial lattice (row 0 at the rear face); the layer is the rows of the rear half where
// most nodes have failed, reported by the centre and extent of those rows.
#include <chrono>
#include <sys/resource.h>
#include <cstdio>
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"

int main(int argc, char** argv) {
    using namespace gpa;
    CLI::App app{"one projectile-and-target run with the measurements of docs/validation.md"};
    std::string scene_file, connectivity;
    double spacing_mm = 0.0, projectile_spacing_mm = 0.0, speed = 0.0, end_us = 0.0;
    int threads = 1;
    app.add_option("scene", scene_file, "scene file")->required()->check(CLI::ExistingFile);
    app.add_option("--spacing", spacing_mm, "spacing of both bodies, mm")->required()->check(CLI::PositiveNumber);
    app.add_option("--projectile-spacing", projectile_spacing_mm, "the projectile's own spacing, mm")->check(CLI::PositiveNumber);
    app.add_option("--speed", speed, "impact speed, m/s")->check(CLI::PositiveNumber);
    app.add_option("--connectivity", connectivity, "variable, automatic or fixed")->check(CLI::IsMember({"variable", "automatic", "fixed"}));
    app.add_option("--end", end_us, "end time, us")->check(CLI::PositiveNumber);
    app.add_option("--threads", threads, "threads")->check(CLI::Range(0, 4096));
    CLI11_PARSE(app, argc, argv);
    try {
        Scene s = io::load_scene(scene_file);
        if (s.bodies.size() != 2) throw std::runtime_error("the scene must have two bodies: the target, then the projectile");
        const double spacing = spacing_mm * 1e-3;
        s.bodies[0].spacing = spacing;
        s.bodies[1].spacing = projectile_spacing_mm > 0.0 ? projectile_spacing_mm * 1e-3 : spacing;
        if (speed > 0.0) {
            s.bodies[1].velocity = {0.0, -speed, 0.0};
            s.bodies[1].origin[1] = s.bodies[0].origin[1] + s.bodies[0].length + spacing;
        }
        if (connectivity == "variable") s.solver.connectivity = ConnectivityMode::Variable;
        if (connectivity == "automatic") s.solver.connectivity = ConnectivityMode::Automatic;
        if (connectivity == "fixed") s.solver.connectivity = ConnectivityMode::Fixed;
        if (end_us > 0.0) s.stop.end_time = end_us * 1e-6;
        Simulation sim(s, threads);
        // CPU time besides wall time: on a shared machine the wall time of a 1-thread run depends on
        // what else runs; its CPU time much less.
        const auto cpu_seconds = [] {
            rusage u{};
            getrusage(RUSAGE_SELF, &u);
            return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
        };
        const double cpu_start = cpu_seconds();
        const auto start = std::chrono::steady_clock::now();
        while (!sim.finished()) sim.step();
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double cpu = cpu_seconds() - cpu_start;
        sim.measure_bodies();
        const NodeStore& n = sim.nodes();
        std::map<long, std::pair<int, int>> rows;  // initial row -> failed, all
        for (std::size_t i = 0; i < sim.real_count(); ++i) {
            if (n.body[i] != 0 || n.initial_position[0][i] > s.bodies[1].radius) continue;
            auto& r = rows[std::lround((n.initial_position[1][i] - s.bodies[0].origin[1]) / spacing - 0.5)];
            r.first += n.failed[i] != 0;
            ++r.second;
        }
        std::string picture;
        long lo = -1, hi = -1;
        const long half = static_cast<long>(rows.size()) / 2;
        for (const auto& [k, r] : rows) {
            picture += r.first == 0 ? '.' : (2 * r.first > r.second ? 'X' : 'x');
            if (k < half && 2 * r.first > r.second) {
                if (lo < 0) lo = k;
                hi = k;
            }
        }
        const Totals& t = sim.totals();
        const BodyTotals& target = t.bodies[0];
        const BodyTotals& projectile = t.bodies[1];
        std::printf("scene %s spacing_mm %.4g projectile_spacing_mm %.4g speed_m_s %.1f connectivity %s threads %d\n",
                    s.name.c_str(), spacing_mm, s.bodies[1].spacing * 1e3, -s.bodies[1].velocity[1],
                    connectivity.empty() ? "(scene)" : connectivity.c_str(), sim.threads());
        std::printf("crater_depth_mm %.3f crater_diameter_mm %.3f perforated %d target_pieces %zu\n", target.crater_depth * 1e3,
                    target.crater_diameter * 1e3, target.perforated ? 1 : 0, target.pieces);
        std::printf("residual_velocity_m_s %.2f projectile_pieces %zu projectile_failed %zu of %zu\n", projectile.residual_speed_along_axis,
                    projectile.pieces, projectile.failed_nodes, projectile.nodes);
        if (lo >= 0) {
            std::printf("spall_layer_centre_mm %.2f spall_layer_thickness_mm %.2f (rows %ld-%ld above the rear face)\n",
                        0.5 * double(lo + hi + 1) * spacing * 1e3, double(hi - lo + 1) * spacing * 1e3, lo, hi);
        } else {
            std::printf("spall_layer none\n");
        }
        std::printf("rows_from_rear_face %s\n", picture.c_str());
        std::printf("failed_nodes %zu variable_nodes %zu of %zu energy_error %.2e steps %zu wall_s %.1f cpu_s %.1f node_steps_per_s %.3g\n",
                    t.failed_nodes, t.variable_nodes, t.real_nodes, t.energy_error, t.step, wall, cpu, sim.node_steps() / wall);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "gpa_impact_study: %s\n", e.what());
        return 2;
    }
    return 0;
}
