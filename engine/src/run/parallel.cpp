#include "gpa/engine/parallel.hpp"

#include <fmt/format.h>
#include <tbb/info.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

int hardware_threads() { return tbb::info::default_concurrency(); }

namespace {
int checked_threads(int threads) {
    if (threads < 0 || threads > 4096) {
        throw InputError(fmt::format("thread count {} is out of range (0 = all hardware threads, or 1-4096)", threads));
    }
    return threads == 0 ? hardware_threads() : threads;
}
}  // namespace

ThreadScope::ThreadScope(int threads)
    : threads_(checked_threads(threads)),
      limit_(threads_ > hardware_threads()
                 ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                         static_cast<std::size_t>(threads_))
                 : nullptr),
      arena_(threads_) {}

}  // namespace gpa
