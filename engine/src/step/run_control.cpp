#include "step/run_control.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

namespace {

std::string component_name(int dim, int c) { return std::string(1, axis_letter(c, dim)); }

std::string stress_name(GeometryKind g, int c) {
    if (g == GeometryKind::ThreeD) return std::array<const char*, 6>{"xx", "yy", "zz", "yz", "xz", "xy"}[c];
    return std::array<const char*, 4>{"xx", "zz", "xz", g == GeometryKind::Axisymmetric ? "tt" : "yy"}[c];
}

// The first real node (lowest index) with a non-finite value in a field a step writes, and
// that field's name.
std::optional<std::pair<std::size_t, std::string>> first_non_finite(const NodeStore& n, std::size_t real) {
    const int d = n.dim();
    std::vector<std::pair<std::string, const std::vector<double>*>> fields;
    for (int c = 0; c < d; ++c) fields.push_back({"position " + component_name(d, c), &n.position[c]});
    for (int c = 0; c < d; ++c) fields.push_back({"velocity " + component_name(d, c), &n.velocity[c]});
    fields.push_back({"volume", &n.volume});
    fields.push_back({"diameter", &n.diameter});
    fields.push_back({"volumetric strain", &n.volumetric_strain});
    for (int c = 0; c < d * d; ++c) {
        fields.push_back({"velocity gradient " + component_name(d, c / d) + component_name(d, c % d), &n.velocity_gradient[c]});
    }
    for (int c = 0; c < d; ++c) fields.push_back({"alpha " + component_name(d, c), &n.alpha[c]});
    for (int c = 0; c < stress_components(d); ++c) {
        fields.push_back({"deviatoric stress " + stress_name(n.geometry(), c), &n.deviatoric_stress[c]});
    }
    fields.push_back({"pressure", &n.pressure});
    fields.push_back({"viscous pressure", &n.viscous_pressure});
    fields.push_back({"sound speed", &n.sound_speed});
    fields.push_back({"internal energy", &n.internal_energy});
    fields.push_back({"stable length", &n.stable_length});
    for (int c = 0; c < d; ++c) fields.push_back({"force " + component_name(d, c), &n.force[c]});
    std::optional<std::pair<std::size_t, std::string>> found;
    for (const auto& [name, field] : fields) {
        const std::size_t count = std::min(real, field->size());
        for (std::size_t i = 0; i < count && (!found || i < found->first); ++i) {
            if (!std::isfinite((*field)[i])) {
                found = std::pair{i, name};
                break;
            }
        }
    }
    return found;
}

std::string describe_site(const FailureSite& f) {
    std::string text = fmt::format("step {} at t = {:.6g} us, phase \"{}\"", f.step, f.time * 1e6, f.phase);
    if (f.node) {
        text += f.id ? fmt::format(": node id {} (index {})", *f.id, *f.node) : fmt::format(": node {}", *f.node);
        if (!f.body.empty()) text += fmt::format(" of body \"{}\"", f.body);
        text += " at (";
        for (int c = 0; c < f.dim; ++c) text += fmt::format("{}{:.6g}", c ? ", " : "", f.position[c] * 1e3);
        text += ") mm";
    }
    if (!f.field.empty()) text += fmt::format(", field {}", f.field);
    return text + ": " + f.cause;
}

}  // namespace

bool RunControl::check_list_memory(const NodeStore& nodes, std::size_t real, std::size_t entries) const {
    const double bytes = double(nodes.size()) * bytes_per_node_besides_lists(nodes.dim()) + double(entries) * bytes_per_list_entry;
    const double limit = double(limit_bytes(memory_));
    if (bytes > limit) {
        throw LimitError(fmt::format("the neighbour lists would hold {} pairs ({:.3g} per node), an estimated {} of "
                                     "memory with the nodes; {}",
                                     entries, double(entries) / double(std::max<std::size_t>(real, 1)), format_bytes(bytes),
                                     describe_limit(memory_)));
    }
    return bytes + double(entries) * bytes_per_kept_pair <= limit;
}

bool RunControl::finished(double time, std::size_t steps, const Totals& t, std::string& reason) const {
    const auto& s = scene_->stop;
    if (s.end_time > 0.0 && time >= s.end_time * (1.0 - 1e-12)) {
        // In microseconds, as the progress line counts the time.
        reason = fmt::format("end time {:.6g} us reached", s.end_time * 1e6);
        return true;
    }
    if (s.kinetic_energy_fraction > 0.0 && steps > 0 &&
        t.kinetic_energy < s.kinetic_energy_fraction * t.initial_kinetic_energy) {
        reason = fmt::format("kinetic energy below {:g} % of its initial value", 100.0 * s.kinetic_energy_fraction);
        return true;
    }
    if (s.max_steps > 0 && steps >= s.max_steps) {
        reason = fmt::format("{} steps done", s.max_steps);
        return true;
    }
    return false;
}

StepFailure RunControl::step_failure(const std::exception& e, const std::string& phase, std::size_t steps, double time,
                                     const NodeStore& nodes, std::size_t real) const {
    const Scene& scene = *scene_;
    FailureSite site;
    site.step = steps + 1;  // the totals phase counts a step when it completes
    site.time = time;
    site.phase = phase.empty() ? "step" : phase;
    site.dim = nodes.dim();
    site.cause = e.what();
    if (const auto* numerical = dynamic_cast<const NumericalError*>(&e); numerical && numerical->node()) {
        site.node = numerical->node();
        site.field = numerical->field();
    } else if (dynamic_cast<const NumericalError*>(&e) || dynamic_cast<const InputError*>(&e)) {
        // The kernel did not say which node: the first with a value that is not a number.
        if (const auto bad = first_non_finite(nodes, real)) {
            site.node = bad->first;
            site.field = bad->second;
        }
    }
    if (site.node && *site.node < nodes.size()) {
        const std::size_t i = *site.node;
        const auto b = static_cast<std::size_t>(nodes.body[i]);
        if (b < scene.bodies.size()) site.body = scene.bodies[b].name;
        if (i < nodes.id.size()) site.id = nodes.id[i];
        for (int c = 0; c < nodes.dim(); ++c) site.position[c] = nodes.position[c][i];
    }
    return StepFailure(describe_site(site), site);
}

void RunControl::check_step(double time_before, double time, double dt_half, std::size_t steps, const Totals& totals,
                            const NodeStore& nodes, std::size_t real) const {
    const Scene& scene = *scene_;
    if (!(time > time_before)) {
        FailureSite site{steps, time, "move", {}, {}, {}, {0, 0, 0}, nodes.dim(), "time", {}};
        site.cause = fmt::format("the time step {:.3g} s no longer advances the time (it is below the rounding step of "
                                 "t = {:.6g} s); a time loop would never end",
                                 dt_half, time);
        throw StepFailure(describe_site(site), site);
    }
    // The energy guard (stop.energy_error): an unstable run gains energy it was never given.
    const double limit = scene.stop.energy_error;
    if (limit > 0.0 && !(std::abs(totals.energy_error) <= limit)) {
        // The fastest node: where an instability has put the energy it made.
        std::size_t fastest = 0;
        double top = -1.0;
        for (std::size_t i = 0; i < real; ++i) {
            double v2 = 0.0;
            for (int c = 0; c < nodes.dim(); ++c) v2 += nodes.velocity[c][i] * nodes.velocity[c][i];
            if (!(v2 <= top)) {
                top = v2;
                fastest = i;
                if (std::isnan(v2)) break;
            }
        }
        FailureSite site{steps, time, "totals", fastest, {}, {}, {0, 0, 0}, nodes.dim(), "total energy", {}};
        if (real > 0) {
            site.id = nodes.id[fastest];
            const auto b = static_cast<std::size_t>(nodes.body[fastest]);
            if (b < scene.bodies.size()) site.body = scene.bodies[b].name;
            for (int c = 0; c < nodes.dim(); ++c) site.position[c] = nodes.position[c][fastest];
        } else {
            site.node.reset();
        }
        const std::string given =
            totals.energy_given != totals.initial_energy
                ? fmt::format(", of {:.6g} J given with the prescribed velocities' work", totals.energy_given)
                : std::string();
        site.cause = fmt::format("the energy error {:+.3g} % exceeds stop.energy_error = {:.3g} % (kinetic {:.6g} J + "
                                 "internal {:.6g} J + boundary work {:.6g} J against {:.6g} J at t = 0{}): the run is "
                                 "unstable (a smaller solver.cfl may help); node {} is the fastest, at {:.4g} m/s",
                                 100.0 * totals.energy_error, 100.0 * limit, totals.kinetic_energy, totals.internal_energy,
                                 totals.boundary_work, totals.initial_energy, given, fastest, std::sqrt(std::max(top, 0.0)));
        throw StepFailure(describe_site(site), site);
    }
}

}  // namespace gpa
