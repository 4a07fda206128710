#include "gpa/engine/phase_graph.hpp"

#include <exception>
#include <stdexcept>

#include <tbb/flow_graph.h>

namespace gpa {

// The step's phases are a chain of continue_nodes (each phase depends on the one before):
//   move -> [reorder] -> geometry (and ghosts) -> neighbours -> gradient -> stress -> plan
//     -> time step -> forces -> integrate -> [smoothing] -> [switching] -> totals
// (bracketed phases only when the scene needs them; see Simulation::Impl::build_phase_graph).
struct PhaseGraph::Impl {
    tbb::flow::graph graph;
    tbb::flow::broadcast_node<tbb::flow::continue_msg> start{graph};
    std::vector<std::unique_ptr<tbb::flow::continue_node<tbb::flow::continue_msg>>> nodes;
    std::vector<PhaseTime> times;
    std::vector<std::function<void()>> bodies;
    std::exception_ptr failure;
    std::size_t failed_phase = 0;  // the phase that threw `failure`
};

PhaseGraph::PhaseGraph() : impl_(std::make_unique<Impl>()) {}
PhaseGraph::~PhaseGraph() = default;

void PhaseGraph::add(std::string name, std::function<void()> body) {
    auto& im = *impl_;
    const std::size_t k = im.bodies.size();
    im.bodies.push_back(std::move(body));
    im.times.push_back({std::move(name), 0.0, 0});
    im.nodes.push_back(std::make_unique<tbb::flow::continue_node<tbb::flow::continue_msg>>(
        im.graph, [&im, k](const tbb::flow::continue_msg&) {
            if (im.failure) return tbb::flow::continue_msg{};  // an earlier phase failed: skip the rest
            const auto t0 = std::chrono::steady_clock::now();
            try {
                im.bodies[k]();
            } catch (...) {
                im.failure = std::current_exception();
                im.failed_phase = k;
            }
            im.times[k].seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            ++im.times[k].calls;
            return tbb::flow::continue_msg{};
        }));
    if (k == 0) {
        tbb::flow::make_edge(im.start, *im.nodes[0]);
    } else {
        tbb::flow::make_edge(*im.nodes[k - 1], *im.nodes[k]);
    }
}

void PhaseGraph::run() {
    auto& im = *impl_;
    if (im.nodes.empty()) return;
    im.failure = nullptr;
    im.start.try_put(tbb::flow::continue_msg{});
    im.graph.wait_for_all();
    if (im.failure) std::rethrow_exception(im.failure);
}

std::vector<PhaseTime> PhaseGraph::times() const { return impl_->times; }

std::string PhaseGraph::failed_phase() const {
    return impl_->failure ? impl_->times[impl_->failed_phase].name : std::string();
}

void PhaseGraph::restore_times(const std::vector<PhaseTime>& times) {
    for (auto& mine : impl_->times) {
        for (const auto& t : times) {
            if (t.name == mine.name) mine = t;
        }
    }
}

std::vector<std::string> PhaseGraph::names() const {
    std::vector<std::string> out;
    for (const auto& t : impl_->times) out.push_back(t.name);
    return out;
}

}  // namespace gpa
