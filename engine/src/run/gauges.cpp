#include "gpa/engine/gauges.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"

namespace gpa {

namespace {

struct FieldInfo {
    GaugeField field;
    std::string_view word;
};

constexpr FieldInfo field_table[] = {
    {GaugeField::Position, "position"},
    {GaugeField::Displacement, "displacement"},
    {GaugeField::Velocity, "velocity"},
    {GaugeField::NormalVelocity, "normal_velocity"},
    {GaugeField::Pressure, "pressure"},
    {GaugeField::VonMises, "von_mises"},
    {GaugeField::Stress, "stress"},
    {GaugeField::PlasticStrain, "plastic_strain"},
    {GaugeField::Temperature, "temperature"},
    {GaugeField::Density, "density"},
    {GaugeField::InternalEnergy, "internal_energy"},
    {GaugeField::Damage, "damage"},
    {GaugeField::VolumetricStrain, "volumetric_strain"},
};

std::string gauge_label(const GaugeSpec& g, std::size_t index) {
    return g.name.empty() ? fmt::format("gauge[{}]", index) : fmt::format("gauge \"{}\" (gauge[{}])", g.name, index);
}

std::string_view axis_name(int dim, int axis) {
    static constexpr std::string_view two[] = {"x", "z"};
    static constexpr std::string_view three[] = {"x", "y", "z"};
    return dim == 3 ? three[axis] : two[axis];
}

// The stress component names in the stored order (geometry.hpp).
std::vector<std::string_view> stress_names(GeometryKind g) {
    switch (g) {
        case GeometryKind::Axisymmetric: return {"xx", "zz", "xz", "tt"};
        case GeometryKind::PlaneStrain: return {"xx", "zz", "xz", "yy"};
        case GeometryKind::ThreeD: break;
    }
    return {"xx", "yy", "zz", "yz", "xz", "xy"};
}

std::string format_point(const std::array<double, 3>& x, int dim) {
    return dim == 3 ? fmt::format("(x, y, z) = ({:.6g}, {:.6g}, {:.6g}) mm", x[0] * 1e3, x[1] * 1e3, x[2] * 1e3)
                    : fmt::format("(x, z) = ({:.6g}, {:.6g}) mm", x[0] * 1e3, x[1] * 1e3);
}

}  // namespace

std::string_view name_of(GaugeField f) {
    for (const auto& e : field_table) {
        if (e.field == f) return e.word;
    }
    return "?";
}

bool gauge_field_of(std::string_view word, GaugeField& out) {
    for (const auto& e : field_table) {
        if (e.word == word) {
            out = e.field;
            return true;
        }
    }
    return false;
}

std::vector<std::string_view> gauge_field_words() {
    std::vector<std::string_view> words;
    for (const auto& e : field_table) words.push_back(e.word);
    return words;
}

std::vector<GaugeField> default_gauge_fields(GaugeKind kind) {
    std::vector<GaugeField> f{GaugeField::Velocity, GaugeField::Pressure, GaugeField::VonMises, GaugeField::PlasticStrain,
                              GaugeField::Temperature};
    if (kind == GaugeKind::FreeSurface) f.insert(f.begin(), GaugeField::NormalVelocity);
    return f;
}

void validate_gauges(const Scene& scene) {
    const int dim = dimension_of(scene.geometry);
    for (std::size_t k = 0; k < scene.gauges.size(); ++k) {
        const GaugeSpec& g = scene.gauges[k];
        const std::string label = gauge_label(g, k);
        if (g.name.empty()) throw GaugeError(fmt::format("{}: a gauge needs a name (it names its file, gauge_<name>.csv)", label), k);
        if (g.name.size() > 64 ||
            !std::all_of(g.name.begin(), g.name.end(), [](char c) {
                return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_';
            })) {
            throw GaugeError(fmt::format("{}: the name may hold letters, digits, '-' and '_' only (at most 64; it names the file "
                                         "gauge_<name>.csv)",
                                         label), k);
        }
        for (std::size_t j = 0; j < k; ++j) {
            if (scene.gauges[j].name == g.name) {
                throw GaugeError(fmt::format("{}: the name is already used by gauge[{}]", label, j), k);
            }
        }
        for (int c = 0; c < dim; ++c) {
            if (!std::isfinite(g.at[c])) throw GaugeError(fmt::format("{}: at: component {} is not finite", label, axis_name(dim, c)), k);
        }
        if (!(g.radius >= 0.0) || !std::isfinite(g.radius)) {
            throw GaugeError(fmt::format("{}: radius = {} m: it must be 0 (one node) or a positive length", label, g.radius), k);
        }
        if (!g.body.empty()) {
            const auto body = std::find_if(scene.bodies.begin(), scene.bodies.end(), [&](const BodySpec& b) { return b.name == g.body; });
            if (body == scene.bodies.end()) {
                std::string names;
                for (const auto& b : scene.bodies) names += (names.empty() ? "\"" : ", \"") + b.name + "\"";
                throw GaugeError(fmt::format("{}: body \"{}\" is not a body of the scene (its bodies: {})", label, g.body, names), k);
            }
            if (body->discretisation != Discretisation::Particles) {
                throw GaugeError(fmt::format("{}: body \"{}\" is meshed with elements; gauges read particle bodies", label, g.body), k);
            }
        } else if (std::none_of(scene.bodies.begin(), scene.bodies.end(),
                                [](const BodySpec& b) { return b.discretisation == Discretisation::Particles; })) {
            throw GaugeError(fmt::format("{}: the scene has no particle body; gauges read particle bodies", label), k);
        }
        if (g.kind == GaugeKind::FreeSurface) {
            if (g.body.empty()) {
                throw GaugeError(fmt::format("{}: a free-surface gauge names its body (the face is that body's: a face of one body "
                                             "may lie under another)",
                                             label),
                                 k);
            }
            if (scene.geometry == GeometryKind::Axisymmetric && g.normal_axis == 0 && g.normal_sign < 0) {
                throw GaugeError(fmt::format("{}: normal -x points at the axis of an axisymmetric scene, which is not a free surface",
                                             label),
                                 k);
            }
            if (g.normal_axis < 0 || g.normal_axis >= dim || (g.normal_sign != 1 && g.normal_sign != -1)) {
                throw GaugeError(fmt::format("{}: a free-surface gauge needs the outward normal of its face, an axis and a sign "
                                             "(for example \"+z\" or \"-x\")",
                                             label), k);
            }
        } else if (g.normal_axis >= 0) {
            throw GaugeError(fmt::format("{}: normal applies to free-surface gauges only (kind = \"free_surface\")", label), k);
        }
        for (std::size_t a = 0; a < g.fields.size(); ++a) {
            if (g.fields[a] == GaugeField::NormalVelocity && g.kind != GaugeKind::FreeSurface) {
                throw GaugeError(fmt::format("{}: fields: normal_velocity is the velocity along a free surface's normal; a point "
                                             "gauge has none (record velocity, or make it kind = \"free_surface\")",
                                             label), k);
            }
            for (std::size_t b = 0; b < a; ++b) {
                if (g.fields[a] == g.fields[b]) throw GaugeError(fmt::format("{}: fields: {} is listed twice", label, name_of(g.fields[a])), k);
            }
        }
    }
}

Gauge::Gauge(const GaugeSpec& spec, const Scene& scene, const NodeStore& nodes, std::size_t real)
    : spec_(spec), geometry_(scene.geometry) {
    if (spec_.fields.empty()) spec_.fields = default_gauge_fields(spec_.kind);
    const int dim = dimension_of(geometry_);
    const std::string label = fmt::format("gauge \"{}\"", spec_.name);
    int body = -1;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (!spec_.body.empty() && scene.bodies[b].name == spec_.body) body = static_cast<int>(b);
    }
    const auto candidate = [&](std::size_t i) { return spec_.body.empty() || nodes.body[i] == body; };
    // Each particle body's lattice spacing per axis: a node's cell extends half of it either way.
    std::vector<std::array<double, 3>> spacing(scene.bodies.size(), std::array<double, 3>{0.0, 0.0, 0.0});
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const BodySpec& body_spec = scene.bodies[b];
        if (body_spec.shape == ShapeKind::Nodes) {  // imported nodes: their median diameter
            const double d = nominal_spacing(body_spec);
            spacing[b] = {d, d, d};
        } else if (body_spec.discretisation == Discretisation::Particles) {
            spacing[b] = body_lattice(scene, b).spacing;
        }
    }
    const auto cell = [&](std::size_t i, int axis) { return spacing[static_cast<std::size_t>(nodes.body[i])][static_cast<std::size_t>(axis)]; };
    const auto largest_cell = [&](std::size_t i) {
        double h = 0.0;
        for (int c = 0; c < dim; ++c) h = std::max(h, cell(i, c));
        return h;
    };
    const auto initial = [&](std::size_t i) {
        std::array<double, 3> x{0.0, 0.0, 0.0};
        for (int c = 0; c < dim; ++c) x[c] = nodes.initial_position[c][i];
        return x;
    };
    // Squared distance from `at`, all axes or all but `skip`.
    const auto distance2 = [&](std::size_t i, int skip) {
        const auto x = initial(i);
        double s = 0.0;
        for (int c = 0; c < dim; ++c) {
            if (c != skip) s += (x[c] - spec_.at[c]) * (x[c] - spec_.at[c]);
        }
        return s;
    };
    const std::string where = spec_.body.empty() ? "any particle body" : fmt::format("body \"{}\"", spec_.body);
    // The nearest candidate (ties: lowest id), for the messages and the single-node point.
    std::size_t nearest = real;
    for (std::size_t i = 0; i < real; ++i) {
        if (!candidate(i)) continue;
        const int skip = spec_.kind == GaugeKind::FreeSurface ? spec_.normal_axis : -1;
        if (nearest == real || distance2(i, skip) < distance2(nearest, skip) ||
            (distance2(i, skip) == distance2(nearest, skip) && nodes.id[i] < nodes.id[nearest])) {
            nearest = i;
        }
    }
    if (nearest == real) throw InputError(fmt::format("{}: {} has no nodes", label, where));

    std::vector<std::size_t> chosen;
    if (spec_.kind == GaugeKind::Point) {
        if (spec_.radius == 0.0) {
            // The nearest node's cell must hold the point, or nearly (within a cell of its centre).
            if (std::sqrt(distance2(nearest, -1)) > largest_cell(nearest)) {
                throw InputError(fmt::format("{}: {} is not in {}: the nearest node is {:.6g} mm away at t = 0, more than a cell "
                                             "({:.6g} mm); move the point into the body",
                                             label, format_point(spec_.at, dim), where, std::sqrt(distance2(nearest, -1)) * 1e3,
                                             largest_cell(nearest) * 1e3));
            }
            chosen.push_back(nearest);
        } else {
            for (std::size_t i = 0; i < real; ++i) {
                if (candidate(i) && distance2(i, -1) <= spec_.radius * spec_.radius) chosen.push_back(i);
            }
            if (chosen.empty()) {
                throw InputError(fmt::format("{}: no node of {} lies within radius {:.6g} mm of {} at t = 0 (the nearest is {:.6g} mm "
                                             "away): make the radius larger or move the point",
                                             label, where, spec_.radius * 1e3, format_point(spec_.at, dim),
                                             std::sqrt(distance2(nearest, -1)) * 1e3));
            }
        }
    } else {
        // The spot: the nodes within the radius across the normal (0: those as near as the nearest).
        const int a = spec_.normal_axis;
        const double s = spec_.normal_sign;
        if (spec_.radius == 0.0 && std::sqrt(distance2(nearest, a)) > largest_cell(nearest)) {
            throw InputError(fmt::format("{}: {} is beside {}: across the normal the nearest node is {:.6g} mm away at t = 0, more "
                                         "than a cell ({:.6g} mm); move the point onto the face",
                                         label, format_point(spec_.at, dim), where, std::sqrt(distance2(nearest, a)) * 1e3,
                                         largest_cell(nearest) * 1e3));
        }
        const double reach2 = spec_.radius > 0.0 ? spec_.radius * spec_.radius : distance2(nearest, a);
        std::vector<std::size_t> spot;
        for (std::size_t i = 0; i < real; ++i) {
            if (candidate(i) && distance2(i, a) <= reach2) spot.push_back(i);
        }
        if (spot.empty()) {
            throw InputError(fmt::format("{}: no node of {} lies within radius {:.6g} mm of {} across the normal at t = 0: make the "
                                         "radius larger or move the point",
                                         label, where, spec_.radius * 1e3, format_point(spec_.at, dim)));
        }
        // Its outermost row: within half a cell of the outermost node along the normal.
        double outermost = -std::numeric_limits<double>::infinity();
        std::size_t edge = spot.front();
        for (const std::size_t i : spot) {
            if (s * initial(i)[a] > outermost) {
                outermost = s * initial(i)[a];
                edge = i;
            }
        }
        for (const std::size_t i : spot) {
            if (s * initial(i)[a] >= outermost - 0.5 * cell(i, a)) chosen.push_back(i);
        }
        // The face is half a cell beyond the outermost node; `at` must be on it.
        const double face = outermost + 0.5 * cell(edge, a);
        if (std::abs(s * spec_.at[a] - face) > cell(edge, a)) {
            throw InputError(fmt::format("{}: {} is not on the face of {} whose outward normal is {}{}: the face there is at {} = "
                                         "{:.6g} mm (the outermost nodes' outer edge at t = 0)",
                                         label, format_point(spec_.at, dim), where, s > 0 ? "+" : "-", axis_name(dim, a),
                                         axis_name(dim, a), s * face * 1e3));
        }
    }
    std::sort(chosen.begin(), chosen.end(), [&](std::size_t x, std::size_t y) { return nodes.id[x] < nodes.id[y]; });
    for (const std::size_t i : chosen) {
        ids_.push_back(nodes.id[i]);
        index_.push_back(i);
    }
}

std::vector<std::string> Gauge::columns() const {
    const int dim = dimension_of(geometry_);
    std::vector<std::string> out;
    for (const GaugeField f : spec_.fields) {
        switch (f) {
            case GaugeField::Position:
            case GaugeField::Displacement:
            case GaugeField::Velocity:
                for (int c = 0; c < dim; ++c) {
                    out.push_back(fmt::format("{}_{}_{}", name_of(f), axis_name(dim, c), f == GaugeField::Velocity ? "m_s" : "m"));
                }
                break;
            case GaugeField::NormalVelocity: out.emplace_back("normal_velocity_m_s"); break;
            case GaugeField::Pressure: out.emplace_back("pressure_Pa"); break;
            case GaugeField::VonMises: out.emplace_back("von_mises_Pa"); break;
            case GaugeField::Stress:
                for (const auto component : stress_names(geometry_)) out.push_back(fmt::format("stress_{}_Pa", component));
                break;
            case GaugeField::PlasticStrain: out.emplace_back("plastic_strain"); break;
            case GaugeField::Temperature: out.emplace_back("temperature_K"); break;
            case GaugeField::Density: out.emplace_back("density_kg_m3"); break;
            case GaugeField::InternalEnergy: out.emplace_back("internal_energy_J_kg"); break;
            case GaugeField::Damage: out.emplace_back("damage"); break;
            case GaugeField::VolumetricStrain: out.emplace_back("volumetric_strain"); break;
        }
    }
    return out;
}

std::vector<double> Gauge::read(const NodeStore& nodes, std::size_t real) {
    // Where the nodes are now: the last places, unless a reordering has moved one.
    bool moved = false;
    for (std::size_t k = 0; k < ids_.size(); ++k) moved = moved || index_[k] >= real || nodes.id[index_[k]] != ids_[k];
    if (moved) {
        std::size_t found = 0;
        for (std::size_t i = 0; i < real; ++i) {
            const auto it = std::lower_bound(ids_.begin(), ids_.end(), nodes.id[i]);
            if (it != ids_.end() && *it == nodes.id[i]) {
                index_[static_cast<std::size_t>(it - ids_.begin())] = i;
                ++found;
            }
        }
        if (found != ids_.size()) {
            throw InputError(fmt::format("gauge \"{}\": {} of its {} nodes are no longer among the run's nodes", spec_.name,
                                         ids_.size() - found, ids_.size()));
        }
    }
    const int dim = dimension_of(geometry_);
    const int components = stress_components(dim);
    double mass = 0.0;
    for (const std::size_t i : index_) mass += nodes.mass[i];
    // The mass-weighted mean of one value over the gauge's nodes.
    const auto mean = [&](auto&& value) {
        double sum = 0.0;
        for (const std::size_t i : index_) sum += nodes.mass[i] * value(i);
        return sum / mass;
    };
    std::vector<double> out;
    for (const GaugeField f : spec_.fields) {
        switch (f) {
            case GaugeField::Position:
                for (int c = 0; c < dim; ++c) out.push_back(mean([&](std::size_t i) { return nodes.position[c][i]; }));
                break;
            case GaugeField::Displacement:
                for (int c = 0; c < dim; ++c) {
                    out.push_back(mean([&](std::size_t i) { return nodes.position[c][i] - nodes.initial_position[c][i]; }));
                }
                break;
            case GaugeField::Velocity:
                for (int c = 0; c < dim; ++c) out.push_back(mean([&](std::size_t i) { return nodes.velocity[c][i]; }));
                break;
            case GaugeField::NormalVelocity:
                out.push_back(spec_.normal_sign * mean([&](std::size_t i) { return nodes.velocity[spec_.normal_axis][i]; }));
                break;
            case GaugeField::Pressure: out.push_back(mean([&](std::size_t i) { return nodes.pressure[i]; })); break;
            case GaugeField::VonMises:
                out.push_back(mean([&](std::size_t i) {
                    double ss = 0.0;
                    for (int c = 0; c < components; ++c) {
                        const double v = nodes.deviatoric_stress[c][i];
                        // Diagonal components once, shear components twice (s : s).
                        const bool shear = dim == 3 ? c >= 3 : c == 2;
                        ss += (shear ? 2.0 : 1.0) * v * v;
                    }
                    return std::sqrt(1.5 * ss);
                }));
                break;
            case GaugeField::Stress:
                for (int c = 0; c < components; ++c) {
                    const bool shear = dim == 3 ? c >= 3 : c == 2;
                    out.push_back(mean([&](std::size_t i) { return nodes.deviatoric_stress[c][i] - (shear ? 0.0 : nodes.pressure[i]); }));
                }
                break;
            case GaugeField::PlasticStrain: out.push_back(mean([&](std::size_t i) { return nodes.plastic_strain[i]; })); break;
            case GaugeField::Temperature: out.push_back(mean([&](std::size_t i) { return nodes.temperature[i]; })); break;
            case GaugeField::Density: out.push_back(mean([&](std::size_t i) { return nodes.mass[i] / nodes.volume[i]; })); break;
            case GaugeField::InternalEnergy: out.push_back(mean([&](std::size_t i) { return nodes.internal_energy[i]; })); break;
            // D in [0, 1], as the snapshots write it (the model sums it past 1 after failure).
            case GaugeField::Damage: out.push_back(mean([&](std::size_t i) { return std::min(nodes.damage[i], 1.0); })); break;
            case GaugeField::VolumetricStrain: out.push_back(mean([&](std::size_t i) { return nodes.volumetric_strain[i]; })); break;
        }
    }
    return out;
}

}  // namespace gpa
