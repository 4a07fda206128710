#include "step/regions.hpp"

#include <fmt/format.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"

namespace gpa {

void Regions::assign(const Scene& scene, NodeStore& nodes, std::size_t real, ElementNodes* element_nodes) {
    const auto& regions = *specs_;
    const std::size_t count = regions.size();
    node_count_.assign(count, 0);
    work_.assign(count, 0.0);
    last_.assign(count, RegionStep{});
    impulse_.assign(count, {0.0, 0.0, 0.0});
    displacement_.assign(count, {0.0, 0.0, 0.0});
    std::vector<std::uint8_t> element_region(element_nodes ? element_nodes->size() : 0, 0);
    const int d = nodes.dim();
    for (std::size_t k = 0; k < count; ++k) {
        const auto& spec = regions[k];
        std::size_t b = 0;
        while (b < scene.bodies.size() && scene.bodies[b].name != spec.body) ++b;
        if (b == scene.bodies.size()) throw InputError(fmt::format("prescribed velocity {}: unknown body \"{}\"", k, spec.body));
        const auto axis = body_axis(scene, b);
        const auto hold = [&](std::uint8_t& region_of, std::array<double*, 3> v, std::size_t i, const std::array<double, 3>& p) {
            if (!in_region(spec, scene.geometry, axis, p)) return;
            if (region_of != 0) {
                throw InputError(fmt::format("prescribed velocities \"{}\" and \"{}\" share node {}", regions[region_of - 1u].name,
                                             spec.name, i));
            }
            region_of = static_cast<std::uint8_t>(k + 1);
            ++node_count_[k];
            for (int c = 0; c < d; ++c) {
                if (spec.velocity[c]) v[c][i] = prescribed_velocity(spec, c, 0.0);
            }
        };
        for (std::size_t i = 0; i < real; ++i) {
            if (nodes.body[i] != static_cast<std::int32_t>(b)) continue;
            std::array<double, 3> p{0, 0, 0};
            for (int c = 0; c < d; ++c) p[c] = nodes.initial_position[c][i];
            hold(nodes.velocity_region[i], {nodes.velocity[0].data(), nodes.velocity[1].data(), d == 3 ? nodes.velocity[2].data() : nullptr},
                 i, p);
        }
        if (element_nodes) {
            ElementNodes& n = *element_nodes;
            for (std::size_t i = 0; i < n.size(); ++i) {
                if (n.body[i] != static_cast<std::int32_t>(b)) continue;
                hold(element_region[i], {n.velocity[0].data(), n.velocity[1].data(), nullptr}, i, {n.position[0][i], n.position[1][i], 0.0});
            }
        }
        if (node_count_[k] == 0) {
            throw InputError(fmt::format("prescribed velocity \"{}\": its region holds no node of body \"{}\"", spec.name, spec.body));
        }
    }
    if (element_nodes) held_elements_.index(element_region.data(), element_region.size(), count);
}

void Regions::index(const NodeStore& nodes, std::size_t real) {
    const auto& regions = *specs_;
    if (regions.empty()) return;
    held_particles_.index(nodes.velocity_region.data(), real, regions.size());
    held_bits_.assign(real, 0);
    for (std::size_t i = 0; i < real; ++i) {
        if (const std::uint8_t k = nodes.velocity_region[i]; k != 0) held_bits_[i] = held_components(regions[k - 1u]);
    }
}

void Regions::book(const std::vector<RegionStep>& step, double dt_avg) {
    for (std::size_t k = 0; k < step.size(); ++k) {
        work_[k] += step[k].work;
        for (int c = 0; c < 3; ++c) impulse_[k][c] += step[k].reaction[c] * dt_avg;
    }
    last_ = step;
}

void Regions::advance_displacements(int dim, double dt) {
    // The velocity the last update imposed, prescribed_velocity(spec, c, t^n + dt / 2), kept from it:
    // the scene's time history, or what a program set after that update (set_region_velocity),
    // which the nodes take only at the next update.
    for (std::size_t k = 0; k < displacement_.size(); ++k) {
        const auto& spec = (*specs_)[k];
        for (int c = 0; c < dim; ++c) {
            if (spec.velocity[c]) displacement_[k][c] += dt * last_[k].velocity[c];
        }
    }
}

void Regions::book_smoothing(int dim, const double* mass, const std::vector<double>& total_change) {
    const auto& nodes_of = held_particles_.nodes();
    for (std::size_t k = 0; k + 1 < nodes_of.offsets.size(); ++k) {
        const auto& spec = (*specs_)[k];
        for (const NodeIndex i : nodes_of.row(k)) {
            for (int c = 0; c < dim; ++c) {
                if (spec.velocity[c]) impulse_[k][c] -= mass[i] * total_change[static_cast<std::size_t>(dim) * i + c];
            }
        }
    }
}

double Regions::report(double time, bool at_half_step, bool at_start, std::vector<RegionReport>& out) const {
    double work_now = 0.0;
    out.resize(specs_->size());
    for (std::size_t k = 0; k < out.size(); ++k) {
        const auto& spec = (*specs_)[k];
        RegionReport& r = out[k];
        r.name = spec.name;
        r.nodes = node_count_[k];
        r.work = at_half_step ? work_[k] : at_start ? 0.0 : work_[k] - 0.5 * last_[k].work;
        for (int c = 0; c < 3; ++c) {
            r.held[c] = spec.velocity[c].has_value();
            r.velocity[c] = prescribed_velocity(spec, c, time);
            r.displacement[c] = displacement_[k][c];
            r.reaction[c] = last_[k].reaction[c];
            r.impulse[c] = impulse_[k][c];
        }
        work_now += r.work;
    }
    return work_now;
}

template <class IO, class Self>
void Regions::state_fields(IO& io, Self& self) {
    io.tag("PVEL");
    io.field(self.work_);
    if constexpr (IO::reading) {
        if (self.work_.size() != self.specs_->size()) io.fail("its prescribed velocities are not the scene's");
    }
    for (std::size_t k = 0; k < self.work_.size(); ++k) {
        for (int c = 0; c < 3; ++c) {
            io.field(self.last_[k].reaction[c]);
            io.field(self.impulse_[k][c]);
            io.field(self.displacement_[k][c]);
            io.field(self.last_[k].velocity[c]);
        }
        io.field(self.last_[k].work);
    }
}

void Regions::write_state(StateWriter& out) const { state_fields(out, *this); }
void Regions::read_state(StateReader& in) { state_fields(in, *this); }

void Regions::check_restored(StateReader& in, const NodeStore& nodes, std::size_t real) {
    const std::size_t regions = specs_->size();
    for (std::size_t i = 0; i < real; ++i) {
        if (nodes.velocity_region[i] > regions) in.fail("a node is held by a prescribed velocity the scene does not have");
    }
    index(nodes, real);
    for (std::size_t k = 0; k < regions; ++k) {
        // (Element nodes are held by their set-up positions, which the mesh keeps; particles move.)
        const std::size_t held = held_particles_.nodes().row_size(k) + (held_elements_.empty() ? 0 : held_elements_.nodes().row_size(k));
        if (held != node_count_[k]) in.fail("its prescribed velocities hold other nodes than the scene's");
    }
}

}  // namespace gpa
