#include "step/external_loads.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

bool ExternalLoads::check_ids(const NodeStore& nodes, std::size_t real) {
    std::vector<bool> seen(real, false);
    for (std::size_t i = 0; i < real; ++i) {
        const std::uint32_t id = nodes.id[i];
        if (id >= real || seen[id]) return false;
        seen[id] = true;
    }
    return true;
}

std::size_t ExternalLoads::index_of(const NodeStore& nodes, std::size_t real, std::uint64_t id) const {
    if (id >= real) {
        throw InputError(fmt::format("node id {}: no particle node has it (the ids of this run are 0 to {}, one per particle node "
                                     "in the order the scene's bodies were filled{})",
                                     id, real == 0 ? 0 : real - 1, real == 0 ? "; this run has none" : ""));
    }
    if (!mapped_.load(std::memory_order_acquire)) {
        const std::lock_guard<std::mutex> lock(map_mutex_);
        if (!mapped_.load(std::memory_order_relaxed)) {
            // The ids are 0 ... real - 1, each once: checked at the set-up and at every restore.
            index_of_id_.assign(real, 0);
            for (std::size_t i = 0; i < real; ++i) index_of_id_[nodes.id[i]] = static_cast<std::uint32_t>(i);
            mapped_.store(true, std::memory_order_release);
        }
    }
    return index_of_id_[id];
}

void ExternalLoads::add_force(std::uint32_t id, const std::array<double, 3>& force) {
    const auto same = std::find_if(pending_.begin(), pending_.end(), [id](const Load& l) { return l.id == id; });
    if (same == pending_.end()) {
        pending_.push_back({id, force});
    } else {
        for (int c = 0; c < 3; ++c) same->force[c] += force[c];
    }
}

void ExternalLoads::add_to_forces(NodeStore& nodes, std::size_t real) {
    applied_to_.clear();
    half_step_.clear();
    const int dim = nodes.dim();
    for (const Load& load : pending_) {
        const std::size_t i = index_of(nodes, real, load.id);
        applied_to_.push_back(i);
        std::array<double, 3> v{0, 0, 0};
        for (int c = 0; c < dim; ++c) {
            v[c] = nodes.velocity[c][i];
            nodes.force[c][i] += load.force[c];
        }
        half_step_.push_back(v);
    }
}

void ExternalLoads::book(const NodeStore& nodes, double dt_avg) {
    // dW = dt_avg F . (v^{n+1/2} + v^{n+3/2}) / 2 (the header), serial in the order the loads
    // were given: the same sum on any thread count.
    const int dim = nodes.dim();
    double step_work = 0.0;
    for (std::size_t k = 0; k < applied_to_.size(); ++k) {
        const std::size_t i = applied_to_[k];
        for (int c = 0; c < dim; ++c) step_work += dt_avg * pending_[k].force[c] * 0.5 * (half_step_[k][c] + nodes.velocity[c][i]);
    }
    work_ += step_work;
    last_force_work_ = step_work;
    pending_.clear();
    applied_to_.clear();
    half_step_.clear();
}

void ExternalLoads::memory_use(MemoryUse& out) const {
    add_memory(out, "external loads: node ids", allocated_bytes(index_of_id_));
}

template <class IO, class Self, class Regions>
void ExternalLoads::state_fields(IO& io, Self& self, Regions& regions, std::size_t real) {
    io.tag("EXTL");
    std::size_t count = self.pending_.size();
    io.field(count);
    if constexpr (IO::reading) {
        constexpr std::uint64_t bytes_per_load = 4 + 3 * 8;
        if (count > io.left() / bytes_per_load || count > real) io.fail("its external loads are damaged");
        self.pending_.assign(count, {});
    }
    for (auto& l : self.pending_) {
        io.field(l.id);
        if constexpr (IO::reading) {
            if (l.id >= real) io.fail("an external load names a node the scene does not have");
        }
        for (auto& f : l.force) {
            io.field(f);
            if constexpr (IO::reading) {
                if (!std::isfinite(f)) io.fail("an external load is not finite");
            }
        }
    }
    io.field(self.work_);
    io.field(self.last_force_work_);
    io.expect(regions.size(), "its prescribed-velocity regions are not the scene's");
    for (auto& r : regions) {
        for (int c = 0; c < 3; ++c) {
            const bool scene_holds = r.velocity[c].has_value();
            bool held = scene_holds;
            double v = r.velocity[c].value_or(0.0);
            io.field(held);
            io.field(v);
            if constexpr (IO::reading) {
                if (held != scene_holds) io.fail(fmt::format("region \"{}\" holds other components than the scene's", r.name));
                if (held && !std::isfinite(v)) io.fail(fmt::format("region \"{}\" has a velocity that is not finite", r.name));
                if (held) r.velocity[c] = v;
            }
        }
        io.field(r.ramp);
        if constexpr (IO::reading) {
            if (!(r.ramp >= 0.0) || !std::isfinite(r.ramp)) io.fail(fmt::format("region \"{}\" has a ramp that is damaged", r.name));
        }
    }
}

void ExternalLoads::write_state(StateWriter& out, const std::vector<PrescribedVelocitySpec>& regions) const {
    state_fields(out, *this, regions, 0);
}

void ExternalLoads::read_state(StateReader& in, std::vector<PrescribedVelocitySpec>& regions, std::size_t real) {
    state_fields(in, *this, regions, real);
}

}  // namespace gpa
