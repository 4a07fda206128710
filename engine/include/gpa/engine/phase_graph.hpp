#pragma once
// The phases of one time step as a oneTBB flow graph, built once from the phases a scene needs
// and fired every step. Each phase's body calls a parallel driver; the graph keeps their order
// and the wall time each one takes.

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace gpa {

struct PhaseTime {
    std::string name;
    double seconds = 0.0;  // accumulated wall time
    std::size_t calls = 0;
};

class PhaseGraph {
public:
    PhaseGraph();
    ~PhaseGraph();
    PhaseGraph(const PhaseGraph&) = delete;
    PhaseGraph& operator=(const PhaseGraph&) = delete;

    // Appends a phase that runs after the previous one. Call before the first run().
    void add(std::string name, std::function<void()> body);
    // Runs every phase once, in order; rethrows the first exception a phase throws.
    void run();
    // The name of the phase whose exception the last run() rethrew; empty if it threw none.
    std::string failed_phase() const;
    std::vector<PhaseTime> times() const;
    // Sets the accumulated times of the phases named in `times` (a resumed run carries on the
    // wall times of the run it continues).
    void restore_times(const std::vector<PhaseTime>& times);
    std::vector<std::string> names() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace gpa
