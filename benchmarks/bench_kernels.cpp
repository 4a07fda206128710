// Throughput of the engine core phases: neighbour search, gradient gather and force scatter,
// on 2D axisymmetric (fixed and variable connectivity) and 3D lattices of 10^5 and 10^6 nodes,
// on 1 and 2 threads, for each scatter scheme; and the material point update (point/NAME: one
// thread, 10^4 points of a library material in plastic flow). Counters:
//   node_updates_per_s  nodes processed per second by the timed phase
//   neighbours          mean neighbour-list length per node
//
// Usage: gpa_bench_kernels [--quick] [google-benchmark flags]
//   --quick  only 10^5 nodes and a short minimum time (what CI prints)

#include <cstring>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/materials/material.hpp"

namespace {

using namespace gpa;

struct Problem {
    GeometryKind geometry;
    Connectivity connectivity;
    std::size_t target_nodes;

    std::string name() const {
        return fmt::format("{}/{}/n:{}", geometry == GeometryKind::ThreeD ? "3D" : "axisym",
                           connectivity == Connectivity::Fixed ? "fixed" : "variable", target_nodes);
    }
};

struct Prepared {
    NodeStore nodes;
    CompressedRows lists;
    double neighbours_per_node = 0.0;
};

PositionView view(const NodeStore& n) {
    PositionView v;
    v.dim = n.dim();
    for (int c = 0; c < n.dim(); ++c) v.component[c] = n.position[c].data();
    return v;
}

// A square (cube) lattice of about target_nodes nodes, jittered by 10 % of a spacing, in
// random stress and velocity states; fixed lists use 8 (2D) or 26 (3D) neighbours.
Prepared& prepared(const Problem& p) {
    static std::map<std::string, std::unique_ptr<Prepared>> cache;
    auto& slot = cache[p.name()];
    if (slot) return *slot;
    slot = std::make_unique<Prepared>(Prepared{NodeStore(p.geometry), {}, 0.0});
    auto& n = slot->nodes;
    const bool three = p.geometry == GeometryKind::ThreeD;
    const auto side = static_cast<std::int64_t>(std::llround(std::pow(double(p.target_nodes), three ? 1.0 / 3.0 : 0.5)));
    const double dx = 1e-4;
    LatticeBlock b;
    b.spacing = {dx, dx, dx};
    b.last = {side, side, three ? side : 1};
    b.density = 7850.0;
    b.connectivity = p.connectivity;
    b.lattice_neighbours = three ? 26 : 8;
    fill_lattice(n, b);
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (int c = 0; c < n.dim(); ++c) {
            n.position[c][i] += 0.1 * dx * u(rng);
            n.velocity[c][i] = 100.0 * u(rng);
        }
        for (int c = 0; c < stress_components(n.dim()); ++c) n.deviatoric_stress[c][i] = 1e8 * u(rng);
        n.pressure[i] = 1e9 * u(rng);
        n.sound_speed[i] = 5000.0;
    }
    update_size_weights(n, 0, n.size());
    n.permute(locality_order(n, 2.0 * dx, 0, n.size()));
    slot->lists = find_neighbours(n, 1.0, n.size());
    slot->neighbours_per_node = double(slot->lists.entries()) / double(n.size());
    return *slot;
}

void set_counters(benchmark::State& state, const Prepared& p) {
    state.counters["node_updates_per_s"] =
        benchmark::Counter(double(p.nodes.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["neighbours"] = p.neighbours_per_node;
    state.counters["nodes"] = double(p.nodes.size());
}

void search(benchmark::State& state, Problem problem, int threads) {
    auto& p = prepared(problem);
    ThreadScope scope(threads);
    CompressedRows out;
    NeighbourScratch scratch;
    for (auto _ : state) {
        scope.run([&] { find_neighbours(p.nodes, 1.0, p.nodes.size(), out, scratch); });
        benchmark::DoNotOptimize(out.indices.data());
    }
    set_counters(state, p);
}

void gradient(benchmark::State& state, Problem problem, int threads) {
    auto& p = prepared(problem);
    ThreadScope scope(threads);
    dispatch_geometry(problem.geometry, [&](auto tag) {
        using G = decltype(tag);
        const auto fields = gradient_fields<G::dim>(p.nodes, 1.0);
        for (auto _ : state) {
            scope.run([&] { compute_velocity_gradient<G>(p.lists, WeightKind::Gpa, fields); });
        }
    });
    set_counters(state, p);
}

void forces(benchmark::State& state, Problem problem, int threads, ScatterScheme scheme) {
    auto& p = prepared(problem);
    ThreadScope scope(threads);
    dispatch_geometry(problem.geometry, [&](auto tag) {
        using G = decltype(tag);
        scope.run([&] { compute_velocity_gradient<G>(p.lists, WeightKind::Gpa, gradient_fields<G::dim>(p.nodes, 1.0)); });
        const auto fields = force_fields<G::dim>(p.nodes, 1.0);
        const ScatterPlan plan = scope.run([&] { return make_plan(scheme, p.lists, view(p.nodes), p.nodes.size()); });
        state.counters["colours"] = double(plan.colours());
        state.counters["groups"] = double(plan.groups());
        for (auto _ : state) {
            scope.run([&] { compute_forces<G>(p.lists, plan, WeightKind::Gpa, nullptr, fields, p.nodes.size()); });
        }
    });
    set_counters(state, p);
}

// Building a scatter plan: slabs and cells depend on positions (rebuilt as nodes move), a graph
// colouring only on the lists (built once for fixed connectivity).
void plan(benchmark::State& state, Problem problem, int threads, ScatterScheme scheme) {
    auto& p = prepared(problem);
    ThreadScope scope(threads);
    for (auto _ : state) {
        auto built = scope.run([&] { return make_plan(scheme, p.lists, view(p.nodes), p.nodes.size()); });
        benchmark::DoNotOptimize(built.centres.data());
    }
    set_counters(state, p);
}

// The material point update (materials/src/point_update.cpp) on 10^4 points of one material,
// as a Taylor impact drives them: a compression along one axis at 10^3-10^5 1/s with a random
// shear, 20 ns steps, plastic strains 0-1.5 already reached and a temperature that grows with
// them. A quarter of the points, unloaded to half their flow stress and strained at 10 1/s, stay
// elastic (the README main job's returns are three quarters of its point updates). Each point is
// first driven onto its yield surface (40 steps that strain it by 2e-4 each, then 3 of 20 ns);
// every iteration then updates all points from that kept state (the copy of the 10^4 states is
// timed too).
struct PointProblem {
    std::vector<materials::PointState> states;
    std::vector<materials::PointIncrement> increments;
};

PointProblem point_problem(const materials::Material& m) {
    constexpr std::size_t count = 10000;
    const materials::PointModel model(m);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    PointProblem p;
    for (std::size_t k = 0; k < count; ++k) {
        const bool elastic = k % 4 == 3;
        const double rate = std::pow(10.0, 3.0 + 2.0 * u(rng));
        materials::PointIncrement inc;
        Eigen::Matrix3d l = Eigen::Matrix3d::Zero();
        l(0, 0) = 0.5 * rate;
        l(1, 1) = -1.02 * rate;  // 2 % of the rate compresses the volume
        l(2, 2) = 0.5 * rate;
        l(0, 1) = 0.3 * rate * (2.0 * u(rng) - 1.0);
        l(1, 0) = 0.3 * rate * (2.0 * u(rng) - 1.0);
        inc.velocity_gradient = l;
        inc.dt = 20e-9;
        inc.density_old = m.density;
        inc.density_new = m.density / (1.0 + l.trace() * inc.dt);
        inc.energy_booked_by_caller = true;
        materials::PointState s;
        s.plastic_strain = 1.5 * u(rng);
        s.temperature = 294.0 + 300.0 * s.plastic_strain;
        materials::PointIncrement loading = inc;
        loading.dt = 2e-4 / rate;
        loading.density_new = m.density / (1.0 + l.trace() * loading.dt);
        for (int warm = 0; warm < 43; ++warm) {
            const auto r = model.update(s, warm < 40 ? loading : inc);
            if (r.fault != materials::PointFault::none) throw std::runtime_error("point benchmark: a warm-up step failed");
        }
        if (elastic) {
            for (double& c : s.deviatoric_stress) c *= 0.5;  // unloaded to half its flow stress
            inc.velocity_gradient *= 10.0 / rate;             // and strained at 10 1/s
            inc.density_new = m.density / (1.0 + inc.velocity_gradient.trace() * inc.dt);
        }
        p.states.push_back(s);
        p.increments.push_back(inc);
    }
    return p;
}

void point_update(benchmark::State& state, std::string material) {
    const materials::Material& m = io::builtin_material(material);
    const PointProblem p = point_problem(m);
    const materials::PointModel model(m);
    std::vector<materials::PointState> work = p.states;
    std::size_t returns = 0, evaluations = 0;
    for (auto _ : state) {
        work = p.states;
        returns = evaluations = 0;
        for (std::size_t k = 0; k < work.size(); ++k) {
            const auto r = model.update(work[k], p.increments[k]);
            returns += r.return_iterations > 0;
            evaluations += static_cast<std::size_t>(r.return_iterations);
        }
        benchmark::DoNotOptimize(work.data());
    }
    state.counters["point_updates_per_s"] =
        benchmark::Counter(double(work.size()) * double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["plastic_fraction"] = double(returns) / double(work.size());
    state.counters["evaluations_per_return"] = returns ? double(evaluations) / double(returns) : 0.0;
}

}  // namespace

int main(int argc, char** argv) {
    bool quick = false;
    std::vector<char*> args;
    for (int k = 0; k < argc; ++k) {
        if (std::strcmp(argv[k], "--quick") == 0) {
            quick = true;
        } else {
            args.push_back(argv[k]);
        }
    }
    static std::string min_time = "--benchmark_min_time=0.2";
    if (quick) args.push_back(min_time.data());
    int count = static_cast<int>(args.size());

    std::vector<std::size_t> sizes{100000};
    if (!quick) sizes.push_back(1000000);
    for (std::size_t n : sizes) {
        for (auto geometry : {GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
            for (auto connectivity : {Connectivity::Fixed, Connectivity::Variable}) {
                const Problem p{geometry, connectivity, n};
                for (int threads : {1, 2}) {
                    const auto suffix = fmt::format("{}/threads:{}", p.name(), threads);
                    if (connectivity == Connectivity::Variable) {
                        benchmark::RegisterBenchmark(("search/" + suffix).c_str(), search, p, threads)->UseRealTime()->Unit(benchmark::kMillisecond);
                    }
                    benchmark::RegisterBenchmark(("gradient/" + suffix).c_str(), gradient, p, threads)->UseRealTime()->Unit(benchmark::kMillisecond);
                    for (auto scheme : {ScatterScheme::Slabs, ScatterScheme::Cells, ScatterScheme::Graph}) {
                        const auto tail = fmt::format("{}/{}", name_of(scheme), suffix);
                        benchmark::RegisterBenchmark(("forces/" + tail).c_str(), forces, p, threads, scheme)
                            ->UseRealTime()
                            ->Unit(benchmark::kMillisecond);
                        if (threads == 1 && !quick) {
                            benchmark::RegisterBenchmark(("plan/" + tail).c_str(), plan, p, threads, scheme)
                                ->UseRealTime()
                                ->Unit(benchmark::kMillisecond);
                        }
                    }
                }
            }
        }
    }
    for (const char* material : {"Armco iron", "OFHC copper", "4340 steel"}) {
        benchmark::RegisterBenchmark(fmt::format("point/{}", material).c_str(), point_update, std::string(material))
            ->Unit(benchmark::kMicrosecond);
    }
    benchmark::Initialize(&count, args.data());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
