#include "progress.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

namespace gpa::app {

Progress::Progress(bool quiet)
    : quiet_(quiet), terminal_(::isatty(::fileno(stderr)) != 0), start_(std::chrono::steady_clock::now()), last_(start_) {}

namespace {

std::string clock_time(double seconds) {
    if (!std::isfinite(seconds) || seconds < 0.0) return "?";
    const auto s = static_cast<long>(std::lround(seconds));
    return s >= 3600 ? fmt::format("{}:{:02d}:{:02d}", s / 3600, (s / 60) % 60, s % 60) : fmt::format("{}:{:02d}", s / 60, s % 60);
}

}  // namespace

std::string Progress::line(const Simulation& sim) const {
    const auto& t = sim.totals();
    const auto& stop = sim.scene().stop;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    // Fraction done: simulated time against the end time, or the fall of the kinetic energy
    // towards its stopping value (on a log scale), whichever is further.
    double done = 0.0;
    if (stop.end_time > 0.0) done = t.time / stop.end_time;
    if (stop.kinetic_energy_fraction > 0.0 && t.initial_kinetic_energy > 0.0 && t.kinetic_energy > 0.0) {
        const double fall = std::log(t.initial_kinetic_energy / t.kinetic_energy) / std::log(1.0 / stop.kinetic_energy_fraction);
        done = std::max(done, std::clamp(fall, 0.0, 1.0));
    }
    if (stop.max_steps > 0) done = std::max(done, double(t.step) / double(stop.max_steps));
    const double eta = done > 0.0 ? wall * (1.0 - done) / done : NAN;
    const double speed = wall > 0.0 ? sim.node_steps() / wall : 0.0;
    const double ke = t.initial_kinetic_energy > 0.0 ? 100.0 * t.kinetic_energy / t.initial_kinetic_energy : 0.0;
    return fmt::format("t {:.4g} us{} | step {} | dt {:.3g} ns | KE {:.1f} % | energy error {:+.2g} % | {:.2f} M node-steps/s | ETA {}",
                       t.time * 1e6, stop.end_time > 0.0 ? fmt::format(" / {:.4g} us", stop.end_time * 1e6) : "", t.step,
                       t.time_step * 1e9, ke, 100.0 * t.energy_error, speed / 1e6, clock_time(eta));
}

void Progress::update(const Simulation& sim, bool force) {
    if (quiet_) return;
    const auto now = std::chrono::steady_clock::now();
    const double since = std::chrono::duration<double>(now - last_).count();
    if (!force && since < (terminal_ ? 0.2 : 5.0)) return;
    last_ = now;
    const std::string text = line(sim);
    if (terminal_) {
        std::fprintf(stderr, "\r%s%s", text.c_str(), std::string(width_ > text.size() ? width_ - text.size() : 0, ' ').c_str());
        std::fflush(stderr);
        width_ = text.size();
    } else {
        spdlog::info("{}", text);
    }
}

void Progress::finish(const Simulation& sim) {
    update(sim, true);
    if (!quiet_ && terminal_) std::fputc('\n', stderr);
}

}  // namespace gpa::app
