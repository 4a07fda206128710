#include "step/measures.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <span>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "reduce_grain.hpp"

namespace gpa {

namespace {

// The directions across a plane along which widths are measured: for an aligned plane its first
// other axis (the radius x in axisymmetric geometry) and in 3D its second, read exactly; for an
// oblique plane t1, the coordinate axis least along n with its part along n removed, and t2 = n x t1.
struct Across {
    int first_axis = -1, second_axis = -1;  // aligned planes
    std::array<double, 3> t1{0, 0, 0}, t2{0, 0, 0};
    template <class Field>
    double first(const Field& x, std::size_t i) const {
        if (first_axis >= 0) return x[static_cast<std::size_t>(first_axis)][i];
        return t1[0] * x[0][i] + t1[1] * x[1][i] + (t1[2] != 0.0 ? t1[2] * x[2][i] : 0.0);
    }
    template <class Field>
    double second(const Field& x, std::size_t i) const {
        if (second_axis >= 0) return x[static_cast<std::size_t>(second_axis)][i];
        return t2[0] * x[0][i] + t2[1] * x[1][i] + (t2[2] != 0.0 ? t2[2] * x[2][i] : 0.0);
    }
    double first(const std::array<double, 3>& x) const {
        return first_axis >= 0 ? x[static_cast<std::size_t>(first_axis)] : t1[0] * x[0] + t1[1] * x[1] + t1[2] * x[2];
    }
    double second(const std::array<double, 3>& x) const {
        return second_axis >= 0 ? x[static_cast<std::size_t>(second_axis)] : t2[0] * x[0] + t2[1] * x[1] + t2[2] * x[2];
    }
};

Across across_of(const GhostPlane& plane, int dim) {
    Across a;
    if (plane.axis >= 0) {
        a.first_axis = plane.axis == 0 ? 1 : 0;
        a.second_axis = dim == 3 ? (plane.axis == 2 ? 1 : 2) : 0;
        return a;
    }
    const auto& n = plane.normal;
    if (dim == 2) {
        a.t1 = {n[1], -n[0], 0.0};
        return a;
    }
    int k = 0;
    for (int c = 1; c < 3; ++c) {
        if (std::abs(n[c]) < std::abs(n[k])) k = c;
    }
    std::array<double, 3> t{0, 0, 0};
    t[k] = 1.0;
    for (int c = 0; c < 3; ++c) t[c] -= n[k] * n[c];
    const double length = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int c = 0; c < 3; ++c) t[c] /= length;
    a.t1 = t;
    a.t2 = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
    return a;
}

// Node i into the extent above `plane` (measure.hpp): across the plane's first other axis (the
// radius x in axisymmetric geometry) in 2D, along the footprint's directions in the plane in 3D;
// with its images across the symmetry planes in `mirrors` that stand on `plane` (normal to another
// axis, at most one per axis), so that a half or quarter model is measured as the whole body.
void add_to_extent(measure::Extent& e, const NodeStore& nodes, std::size_t i, const GhostPlane& plane, const Across& across,
                   bool axisymmetric, double base, std::span<const GhostPlane> mirrors) {
    const int d = nodes.dim();
    const double height = plane.distance_of(nodes.position, i) - base;
    const double cell = measure::particle_cell_size(nodes.size_weight[i], d);
    const auto add = [&](double along_first, double along_second) {
        if (d == 3) {
            measure::add_particle_3d(e, height, along_first, along_second, cell);
        } else {
            measure::add_particle(e, height, along_first, cell, axisymmetric && across.first_axis == 0);
        }
    };
    if (mirrors.empty()) {  // the whole body (most scenes, every step): no images to make
        add(across.first(nodes.position, i), d == 3 ? across.second(nodes.position, i) : 0.0);
        return;
    }
    const std::size_t images = std::size_t{1} << mirrors.size();
    for (std::size_t mask = 0; mask < images; ++mask) {
        std::array<double, 3> x{nodes.position[0][i], nodes.position[1][i], d == 3 ? nodes.position[2][i] : 0.0};
        for (std::size_t k = 0; k < mirrors.size(); ++k) {
            if (mask & (std::size_t{1} << k)) mirrors[k].reflect_point(x);
        }
        add(across.first(x), d == 3 ? across.second(x) : 0.0);
    }
}

}  // namespace

NodeSums& NodeSums::operator+=(const NodeSums& o) {
    kinetic += o.kinetic;
    internal += o.internal;
    plastic += o.plastic;
    viscous += o.viscous;
    for (int c = 0; c < 3; ++c) momentum[c] += o.momentum[c];
    extent += o.extent;
    variable += o.variable;
    failed += o.failed;
    return *this;
}

void Measures::set_up(const Scene& scene, const NodeStore& nodes, std::size_t real) {
    std::vector<std::array<double, 3>> body_velocity;
    for (const auto& b : scene.bodies) body_velocity.push_back(b.velocity);
    impact_ = impact_frame(nodes, real, body_velocity, scene.geometry == GeometryKind::Axisymmetric);
    body_kinetic_half_.assign(scene.bodies.size(), 0.0);
    // The symmetry planes a particle body reaches (scene.hpp, reaches_symmetry_plane); not in
    // axisymmetric geometry, whose widths are mirrored about the axis already.
    width_mirrors_.clear();
    if (scene.geometry == GeometryKind::Axisymmetric) return;
    for (std::size_t k = 0; k < scene.planes.size(); ++k) {
        const PlaneSpec& p = scene.planes[k];
        for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
            if (scene.bodies[b].discretisation == Discretisation::Particles && reaches_symmetry_plane(scene, b, k)) {
                width_mirrors_.push_back({p.name, p.axis, p.position, p.side, false, false, false, p.axis < 0 ? p.normal : std::array<double, 3>{}});
                break;
            }
        }
    }
}

std::vector<GhostPlane> Measures::mirrors_on(const GhostPlane& plane) const {
    std::vector<GhostPlane> out;
    for (const GhostPlane& m : width_mirrors_) {
        // Planes standing on `plane` (perpendicular to it and to each other): two parallel symmetry
        // planes would make an endless row of images. (No measuring plane: axis -1 and no normal.)
        const bool measuring = plane.axis >= 0 || plane.normal != std::array<double, 3>{};
        if (measuring && !perpendicular(m, plane)) continue;
        if (!std::all_of(out.begin(), out.end(), [&](const GhostPlane& o) { return perpendicular(m, o); })) continue;
        out.push_back(m);
    }
    return out;
}

double Measures::advance_kinetic(double half_step_now) {
    const double at_integer_time = 0.5 * (kinetic_half_ + half_step_now);
    kinetic_half_ = half_step_now;
    return at_integer_time;
}

NodeSums Measures::node_sums(const NodeStore& nodes, std::size_t real, const GhostPlane* plane, bool axisymmetric) const {
    const int d = nodes.dim();
    const std::vector<GhostPlane> mirrors = plane ? mirrors_on(*plane) : std::vector<GhostPlane>{};
    const Across across = plane ? across_of(*plane, d) : Across{};
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), NodeSums{},
        [&](const tbb::blocked_range<std::size_t>& r, NodeSums acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double m = nodes.mass[i];
                double v2 = 0.0;
                for (int c = 0; c < d; ++c) {
                    v2 += nodes.velocity[c][i] * nodes.velocity[c][i];
                    acc.momentum[c] += m * nodes.velocity[c][i];
                }
                acc.kinetic += 0.5 * m * v2;
                acc.internal += m * nodes.internal_energy[i];
                acc.plastic += m * nodes.plastic_work[i];
                acc.viscous += m * nodes.viscous_work[i];
                acc.variable += nodes.connectivity[i] == Connectivity::Variable;
                acc.failed += nodes.failed[i] != 0;
                if (plane) add_to_extent(acc.extent, nodes, i, *plane, across, axisymmetric, 0.0, mirrors);
            }
            return acc;
        },
        [](NodeSums x, const NodeSums& y) { return x += y; });
}

measure::Extent Measures::particle_extent(const NodeStore& nodes, std::size_t real, const GhostPlane& plane, bool axisymmetric,
                                          double base) const {
    const std::vector<GhostPlane> mirrors = mirrors_on(plane);
    const Across across = across_of(plane, nodes.dim());
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), measure::Extent{},
        [&](const tbb::blocked_range<std::size_t>& r, measure::Extent acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) add_to_extent(acc, nodes, i, plane, across, axisymmetric, base, mirrors);
            return acc;
        },
        [](measure::Extent x, const measure::Extent& y) { return x += y; });
}

measure::Extent Measures::element_extent(const ElementMesh& m, const GhostPlane& plane, bool axisymmetric, double base) {
    // The element rule of measure.hpp: nodes lie on the boundary (no d/2), "on the face" within
    // the face tolerance of the node's body from `base`.
    // Element scenes have aligned planes only (validate_scene).
    const int across = plane.axis == 0 ? 1 : 0;
    return tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, m.nodes.size(), reduce_grain), measure::Extent{},
        [&](const tbb::blocked_range<std::size_t>& r, measure::Extent acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double spacing = m.body_spacing[static_cast<std::size_t>(m.nodes.body[i])];
                measure::add_element_node(acc, plane.distance(m.nodes.position[plane.axis][i]) - base, m.nodes.position[across][i],
                                          measure::element_face_tolerance(spacing, base), axisymmetric && across == 0);
            }
            return acc;
        },
        [](measure::Extent x, const measure::Extent& y) { return x += y; });
}

void Measures::body_totals(const Scene& scene, const NodeStore& nodes, std::size_t real, bool advance_kinetic,
                           const NodeSums* particle_sums, std::vector<BodyTotals>& out) {
    const int d = nodes.dim();
    const std::size_t bodies = scene.bodies.size();
    if (bodies == 1 && particle_sums) {
        out.resize(1);
        BodyTotals& t = out[0];
        t.name = scene.bodies[0].name;
        if (t.mass == 0.0) t.mass = std::accumulate(nodes.mass.begin(), nodes.mass.begin() + real, 0.0);
        if (advance_kinetic) {
            t.kinetic_energy = 0.5 * (body_kinetic_half_[0] + particle_sums->kinetic);
            body_kinetic_half_[0] = particle_sums->kinetic;
        }
        t.internal_energy = particle_sums->internal;
        for (int c = 0; c < 3; ++c) {
            t.momentum[c] = c < d ? particle_sums->momentum[c] : 0.0;
            t.centre_velocity[c] = t.mass > 0.0 ? t.momentum[c] / t.mass : 0.0;
        }
        t.nodes = real;
        t.failed_nodes = particle_sums->failed;
        t.target = impact_.defined && impact_.target[0];
        return;
    }
    struct BodySums {
        std::vector<double> values;  // per body: mass, kinetic, internal, momentum[3], nodes, failed
        BodySums& operator+=(const BodySums& o) {
            if (values.empty()) {
                values = o.values;
            } else {
                for (std::size_t k = 0; k < o.values.size(); ++k) values[k] += o.values[k];
            }
            return *this;
        }
    };
    constexpr std::size_t slots = 8;
    const BodySums s = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, real, reduce_grain), BodySums{},
        [&](const tbb::blocked_range<std::size_t>& r, BodySums acc) {
            if (acc.values.empty()) acc.values.assign(bodies * slots, 0.0);
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                double* v = acc.values.data() + static_cast<std::size_t>(nodes.body[i]) * slots;
                const double m = nodes.mass[i];
                double v2 = 0.0;
                for (int c = 0; c < d; ++c) {
                    v2 += nodes.velocity[c][i] * nodes.velocity[c][i];
                    v[3 + c] += m * nodes.velocity[c][i];
                }
                v[0] += m;
                v[1] += 0.5 * m * v2;
                v[2] += m * nodes.internal_energy[i];
                v[6] += 1.0;
                v[7] += nodes.failed[i] != 0;
            }
            return acc;
        },
        [](BodySums x, const BodySums& y) { return x += y; });
    out.resize(bodies);
    for (std::size_t b = 0; b < bodies; ++b) {
        BodyTotals& t = out[b];
        t.name = scene.bodies[b].name;
        const double* v = s.values.empty() ? nullptr : s.values.data() + b * slots;
        const double kinetic = v ? v[1] : 0.0;
        t.mass = v ? v[0] : 0.0;
        if (advance_kinetic) {
            t.kinetic_energy = 0.5 * (body_kinetic_half_[b] + kinetic);
            body_kinetic_half_[b] = kinetic;
        }
        t.internal_energy = v ? v[2] : 0.0;
        for (int c = 0; c < 3; ++c) {
            t.momentum[c] = v && c < d ? v[3 + c] : 0.0;
            t.centre_velocity[c] = t.mass > 0.0 ? t.momentum[c] / t.mass : 0.0;
        }
        t.nodes = v ? static_cast<std::size_t>(v[6]) : 0;
        t.failed_nodes = v ? static_cast<std::size_t>(v[7]) : 0;
        t.target = impact_.defined && impact_.target[b];
    }
}

void Measures::local_fields(const Scene& scene, const NodeStore& nodes, std::size_t real, const GhostPlane* plane,
                            const ElementPart* elements, double base_height, Totals::LocalFields& out) const {
    // measure.hpp: peaks over a neighbourhood of the same radius for particle nodes and element
    // triangles; the face roughness over the points on the body's base.
    out.radius = scene.output.peak_radius > 0.0 ? scene.output.peak_radius
                 : scene.bodies.empty()        ? 0.0
                                               : 2.0 * nominal_spacing(scene.bodies.front());
    out.measured = out.radius > 0.0;
    if (!out.measured) return;
    const int d = nodes.dim();
    const int across = plane && plane->axis == 0 ? 1 : 0;  // element nodes (aligned planes only)
    const Across particle_across = plane ? across_of(*plane, d) : Across{0, 0};
    // The material points, and their plastic strain and temperature.
    std::vector<measure::FieldPoint> points;
    std::vector<double> strain, heat;
    std::vector<double> face_across, face_value;
    std::vector<std::array<double, 3>> face_position;  // of the face points, for their images
    // The face row of particles: nodes on the base now that started in the lattice row nearest
    // the plane (below the next row up), so that a second row pressed down does not mix in.
    double first_row = INFINITY;
    if (plane) {
        for (std::size_t i = 0; i < real; ++i) first_row = std::min(first_row, plane->distance_of(nodes.initial_position, i));
    }
    for (std::size_t i = 0; i < real; ++i) {
        measure::FieldPoint p;
        for (int c = 0; c < d; ++c) p.position[c] = nodes.position[c][i];
        p.weight = nodes.size_weight[i];
        p.body = nodes.body[i];
        points.push_back(p);
        strain.push_back(nodes.plastic_strain[i]);
        heat.push_back(nodes.temperature[i]);
        if (plane && plane->distance_of(nodes.position, i) - base_height < measure::particle_cell_size(nodes.size_weight[i], d) &&
            plane->distance_of(nodes.initial_position, i) - first_row < 0.5 * nodes.initial_diameter[i]) {
            face_across.push_back(particle_across.first(nodes.position, i));
            face_position.push_back({nodes.position[0][i], nodes.position[1][i], d == 3 ? nodes.position[2][i] : 0.0});
            face_value.push_back(nodes.plastic_strain[i]);
        }
    }
    if (elements) {
        const ElementMesh& m = elements->mesh();
        for (std::size_t q = 0; q < m.quads.size(); ++q) {
            const auto& n = m.quads.nodes[q];
            for (int k = 0; k < 4; ++k) {
                const NodeIndex a = n[4], b = n[k], c = n[(k + 1) % 4];
                const std::size_t t = 4 * q + static_cast<std::size_t>(k);
                measure::FieldPoint p;
                for (int x = 0; x < 2; ++x) {
                    p.position[x] = (m.nodes.position[x][a] + m.nodes.position[x][b] + m.nodes.position[x][c]) / 3.0;
                }
                p.weight = 0.5 * std::abs((m.nodes.position[0][b] - m.nodes.position[0][a]) * (m.nodes.position[1][c] - m.nodes.position[1][a]) -
                                          (m.nodes.position[1][b] - m.nodes.position[1][a]) * (m.nodes.position[0][c] - m.nodes.position[0][a]));
                p.body = m.quads.body[q];
                points.push_back(p);
                strain.push_back(m.points.plastic_strain[t]);
                heat.push_back(m.points.temperature[t]);
                if (plane) {
                    // A triangle whose outer edge lies on the base.
                    const double tol =
                        measure::element_face_tolerance(m.body_spacing[static_cast<std::size_t>(m.quads.body[q])], base_height);
                    const double hb = plane->distance(m.nodes.position[plane->axis][b]) - base_height;
                    const double hc = plane->distance(m.nodes.position[plane->axis][c]) - base_height;
                    if (hb <= tol && hc <= tol) {
                        face_across.push_back(p.position[across]);
                        face_position.push_back(p.position);
                        face_value.push_back(m.points.plastic_strain[t]);
                    }
                }
            }
        }
    }
    // A half or quarter model: the points' images across the symmetry planes bodies reach belong to
    // the neighbourhoods too (a point next to the plane has its mirror neighbours in the whole
    // body). The images follow the points, so a tie still goes to the real point.
    GhostPlane no_plane;
    no_plane.axis = -1;
    const std::vector<GhostPlane> mirrors = mirrors_on(plane ? *plane : no_plane);
    if (!mirrors.empty()) {
        const std::size_t real_points = points.size(), face = face_across.size();
        for (std::size_t mask = 1; mask < (std::size_t{1} << mirrors.size()); ++mask) {
            const auto image = [&](std::array<double, 3> x) {
                for (std::size_t k = 0; k < mirrors.size(); ++k) {
                    if (mask & (std::size_t{1} << k)) mirrors[k].reflect_point(x);
                }
                return x;
            };
            for (std::size_t q = 0; q < real_points; ++q) {
                measure::FieldPoint s = points[q];
                s.position = image(points[q].position);
                points.push_back(s);
                strain.push_back(strain[q]);
                heat.push_back(heat[q]);
            }
            for (std::size_t q = 0; q < face; ++q) {
                const auto x = image(face_position[q]);
                face_across.push_back(elements ? x[static_cast<std::size_t>(across)] : particle_across.first(x));
                face_value.push_back(face_value[q]);
            }
        }
    }
    const std::array<std::span<const double>, 2> fields{strain, heat};
    const std::vector<measure::LocalPeak> peaks = measure::local_peaks(points, fields, out.radius, d);
    out.plastic_strain = peaks[0];
    out.temperature = peaks[1];
    // The counts are the model's own points: each point and its images are alone or not together
    // (the images are the whole body's mirror copies), so both counts divide by the copies.
    const std::size_t copies = std::size_t{1} << mirrors.size();
    for (measure::LocalPeak* peak : {&out.plastic_strain, &out.temperature}) {
        peak->points /= copies;
        peak->alone /= copies;
    }
    out.face_roughness = measure::face_roughness(face_across, face_value);
    out.face_points = face_value.size();
}
template <class IO, class Self>
void Measures::state_fields(IO& io, Self& self) {
    io.tag("MEAS");
    io.field(self.kinetic_half_);
    io.field(self.body_kinetic_half_);
}

void Measures::write_state(StateWriter& out) const { state_fields(out, *this); }

void Measures::read_state(StateReader& in, std::size_t bodies) {
    state_fields(in, *this);
    if (body_kinetic_half_.size() != bodies) in.fail("its bodies are not the scene's");
}

}  // namespace gpa
