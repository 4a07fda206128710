#pragma once
// Running engine work on a chosen number of threads. Results never depend on that number (every
// driver is deterministic), only the speed does.

#include <memory>
#include <utility>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

namespace gpa {

class ThreadScope {
public:
    // threads = 0 uses every hardware thread. More threads than cores are allowed (tests use
    // them to show that results do not change).
    explicit ThreadScope(int threads = 0);
    int threads() const { return threads_; }

    template <class F>
    decltype(auto) run(F&& f) {
        return arena_.execute(std::forward<F>(f));
    }

private:
    int threads_;
    std::unique_ptr<tbb::global_control> limit_;
    tbb::task_arena arena_;
};

int hardware_threads();

}  // namespace gpa
