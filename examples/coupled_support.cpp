// gpa coupled to a model of its own, step by step: a steel striker hits an aluminium plate that
// rests on a support, and the support is a mass on a spring that gpa knows nothing about.
//
//   each step:  gpa  --reaction R of the support on the plate-->  support:  M a = -k u - R
//               gpa  <--velocity of the support (its displacement rate)--  support
//
// The plate's bottom rows are a prescribed-velocity region ("support") whose velocity the program
// sets between steps (Simulation::set_region_velocity); gpa reports the force the region needed,
// its displacement and the work it did on the plate (Totals::regions). The support is advanced with
// the same leapfrog and time steps as gpa's nodes, one step behind (it learns the reaction of a step
// after the step): an explicit, staggered coupling.
//
// What it checks: the energy that crossed the interface is the same seen from both sides, up to
// the lag, which is first order in the time step: run at C_cfl 0.4 and 0.2, the mismatch must fall
// by at least 1.6 (2 for a first-order error, less a margin for the changed impact), and stay below
// 2 % of the energy exchanged at the finer step. gpa's own energy balance must close as usual.
// And a coupled run stopped half-way and resumed from its checkpoint (the support's state saved
// with it through RunHooks::checkpoint_data) must end exactly where the unbroken run ends.
//
//   usage: coupled_support OUTPUT_FOLDER
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <exception>
#include <stdexcept>
#include <string>

#include "gpa/io/run_loop.hpp"

namespace {

// Plane strain: masses, forces and energies are per metre of depth.
const char* scene_text = R"(
name = "plate on a sprung support"
geometry = "plane-strain"

[[body]]
name = "plate"
shape = "rectangle"
material = "2024-T351 aluminium"
origin = ["-10 mm", 0]
size = ["20 mm", "4 mm"]
spacing = "0.5 mm"

[[body]]
name = "striker"
shape = "rectangle"
material = "4340 steel"
origin = ["-2 mm", "4.5 mm"]
size = ["4 mm", "4 mm"]
spacing = "0.5 mm"
velocity = [0, "-150 m/s"]

[[prescribed_velocity]]
name = "support"
body = "plate"
region = { below = { z = "0.5 mm" } }   # the bottom row of nodes, held along z
velocity = { z = 0 }

[stop]
end_time = "15 us"

[output]
snapshots = 4
)";

struct Support {
    double mass = 2.0;          // kg per metre of depth (the plate: 0.22)
    double stiffness = 2.0e10;  // N/m per metre: a period of 2 pi sqrt(M / k) = 63 us
    double velocity = 0.0;      // m/s, a half step ahead like gpa's nodes
    double work_received = 0.0; // the work the plate did on the support, J per metre
};

struct Outcome {
    double plate_work = 0.0;      // the work the support did on the plate (gpa's count), J/m
    double support_work = 0.0;    // the work the plate did on the support (the support's count), J/m
    double energy_error = 0.0;    // gpa's relative energy error
    std::size_t steps = 0;
};

// The support's state as bytes, for the run's checkpoints, and back.
std::string save(const Support& s) { return std::string(reinterpret_cast<const char*>(&s), sizeof s); }
Support restore(const std::string& bytes) {
    if (bytes.size() != sizeof(Support)) throw std::runtime_error("the checkpoint holds no support state");
    Support s;
    std::memcpy(&s, bytes.data(), sizeof s);
    return s;
}

// A run at C_cfl `cfl` in `folder`; with stop_at > 0 it is stopped after that step and resumed.
Outcome run(const std::string& folder, double cfl, std::size_t stop_at = 0) {
    gpa::io::SceneSource source{std::string(scene_text) + "\n[solver]\ncfl = " + std::to_string(cfl) + "\n",
                                "coupled_support's scene", "(coupled_support)", {}};
    gpa::io::RunSettings settings;
    settings.output = folder;
    settings.overwrite = true;
    std::unique_ptr<gpa::io::RunLoop> loop = std::make_unique<gpa::io::RunLoop>(source, settings);
    Support support;
    gpa::io::RunHooks hooks;
    hooks.after_step = [&](gpa::Simulation& sim) {
        const gpa::RegionReport& region = sim.totals().regions.at(0);
        const double reaction = region.reaction[1];    // z: the force the support put on the plate
        const double displacement = region.displacement[1];
        // The update gpa's nodes just made used dt_avg = (dt^{n+1/2} + dt^{n+3/2}) / 2.
        const double dt_avg = 0.5 * (sim.totals().time_step + sim.next_time_step());
        const double before = support.velocity;
        support.velocity += dt_avg * (-support.stiffness * displacement - reaction) / support.mass;
        // The plate pushes on the support with -R; its work in the leapfrog's form.
        support.work_received += dt_avg * -reaction * 0.5 * (before + support.velocity);
        sim.set_region_velocity("support", {0.0, support.velocity, 0.0});
    };
    hooks.checkpoint_data = [&] { return save(support); };
    if (stop_at > 0) {
        hooks.stop_requested = [&] {
            return loop->simulation().steps() == stop_at ? gpa::io::StopRequest{1, "coupled_support"} : gpa::io::StopRequest{};
        };
        if (loop->run(hooks).status != gpa::io::RunStatus::Interrupted) throw std::runtime_error("the run was not stopped");
        loop.reset();  // (the folder is locked while its loop exists)
        loop = gpa::io::RunLoop::resume(folder, source, settings);
        support = restore(loop->checkpoint_data());
        hooks.stop_requested = nullptr;
    }
    const gpa::io::RunResult result = loop->run(hooks);
    if (result.status != gpa::io::RunStatus::Finished) throw std::runtime_error("the run did not finish: " + result.message);
    const gpa::Totals& t = loop->simulation().totals();
    return {t.regions.at(0).work, support.work_received, t.energy_error, t.step};
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) return std::fprintf(stderr, "usage: coupled_support OUTPUT_FOLDER\n"), 2;
    try {
        const Outcome coarse = run(std::string(argv[1]) + "/cfl-0.4", 0.4);
        const Outcome fine = run(std::string(argv[1]) + "/cfl-0.2", 0.2);
        bool ok = true;
        double mismatch[2];
        for (int k = 0; k < 2; ++k) {
            const Outcome& o = k == 0 ? coarse : fine;
            mismatch[k] = std::abs(o.plate_work + o.support_work) / std::abs(o.support_work);
            std::printf("C_cfl %.1f, %zu steps: the plate gave the support %.6g J/m, the support took %.6g J/m (mismatch %.3g %%); "
                        "gpa's energy error %+.2e\n",
                        k == 0 ? 0.4 : 0.2, o.steps, -o.plate_work, o.support_work, 100.0 * mismatch[k], o.energy_error);
            ok = ok && std::abs(o.energy_error) < 1e-3 && o.support_work > 0.0;
        }
        std::printf("mismatch falls by %.2f when the time step is halved\n", mismatch[0] / mismatch[1]);
        ok = ok && mismatch[0] >= 1.6 * mismatch[1] && mismatch[1] < 0.02;
        const Outcome resumed = run(std::string(argv[1]) + "/cfl-0.4-resumed", 0.4, 200);
        const bool same = resumed.steps == coarse.steps && resumed.plate_work == coarse.plate_work &&
                          resumed.support_work == coarse.support_work && resumed.energy_error == coarse.energy_error;
        std::printf("stopped after step 200 and resumed: %s the unbroken run (%.17g J/m)\n", same ? "the same as" : "NOT the same as",
                    resumed.support_work);
        if (!same) {
            std::printf("  unbroken: %zu steps, %.17g, %.17g, %.17g\n  resumed:  %zu steps, %.17g, %.17g, %.17g\n", coarse.steps, coarse.plate_work,
                        coarse.support_work, coarse.energy_error, resumed.steps, resumed.plate_work, resumed.support_work, resumed.energy_error);
        }
        ok = ok && same;
        std::printf("%s\n", ok ? "ok" : "FAILED");
        return ok ? 0 : 1;
    } catch (const std::exception& e) {
        return std::fprintf(stderr, "coupled_support: %s\n", e.what()), 2;
    }
}
