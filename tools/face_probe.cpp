// Diagnostic (issue 13): runs a scene with variant settings and prints the local fields near the
// impact face: per lattice row (rows 1-3) the plastic strain of each node ordered by radius, the
// raw peak and where it is, the number of nodes whose alpha hit the limit. Elements: the triangles
// touching the face.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"

using namespace gpa;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "face_probe SCENE [refine] [variant-spec] [nodes.csv]\n");
        return 2;
    }
    Scene scene = io::load_scene(argv[1]);
    const double factor = argc > 2 ? std::stod(argv[2]) : 1.0;
    if (argc > 3) io::apply_variant(io::parse_variant(argv[3]), scene);
    scene = io::refined(scene, factor);
    Simulation sim(scene, 1);
    // With a fourth argument: every node's initial and final position (and, for particles, its
    // section and plastic strain) to that CSV file, to compare displacement fields.
    std::array<std::vector<double>, 2> element_start;
    if (const ElementPart* e = sim.elements()) element_start = e->mesh().nodes.position;
    while (!sim.finished()) sim.step();
    if (argc > 4) {
        std::FILE* out = std::fopen(argv[4], "w");
        if (!out) { std::fprintf(stderr, "cannot write %s\n", argv[4]); return 1; }
        std::fprintf(out, "x0,z0,x,z,section,plastic_strain\n");
        if (const ElementPart* e = sim.elements()) {
            const auto& p = e->mesh().nodes.position;
            for (std::size_t i = 0; i < p[0].size(); ++i)
                std::fprintf(out, "%.9e,%.9e,%.9e,%.9e,0,0\n", element_start[0][i], element_start[1][i], p[0][i], p[1][i]);
        } else {
            const auto& n = sim.nodes();
            for (std::size_t i = 0; i < sim.real_count(); ++i)
                std::fprintf(out, "%.9e,%.9e,%.9e,%.9e,%.9e,%.6f\n", n.initial_position[0][i], n.initial_position[1][i],
                             n.position[0][i], n.position[1][i], n.size_weight[i], n.plastic_strain[i]);
        }
        std::fclose(out);
    }
    sim.measure_bodies();
    const auto& t = sim.totals();
    fmt::print("local: peak strain {:.4f} at ({:.3f}, {:.3f}) mm, max {:.4f}; peak T {:.1f} K; face roughness {:.4f} over {} points\n",
               t.local.plastic_strain.value, t.local.plastic_strain.position[0] * 1e3, t.local.plastic_strain.position[1] * 1e3,
               t.local.plastic_strain.raw, t.local.temperature.value, t.local.face_roughness, t.local.face_points);
    fmt::print("steps {} time {:.3f} us L {:.4f} mm D {:.4f} mm PW {:.3f} J\n", sim.steps(), sim.time() * 1e6,
               t.length * 1e3, t.footprint_diameter * 1e3, t.plastic_work);
    if (const ElementPart* e = sim.elements()) {
        const auto& m = e->mesh();
        double peak = 0;
        std::size_t at = 0;
        for (std::size_t k = 0; k < m.points.size(); ++k) {
            if (m.points.plastic_strain[k] > peak) { peak = m.points.plastic_strain[k]; at = k; }
        }
        const auto& q = m.quads.nodes[at / 4];
        double cx = 0, cz = 0;
        for (int c = 0; c < 5; ++c) { cx += m.nodes.position[0][q[c]] / 5; cz += m.nodes.position[1][q[c]] / 5; }
        fmt::print("element peak eps_p {:.3f} at ({:.3f}, {:.3f}) mm\n", peak, cx * 1e3, cz * 1e3);
        // first row of quads: mean eps_p per quad along x
        std::vector<std::pair<double, double>> row;
        for (std::size_t qi = 0; qi < m.quads.size(); ++qi) {
            const auto& qq = m.quads.nodes[qi];
            double zmin = 1e9, xm = 0;
            for (int c = 0; c < 4; ++c) { zmin = std::min(zmin, m.nodes.position[1][qq[c]]); xm += m.nodes.position[0][qq[c]] / 4; }
            if (zmin < 1e-9) {
                double ep = 0;
                for (int k = 0; k < 4; ++k) ep += m.points.plastic_strain[4 * qi + k] / 4;
                row.push_back({xm, ep});
            }
        }
        std::sort(row.begin(), row.end());
        fmt::print("face quads:");
        for (auto& [x, ep] : row) fmt::print(" {:.2f}@{:.2f}", ep, x * 1e3);
        fmt::print("\n");
        return 0;
    }
    const auto& n = sim.nodes();
    const std::size_t N = sim.real_count();
    double peak = 0, peakT = 0;
    std::size_t at = 0;
    for (std::size_t i = 0; i < N; ++i) {
        if (n.plastic_strain[i] > peak) { peak = n.plastic_strain[i]; at = i; }
        peakT = std::max(peakT, n.temperature[i]);
    }
    fmt::print("peak eps_p {:.3f} at ({:.3f}, {:.3f}) mm, peak T {:.0f} K\n", peak, n.position[0][at] * 1e3,
               n.position[1][at] * 1e3, peakT);
    std::map<long, std::vector<std::size_t>> rows;
    const double dz = scene.bodies[0].spacing;
    for (std::size_t i = 0; i < N; ++i) rows[std::lround(n.initial_position[1][i] / dz - 0.5)].push_back(i);
    int shown = 0;
    double jumps = 0; int njumps = 0;
    for (auto& [k, ids] : rows) {
        if (shown++ >= 3) break;
        std::sort(ids.begin(), ids.end(), [&](auto a, auto b) { return n.position[0][a] < n.position[0][b]; });
        fmt::print("row {}:", k);
        for (std::size_t m = 0; m < ids.size(); ++m) {
            const auto i = ids[m];
            fmt::print(" {:.2f}", n.plastic_strain[i]);
            if (m > 0 && m + 1 < ids.size()) {
                jumps += std::abs(n.plastic_strain[i] - 0.5 * (n.plastic_strain[ids[m - 1]] + n.plastic_strain[ids[m + 1]]));
                ++njumps;
            }
        }
        fmt::print("\n   x:");
        for (auto i : ids) fmt::print(" {:.2f}", n.position[0][i] * 1e3);
        fmt::print("\n   z:");
        for (auto i : ids) fmt::print(" {:.3f}", n.position[1][i] * 1e3);
        fmt::print("\n   d:");
        for (auto i : ids) fmt::print(" {:.3f}", n.diameter[i] * 1e3);
        fmt::print("\n");
    }
    std::size_t clamped = 0;
    for (std::size_t i = 0; i < N; ++i) {
        for (int b = 0; b < 2; ++b) {
            if (scene.solver.alpha_limit > 0 && n.alpha[b][i] * n.size_weight[i] >= scene.solver.alpha_limit * (1 - 1e-12)) { ++clamped; break; }
        }
    }
    fmt::print("rows 1-3 detrended roughness {:.3f}; alpha-clamped nodes {}\n", jumps / std::max(njumps, 1), clamped);
    return 0;
}
