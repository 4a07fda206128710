#pragma once
// Progress of a run: on a terminal one line rewritten in place (simulated time, step, ETA,
// speed); otherwise plain log lines every few seconds.

#include <chrono>
#include <string>

#include "gpa/engine/simulation.hpp"

namespace gpa::app {

class Progress {
public:
    explicit Progress(bool quiet);
    void update(const Simulation& sim, bool force = false);
    void finish(const Simulation& sim);

private:
    std::string line(const Simulation& sim) const;
    bool quiet_, terminal_;
    std::chrono::steady_clock::time_point start_, last_;
    std::size_t width_ = 0;
};

}  // namespace gpa::app
