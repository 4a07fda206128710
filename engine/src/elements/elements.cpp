// The element solver's drivers: meshing, the colouring of the assembly, and the phases of a step
// (elements.hpp). The physics is in element_kernels.hpp and in the shared material point update
// (stress.hpp); docs/elements.md is the formulation.

#include "gpa/engine/elements.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/element_kernels.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/stress.hpp"
#include "reduce_grain.hpp"

namespace gpa {

using element::Vec2;

namespace {

constexpr std::size_t quad_grain = 256;
constexpr NodeIndex no_mesh_node = std::numeric_limits<NodeIndex>::max();
constexpr std::size_t max_planes = 8;  // ElementNodes::held and ::contact are bit masks of 8 planes

Vec2 position_of(const ElementNodes& n, std::size_t i) { return {n.position[0][i], n.position[1][i]}; }
Vec2 velocity_of(const ElementNodes& n, std::size_t i) { return {n.velocity[0][i], n.velocity[1][i]}; }

// The five nodes of quadrilateral q (corners, centre) as positions.
std::array<Vec2, 5> corners_of(const ElementMesh& m, std::size_t q) {
    std::array<Vec2, 5> x;
    for (int c = 0; c < 5; ++c) x[c] = position_of(m.nodes, m.quads.nodes[q][c]);
    return x;
}

// The four triangles of a quadrilateral (centre, corner k, corner k+1).
template <class G>
std::array<element::Triangle, 4> triangles_of(const std::array<Vec2, 5>& x) {
    std::array<element::Triangle, 4> t;
    for (int k = 0; k < 4; ++k) t[k] = element::triangle<G>(x[4], x[k], x[(k + 1) % 4]);
    return t;
}

constexpr std::array<int, 3> triangle_nodes(int k) { return {4, k, (k + 1) % 4}; }

element::Deviator deviator_of(const ElementPoints& p, std::size_t i) {
    return {p.deviatoric_stress[0][i], p.deviatoric_stress[1][i], p.deviatoric_stress[2][i], p.deviatoric_stress[3][i]};
}

std::string node_list(const ElementMesh& m, std::size_t q) {
    std::string out;
    for (int c = 0; c < 5; ++c) {
        const NodeIndex i = m.quads.nodes[q][c];
        out += fmt::format("{}{} ({:.6g}, {:.6g}) mm", c ? ", " : "", i, 1e3 * m.nodes.position[0][i], 1e3 * m.nodes.position[1][i]);
    }
    return out;
}

template <class G>
void dispatch_2d(GeometryKind g, G&& f) {
    if (g == GeometryKind::Axisymmetric) {
        f(Axisymmetric{});
    } else {
        f(PlaneStrain{});
    }
}

}  // namespace

void ElementNodes::resize(std::size_t n) {
    for (int c = 0; c < 2; ++c) {
        position[c].resize(n, 0.0);
        velocity[c].resize(n, 0.0);
        force[c].resize(n, 0.0);
    }
    mass.resize(n, 0.0);
    body.resize(n, 0);
    on_axis.resize(n, 0);
    held.resize(n, 0);
    contact.resize(n, 0);
}

void ElementPoints::resize(std::size_t n) {
    for (auto& s : deviatoric_stress) s.resize(n, 0.0);
    for (auto* f : {&pressure, &viscous_pressure, &sound_speed, &internal_energy, &temperature, &plastic_strain, &plastic_strain_rate, &damage,
                    &plastic_work, &viscous_work, &mass, &density, &volume}) {
        f->resize(n, 0.0);
    }
    failed.resize(n, 0);
    for (auto& l : velocity_gradient) l.resize(n, 0.0);
}

// --- meshing ---------------------------------------------------------------------------------

namespace {

template <class G>
void mesh_body(const Scene& scene, std::size_t b, ElementMesh& mesh) {
    const BodySpec& body = scene.bodies[b];
    const std::size_t material = material_index(scene, body.material, body.name);
    const LatticeBlock block = body_lattice(scene, b);
    const std::int64_t nx = block.last[0] - block.first[0], nz = block.last[1] - block.first[1];
    const double sx = block.spacing[0], sz = block.spacing[1];
    mesh.body_spacing[b] = std::min(sx, sz);

    std::vector<NodeIndex> corner(static_cast<std::size_t>((nx + 1) * (nz + 1)), no_mesh_node);
    const auto add_node = [&](double x, double z) {
        const std::size_t i = mesh.nodes.size();
        mesh.nodes.resize(i + 1);
        mesh.nodes.position[0][i] = x;
        mesh.nodes.position[1][i] = z;
        mesh.nodes.velocity[0][i] = body.velocity[0];
        mesh.nodes.velocity[1][i] = body.velocity[1];
        mesh.nodes.body[i] = static_cast<std::int32_t>(b);
        mesh.nodes.on_axis[i] = G::axisymmetric && x == 0.0;
        return static_cast<NodeIndex>(i);
    };
    const auto corner_node = [&](std::int64_t i, std::int64_t k) {
        NodeIndex& n = corner[static_cast<std::size_t>(k * (nx + 1) + i)];
        if (n == no_mesh_node) n = add_node(block.origin[0] + double(block.first[0] + i) * sx, block.origin[1] + double(block.first[1] + k) * sz);
        return n;
    };
    const std::size_t first_quad = mesh.quads.size();
    for (std::int64_t k = 0; k < nz; ++k) {
        for (std::int64_t i = 0; i < nx; ++i) {
            const std::array<double, 3> centre{block.origin[0] + (double(block.first[0] + i) + 0.5) * sx,
                                               block.origin[1] + (double(block.first[1] + k) + 0.5) * sz, 0.0};
            if (block.inside && !block.inside(centre)) continue;
            std::array<NodeIndex, 5> q{corner_node(i, k), corner_node(i + 1, k), corner_node(i + 1, k + 1), corner_node(i, k + 1), 0};
            q[4] = add_node(centre[0], centre[1]);
            mesh.quads.nodes.push_back(q);
            mesh.quads.body.push_back(static_cast<std::int32_t>(b));
            mesh.quads.material.push_back(static_cast<std::int32_t>(material));
        }
    }
    if (mesh.quads.size() == first_quad) {
        throw InputError(fmt::format("body \"{}\": its mesh holds no element (spacing {} m too coarse for its size)", body.name,
                                     body.spacing));
    }
}

// The state of an unloaded mesh at its node positions (elements.hpp, initialise_element_state).
template <class G>
void initialise_state(ElementMesh& mesh, const Scene& scene) {
    ElementQuads& quads = mesh.quads;
    const std::size_t n = quads.size();
    quads.mass.assign(n, 0.0);
    quads.volume.assign(n, 0.0);
    quads.length.assign(n, 0.0);
    quads.rate.assign(n, 0.0);
    mesh.points.resize(0);
    mesh.points.resize(4 * n);
    std::fill(mesh.nodes.mass.begin(), mesh.nodes.mass.end(), 0.0);
    // Each body's initial stress: its deviator into every triangle, its mean stress into an
    // initial compression (bodies.hpp, as for particles).
    std::vector<double> density(scene.bodies.size(), 0.0);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (scene.bodies[b].discretisation != Discretisation::Elements) continue;
        const auto& body = scene.bodies[b];
        const auto& mat = scene.materials.at(material_index(scene, body.material, body.name));
        const auto& sig = body.initial_stress;
        density[b] = mat.density / (1.0 + initial_volumetric_strain(mat, -(sig[0] + sig[1] + sig[3]) / 3.0, body.name));
    }
    for (std::size_t q = 0; q < n; ++q) {
        const std::size_t b = static_cast<std::size_t>(quads.body[q]);
        const BodySpec& body = scene.bodies.at(b);
        const materials::Material& mat = scene.materials.at(static_cast<std::size_t>(quads.material[q]));
        const auto& sig = body.initial_stress;
        const double mean = (sig[0] + sig[1] + sig[3]) / 3.0;
        const InitialPointState start = initial_material_point(mat, density[b]);
        const auto x = corners_of(mesh, q);
        const auto t = triangles_of<G>(x);
        for (int k = 0; k < 4; ++k) {
            const std::size_t p = 4 * q + static_cast<std::size_t>(k);
            if (!(t[k].area > 0.0) || !(t[k].volume > 0.0)) {
                throw InputError(fmt::format("body \"{}\": element {} (triangle {}) has no positive area at the start; its "
                                             "nodes: {}",
                                             body.name, q, k, node_list(mesh, q)));
            }
            const double m = density[b] * t[k].volume;
            mesh.points.mass[p] = m;
            mesh.points.density[p] = density[b];
            mesh.points.volume[p] = t[k].volume;
            mesh.points.deviatoric_stress[0][p] = sig[0] - mean;
            mesh.points.deviatoric_stress[1][p] = sig[1] - mean;
            mesh.points.deviatoric_stress[2][p] = sig[2];
            mesh.points.deviatoric_stress[3][p] = sig[3] - mean;
            mesh.points.temperature[p] = mat.room_temperature;
            mesh.points.pressure[p] = start.pressure;
            mesh.points.sound_speed[p] = start.sound_speed;
            quads.mass[q] += m;
            quads.volume[q] += t[k].volume;
            // E4: lumped (row-sum) nodal masses.
            const auto corners = triangle_nodes(k);
            const auto share = element::lumped_masses<G>(t[k], {x[corners[0]], x[corners[1]], x[corners[2]]}, m);
            for (int a = 0; a < 3; ++a) mesh.nodes.mass[quads.nodes[q][corners[a]]] += share[a];
        }
        quads.length[q] = element::stable_length(x, t);
    }
}

}  // namespace

void initialise_element_state(ElementMesh& mesh, const Scene& scene) {
    dispatch_2d(mesh.geometry, [&](auto g) { initialise_state<decltype(g)>(mesh, scene); });
}

namespace {

// Edges of quadrilaterals that no other quadrilateral shares (the boundary of each body's mesh).
std::vector<std::array<NodeIndex, 2>> boundary_edges(const ElementQuads& quads) {
    std::map<std::pair<NodeIndex, NodeIndex>, int> count;
    for (const auto& q : quads.nodes) {
        for (int k = 0; k < 4; ++k) {
            const NodeIndex a = q[k], b = q[(k + 1) % 4];
            ++count[{std::min(a, b), std::max(a, b)}];
        }
    }
    std::vector<std::array<NodeIndex, 2>> out;
    for (const auto& q : quads.nodes) {
        for (int k = 0; k < 4; ++k) {
            const NodeIndex a = q[k], b = q[(k + 1) % 4];
            if (count[{std::min(a, b), std::max(a, b)}] == 1) out.push_back({a, b});
        }
    }
    return out;
}

}  // namespace

ElementMesh mesh_element_bodies(const Scene& scene) {
    ElementMesh mesh;
    mesh.geometry = scene.geometry;
    mesh.body_spacing.assign(scene.bodies.size(), 0.0);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (scene.bodies[b].discretisation != Discretisation::Elements) continue;
        if (dimension_of(scene.geometry) != 2) {
            throw InputError(fmt::format("body \"{}\": elements are 2D only (axisymmetric or plane strain)", scene.bodies[b].name));
        }
        dispatch_2d(scene.geometry, [&](auto g) { mesh_body<decltype(g)>(scene, b, mesh); });
    }
    mesh.boundary_edges = boundary_edges(mesh.quads);
    initialise_element_state(mesh, scene);
    return mesh;
}

ElementOptions element_options(const Scene& scene) {
    ElementOptions o;
    // Bond viscosity is a particle pair's; element bodies take the nodal form (Eq. 36) whenever
    // the scene asks for any artificial viscosity.
    o.viscosity = scene.solver.viscosity != ViscosityKind::None;
    o.viscosity_linear = scene.solver.viscosity_linear;
    o.viscosity_quadratic = scene.solver.viscosity_quadratic;
    o.failure = scene.solver.failure;
    return o;
}

// --- colouring -------------------------------------------------------------------------------

ScatterPlan make_element_plan(const ElementQuads& quads, std::size_t node_count, ScatterScheme scheme) {
    ScatterPlan plan;
    plan.scheme = scheme == ScatterScheme::Serial ? ScatterScheme::Serial : ScatterScheme::Graph;
    const std::size_t n = quads.size();
    if (plan.scheme == ScatterScheme::Serial) {
        plan.centres.resize(n);
        std::iota(plan.centres.begin(), plan.centres.end(), NodeIndex{0});
        plan.colour_offsets = {0, 1};
        plan.group_offsets = {0, n};
        return plan;
    }
    // Node -> quadrilaterals, then a greedy colouring in quadrilateral order.
    std::vector<std::size_t> offsets(node_count + 1, 0);
    for (const auto& q : quads.nodes) {
        for (NodeIndex i : q) ++offsets[i + 1];
    }
    std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
    std::vector<NodeIndex> incident(offsets.back());
    std::vector<std::size_t> fill(offsets.begin(), offsets.end() - 1);
    for (std::size_t q = 0; q < n; ++q) {
        for (NodeIndex i : quads.nodes[q]) incident[fill[i]++] = static_cast<NodeIndex>(q);
    }
    std::vector<int> colour(n, -1);
    int colours = 0;
    std::vector<std::size_t> used;
    for (std::size_t q = 0; q < n; ++q) {
        used.clear();
        for (NodeIndex i : quads.nodes[q]) {
            for (std::size_t e = offsets[i]; e < offsets[i + 1]; ++e) {
                const int c = colour[incident[e]];
                if (c >= 0) used.push_back(static_cast<std::size_t>(c));
            }
        }
        int c = 0;
        while (std::find(used.begin(), used.end(), static_cast<std::size_t>(c)) != used.end()) ++c;
        colour[q] = c;
        colours = std::max(colours, c + 1);
    }
    constexpr std::size_t group_size = 64;  // any size gives the same sums: quadrilaterals of one colour share no node
    plan.colour_offsets.assign(1, 0);
    plan.group_offsets.assign(1, 0);
    for (int c = 0; c < colours; ++c) {
        std::size_t in_group = 0;
        for (std::size_t q = 0; q < n; ++q) {
            if (colour[q] != c) continue;
            plan.centres.push_back(static_cast<NodeIndex>(q));
            if (++in_group == group_size) {
                plan.group_offsets.push_back(plan.centres.size());
                in_group = 0;
            }
        }
        if (in_group > 0) plan.group_offsets.push_back(plan.centres.size());
        plan.colour_offsets.push_back(plan.group_offsets.size() - 1);
    }
    return plan;
}

bool element_plan_is_conflict_free(const ScatterPlan& plan, const ElementQuads& quads, std::size_t node_count) {
    std::vector<int> seen(quads.size(), 0);
    for (NodeIndex q : plan.centres) {
        if (q >= quads.size() || seen[q]++) return false;
    }
    if (std::any_of(seen.begin(), seen.end(), [](int s) { return s != 1; })) return false;
    if (plan.scheme == ScatterScheme::Serial) return plan.groups() == 1;
    std::vector<std::size_t> writer(node_count, std::numeric_limits<std::size_t>::max());
    for (std::size_t c = 0; c < plan.colours(); ++c) {
        for (std::size_t g = plan.colour_offsets[c]; g < plan.colour_offsets[c + 1]; ++g) {
            for (NodeIndex q : plan.group(g)) {
                for (NodeIndex i : quads.nodes[q]) {
                    // A node written by another group of this colour (tagged colour c, group g) is a conflict.
                    const std::size_t tag = c * plan.groups() + g;
                    if (writer[i] != std::numeric_limits<std::size_t>::max() && writer[i] / plan.groups() == c &&
                        writer[i] != tag) {
                        return false;
                    }
                    writer[i] = tag;
                }
            }
        }
    }
    return true;
}

// --- the part ------------------------------------------------------------------------------

ElementPart::ElementPart(const Scene& scene, ElementMesh mesh, ElementOptions options)
    : scene_(scene), mesh_(std::move(mesh)), options_(options) {
    if (scene_.planes.size() > max_planes) {
        throw InputError(fmt::format("a scene with element bodies takes at most {} planes (it has {})", max_planes,
                                     scene_.planes.size()));
    }
    for (const auto& m : scene_.materials) materials::validate(m);
    plan_ = make_element_plan(mesh_.quads, mesh_.nodes.size(), options_.scatter);
    groups_.assign(scene_.materials.size(), {});
    for (std::size_t q = 0; q < mesh_.quads.size(); ++q) groups_[static_cast<std::size_t>(mesh_.quads.material[q])].push_back(q);
    for (std::size_t k = 0; k < scene_.planes.size(); ++k) {
        if (scene_.planes[k].kind == PlaneKind::Rigid) rigid_planes_.push_back(k);
    }
    reaction_.assign(rigid_planes_.size(), 0.0);
    impulse_.assign(rigid_planes_.size(), 0.0);
    // Nodes that start on a symmetry plane or on a rigid plane without lift-off stay on it.
    ElementNodes& n = mesh_.nodes;
    for (std::size_t i = 0; i < n.size(); ++i) {
        for (std::size_t k = 0; k < scene_.planes.size(); ++k) {
            const PlaneSpec& p = scene_.planes[k];
            const double gap = p.side * (n.position[p.axis][i] - p.position);
            const double tolerance = face_tolerance(i);
            if (gap > tolerance) continue;
            n.contact[i] |= std::uint8_t(1u << k);
            if (p.kind == PlaneKind::Symmetry || !p.lift_off) n.held[i] |= std::uint8_t(1u << k);
        }
    }
}

ElementPart::~ElementPart() = default;

namespace {

// The arrays of the element state a checkpoint carries, in one order for writing and reading.
template <class Mesh, class F>
void for_each_state_array(Mesh& m, F&& f) {
    for (int c = 0; c < 2; ++c) {
        f(m.nodes.position[c]);
        f(m.nodes.velocity[c]);
        f(m.nodes.force[c]);
    }
    f(m.nodes.held);
    f(m.nodes.contact);
    f(m.quads.volume);
    f(m.quads.length);
    f(m.quads.rate);
    for (auto& s : m.points.deviatoric_stress) f(s);
    f(m.points.pressure);
    f(m.points.viscous_pressure);
    f(m.points.sound_speed);
    f(m.points.internal_energy);
    f(m.points.temperature);
    f(m.points.plastic_strain);
    f(m.points.plastic_strain_rate);
    f(m.points.damage);
    f(m.points.plastic_work);
    f(m.points.viscous_work);
    f(m.points.failed);
    f(m.points.density);
    f(m.points.volume);
    for (auto& l : m.points.velocity_gradient) f(l);
}

}  // namespace

void ElementPart::write_state(StateWriter& out) const {
    out.tag("ELEM");
    out.value<std::uint64_t>(mesh_.nodes.size());
    out.value<std::uint64_t>(mesh_.quads.size());
    out.value<std::uint64_t>(mesh_.points.size());
    for_each_state_array(mesh_, [&](const auto& v) { out.array(v); });
    out.array(reaction_);
    out.array(impulse_);
    out.value<double>(boundary_work_);
}

void ElementPart::read_state(StateReader& in) {
    in.tag("ELEM");
    const auto nodes = in.value<std::uint64_t>();
    const auto quads = in.value<std::uint64_t>();
    const auto points = in.value<std::uint64_t>();
    if (nodes != mesh_.nodes.size() || quads != mesh_.quads.size() || points != mesh_.points.size()) {
        in.fail(fmt::format("its element mesh has {} nodes, {} quadrilaterals and {} triangles; this scene's has {}, {} and {}", nodes,
                            quads, points, mesh_.nodes.size(), mesh_.quads.size(), mesh_.points.size()));
    }
    for_each_state_array(mesh_, [&](auto& v) {
        const std::size_t expected = v.size();
        in.array(v);
        if (v.size() != expected) in.fail("an element array has another length than this scene's mesh (a damaged checkpoint)");
    });
    in.array(reaction_);
    in.array(impulse_);
    if (reaction_.size() != rigid_planes_.size() || impulse_.size() != rigid_planes_.size()) in.fail("its planes are not the scene's");
    boundary_work_ = in.value<double>();
}

double ElementPart::face_tolerance(std::size_t node) const {
    return measure::element_face_tolerance(mesh_.body_spacing[static_cast<std::size_t>(mesh_.nodes.body[node])]);
}

void ElementPart::move(double dt) {
    ElementNodes& n = mesh_.nodes;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < 2; ++c) {
            double* x = n.position[c].data();
            const double* v = n.velocity[c].data();
            for (std::size_t i = r.begin(); i != r.end(); ++i) x[i] = leapfrog_position(x[i], v[i], dt);
        }
    });
}

void ElementPart::update_stress(double dt, std::size_t step, double time) {
    dispatch_2d(mesh_.geometry, [&](auto g) { update_stress_in<decltype(g)>(dt, step, time); });
}

template <class G>
void ElementPart::update_stress_in(double dt, std::size_t step, double time) {
    ElementMesh& m = mesh_;
    ElementPoints& p = m.points;
    const MaterialPointFields fields = material_point_fields(p, 4);
    FirstPointFailure inverted, failed;  // indexed by triangle
    for (std::size_t mat = 0; mat < groups_.size(); ++mat) {
        const materials::PointModel model(scene_.materials[mat]);  // the material's models, chosen once for its group
        const auto& members = groups_[mat];
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, members.size(), quad_grain), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t j = r.begin(); j != r.end(); ++j) {
                const std::size_t q = members[j];
                const auto& ids = m.quads.nodes[q];
                std::array<Vec2, 5> x, v, mid;
                for (int c = 0; c < 5; ++c) {
                    x[c] = position_of(m.nodes, ids[c]);
                    v[c] = velocity_of(m.nodes, ids[c]);
                    mid[c] = x[c] - 0.5 * dt * v[c];  // x^{n+1/2}: the strain rates of the step on the mid-step geometry
                }
                const auto now = triangles_of<G>(x);
                const auto half = triangles_of<G>(mid);
                double volume = 0.0;
                bool ok = true;
                for (int k = 0; k < 4; ++k) {
                    if (!(now[k].area > 0.0) || !(now[k].volume > 0.0) || !(half[k].area > 0.0)) {
                        inverted.record(4 * q + static_cast<std::size_t>(k),
                                        fmt::format("its area would be {:.3g} mm^2", 1e6 * now[k].area));
                        ok = false;
                    }
                    volume += now[k].volume;
                }
                if (!ok) continue;
                // E7: the quadrilateral's density and mean volumetric rate over the step; E8, E9: its
                // width, the length of the viscosity and of the time step.
                const double volume_old = m.quads.volume[q];
                const double quad_rate = element::mean_dilatation_rate(volume_old, volume, dt);
                const double h = element::stable_length(x, now);
                double most_compressive = quad_rate;
                for (int k = 0; k < 4; ++k) {
                    const std::size_t i = 4 * q + static_cast<std::size_t>(k);
                    const auto corners = triangle_nodes(k);
                    const element::Kinematics kin =
                        element::kinematics<G>(half[k], {v[corners[0]], v[corners[1]], v[corners[2]]});
                    double density_old, density_new, rate;
                    if (options_.mean_dilatation) {
                        density_old = m.quads.mass[q] / volume_old;
                        density_new = m.quads.mass[q] / volume;
                        rate = quad_rate;
                    } else {
                        density_old = p.mass[i] / p.volume[i];
                        density_new = p.mass[i] / now[k].volume;
                        rate = element::mean_dilatation_rate(p.volume[i], now[k].volume, dt);
                        most_compressive = k == 0 ? rate : std::min(most_compressive, rate);
                    }
                    // Eq. 36 in the element's terms (E9): Q = C_L rho c h |eps_v_dot| + C_Q rho h^2 eps_v_dot^2
                    // in compression.
                    const double q_new = options_.viscosity ? nodal_viscosity(rate, density_new, p.sound_speed[i], h,
                                                                              options_.viscosity_linear,
                                                                              options_.viscosity_quadratic)
                                                            : 0.0;
                    materials::PointIncrement inc;
                    const auto& l = kin.velocity_gradient;
                    inc.velocity_gradient << l(0, 0), l(0, 1), 0.0, l(1, 0), l(1, 1), 0.0, 0.0, 0.0, kin.hoop_rate;
                    inc.dt = dt;
                    inc.density_old = density_old;
                    inc.density_new = density_new;
                    inc.viscous_pressure_old = p.viscous_pressure[i];
                    inc.viscous_pressure_new = q_new;
                    inc.failure_enabled = options_.failure;
                    const materials::PointResult result = advance_material_point<2>(fields, i, model, inc);
                    if (result.fault != materials::PointFault::none) {
                        failed.record(i, point_fault_message<2>(fields, i, model, inc, result));
                        continue;
                    }
                    p.viscous_pressure[i] = q_new;
                    p.density[i] = density_new;
                    p.volume[i] = now[k].volume;
                    p.velocity_gradient[0][i] = l(0, 0);
                    p.velocity_gradient[1][i] = l(0, 1);
                    p.velocity_gradient[2][i] = l(1, 0);
                    p.velocity_gradient[3][i] = l(1, 1);
                    p.velocity_gradient[4][i] = kin.hoop_rate;
                }
                m.quads.volume[q] = volume;
                m.quads.length[q] = h;
                m.quads.rate[q] = most_compressive;
            }
        });
    }
    const auto where = [&](std::size_t i) {
        const std::size_t q = i / 4;
        return fmt::format("element {} (triangle {} of its four) of body \"{}\" at step {}, t = {:.6g} us", q, i % 4,
                           scene_.bodies.at(static_cast<std::size_t>(m.quads.body[q])).name, step, 1e6 * time);
    };
    if (inverted.any()) {
        const std::size_t q = inverted.index() / 4;
        throw NumericalError(fmt::format(
            "{} inverted: {}; its nodes (corners, then centre; element and node numbers are the `element` and `id` arrays of elements_*.vtu): {}. The mesh has tangled there; remedies: a smaller "
            "solver.cfl, a finer or more even mesh (spacing, spacing_z), more artificial viscosity "
            "(solver.viscosity_linear, solver.viscosity_quadratic), or particles (discretisation = \"particles\") for a "
            "body that deforms this much",
            where(inverted.index()), inverted.message(), node_list(m, q)));
    }
    if (failed.any()) {
        const std::size_t i = failed.index();
        throw NumericalError(fmt::format("{}, material \"{}\": {}; its nodes (element and node numbers are the `element` and `id` arrays of elements_*.vtu): {}", where(i),
                                         scene_.materials.at(static_cast<std::size_t>(m.quads.material[i / 4])).name,
                                         failed.message(), node_list(m, i / 4)));
    }
}

double ElementPart::stable_time_step() const {
    const ElementMesh& m = mesh_;
    const ElementPoints& p = m.points;
    const auto local = [&](std::size_t q) {
        double best = std::numeric_limits<double>::infinity();
        const double l = m.quads.length[q];
        for (std::size_t i = 4 * q; i < 4 * q + 4; ++i) {
            // E9: the viscosity's damping with the sound speed.
            const double zeta = options_.viscosity ? element::viscous_speed(m.quads.rate[q], p.sound_speed[i], l,
                                                                            options_.viscosity_linear,
                                                                            options_.viscosity_quadratic)
                                                   : 0.0;
            const double dt = element::stable_time_step(l, p.sound_speed[i], zeta);
            if (std::isnan(dt)) return dt;
            best = std::min(best, dt);
        }
        return best;
    };
    const double limit = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, m.quads.size(), reduce_grain), std::numeric_limits<double>::infinity(),
        [&](const tbb::blocked_range<std::size_t>& r, double best) {
            for (std::size_t q = r.begin(); q != r.end(); ++q) {
                const double dt = local(q);
                if (std::isnan(dt)) return dt;
                best = std::min(best, dt);
            }
            return best;
        },
        [](double a, double b) { return std::isnan(a) || std::isnan(b) ? std::nan("") : std::min(a, b); });
    if (std::isnan(limit)) {
        for (std::size_t q = 0; q < m.quads.size(); ++q) {
            if (std::isnan(local(q))) {
                throw NumericalError(fmt::format("element {} of body \"{}\": its stable time step is not a number (length {} m, "
                                                 "sound speeds {}, {}, {}, {} m/s); its nodes: {}",
                                                 q, scene_.bodies.at(static_cast<std::size_t>(m.quads.body[q])).name,
                                                 m.quads.length[q], p.sound_speed[4 * q], p.sound_speed[4 * q + 1],
                                                 p.sound_speed[4 * q + 2], p.sound_speed[4 * q + 3], node_list(m, q)));
            }
        }
    }
    return limit;
}

void ElementPart::compute_forces() {
    dispatch_2d(mesh_.geometry, [&](auto g) { compute_forces_in<decltype(g)>(); });
}

template <class G>
void ElementPart::compute_forces_in() {
    ElementMesh& m = mesh_;
    ElementNodes& n = m.nodes;
    const ElementPoints& p = m.points;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n.size(), 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < 2; ++c) std::fill(n.force[c].begin() + r.begin(), n.force[c].begin() + r.end(), 0.0);
    });
    const auto quad_forces = [&](std::size_t q) {
        const auto x = corners_of(m, q);
        const auto t = triangles_of<G>(x);
        std::array<Vec2, 5> f;
        for (auto& v : f) v.setZero();
        // E7 with E5: the quadrilateral's mean pressure sum_t (M_t / M_q)(P_t + Q_t) acts on the
        // volume of each triangle, each deviator with the weight M_t / rho_q (the material's volume
        // of the triangle, the one its energy is booked with). Without mean dilatation: each
        // triangle's own P + Q on its own volume.
        double mean_pressure = 0.0;
        if (options_.mean_dilatation) {
            for (std::size_t i = 4 * q; i < 4 * q + 4; ++i) {
                mean_pressure += p.mass[i] / m.quads.mass[q] * (p.pressure[i] + p.viscous_pressure[i]);
            }
        }
        for (int k = 0; k < 4; ++k) {
            const std::size_t i = 4 * q + static_cast<std::size_t>(k);
            const double weight = options_.mean_dilatation ? p.mass[i] / p.density[i] : t[k].volume;
            const double pressure = options_.mean_dilatation ? mean_pressure : p.pressure[i] + p.viscous_pressure[i];
            const auto ft = element::triangle_forces<G>(t[k], deviator_of(p, i), weight, pressure);
            const auto corners = triangle_nodes(k);
            for (int a = 0; a < 3; ++a) f[corners[a]] += ft[a];
        }
        for (int c = 0; c < 5; ++c) {
            const NodeIndex i = m.quads.nodes[q][c];
            n.force[0][i] += f[c].x();
            n.force[1][i] += f[c].y();
        }
    };
    // Colours one after another, the groups of a colour in parallel: no two quadrilaterals of a
    // colour share a node, so each node's contributions arrive in colour order on any thread count.
    for (std::size_t c = 0; c < plan_.colours(); ++c) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(plan_.colour_offsets[c], plan_.colour_offsets[c + 1], 1),
                          [&](const tbb::blocked_range<std::size_t>& r) {
                              for (std::size_t g = r.begin(); g != r.end(); ++g) {
                                  for (NodeIndex q : plan_.group(g)) quad_forces(q);
                              }
                          });
    }
}

namespace {

struct ConstraintSums {
    std::array<double, max_planes> reaction{};  // sum of M dv_normal / dt_avg per scene plane
    double work = 0.0;                          // work of the constraint forces, J

    ConstraintSums& operator+=(const ConstraintSums& o) {
        for (std::size_t k = 0; k < max_planes; ++k) reaction[k] += o.reaction[k];
        work += o.work;
        return *this;
    }
};

}  // namespace

void ElementPart::integrate(double dt_avg, double dt_next) {
    ElementNodes& n = mesh_.nodes;
    const auto& planes = scene_.planes;
    const ConstraintSums s = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, n.size(), reduce_grain), ConstraintSums{},
        [&](const tbb::blocked_range<std::size_t>& r, ConstraintSums acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double mass = n.mass[i];
                std::array<double, 2> v_old{n.velocity[0][i], n.velocity[1][i]};
                std::array<double, 2> v{leapfrog_velocity(v_old[0], n.force[0][i], mass, dt_avg), leapfrog_velocity(v_old[1], n.force[1][i], mass, dt_avg)};
                // The axis: x stays 0 (the radial force on an axis node does no work, since u = 0).
                if (n.on_axis[i]) v[0] = 0.0;
                n.contact[i] = 0;
                for (std::size_t k = 0; k < planes.size(); ++k) {
                    const PlaneSpec& plane = planes[k];
                    const int a = plane.axis;
                    const double gap = plane.side * (n.position[a][i] - plane.position);
                    const bool held = (n.held[i] >> k) & 1u;
                    // Where the node would be after the next step, and the normal velocity that
                    // puts it on the plane instead.
                    const double predicted = gap + plane.side * dt_next * v[a];
                    if (!held && !(predicted < 0.0)) continue;
                    const double target = -plane.side * gap / dt_next;
                    const double change = target - v[a];
                    v[a] = target;
                    // The constraint's force M dv / dt_avg does the leapfrog work
                    // F . (v^{n+1/2} + v^{n+3/2}) / 2 dt_avg (docs/elements.md, "Contact").
                    acc.reaction[k] += plane.side * mass * change / dt_avg;
                    acc.work += mass * change * 0.5 * (v_old[a] + target);
                    n.contact[i] |= std::uint8_t(1u << k);
                    if (plane.kind == PlaneKind::Rigid && !plane.lift_off) n.held[i] |= std::uint8_t(1u << k);
                }
                n.velocity[0][i] = v[0];
                n.velocity[1][i] = v[1];
            }
            return acc;
        },
        [](ConstraintSums x, const ConstraintSums& y) { return x += y; });
    boundary_work_ -= s.work;
    for (std::size_t k = 0; k < rigid_planes_.size(); ++k) {
        reaction_[k] = s.reaction[rigid_planes_[k]];
        impulse_[k] += reaction_[k] * dt_avg;
    }
}

ElementPart::Sums ElementPart::sums() const {
    const ElementNodes& n = mesh_.nodes;
    const ElementPoints& p = mesh_.points;
    Sums nodes = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, n.size(), reduce_grain), Sums{},
        [&](const tbb::blocked_range<std::size_t>& r, Sums acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                const double vx = n.velocity[0][i], vz = n.velocity[1][i];
                acc.kinetic += 0.5 * n.mass[i] * (vx * vx + vz * vz);
                acc.momentum[0] += n.mass[i] * vx;
                acc.momentum[1] += n.mass[i] * vz;
            }
            return acc;
        },
        [](Sums x, const Sums& y) {
            x.kinetic += y.kinetic;
            x.momentum[0] += y.momentum[0];
            x.momentum[1] += y.momentum[1];
            return x;
        });
    const Sums points = tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, p.size(), reduce_grain), Sums{},
        [&](const tbb::blocked_range<std::size_t>& r, Sums acc) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                acc.internal += p.mass[i] * p.internal_energy[i];
                acc.plastic += p.mass[i] * p.plastic_work[i];
                acc.viscous += p.mass[i] * p.viscous_work[i];
            }
            return acc;
        },
        [](Sums x, const Sums& y) {
            x.internal += y.internal;
            x.plastic += y.plastic;
            x.viscous += y.viscous;
            return x;
        });
    nodes.internal = points.internal;
    nodes.plastic = points.plastic;
    nodes.viscous = points.viscous;
    return nodes;
}

}  // namespace gpa
