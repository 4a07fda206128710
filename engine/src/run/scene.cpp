#include "gpa/engine/scene.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <exception>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/prescribed.hpp"
#include "gpa/engine/solver_options.hpp"

// The rules a scene must keep, for a scene read from a file and one built in code alike.
// Messages use the scene file's key names (solver.cfl, body "bar" (body[0]).radius), which are
// also the names of the Scene's fields.

namespace gpa {

namespace {

[[noreturn]] void fail(std::string message) { throw InputError(std::move(message)); }

bool finite(double v) { return std::isfinite(v); }

std::string body_label(const BodySpec& b, std::size_t i) {
    return b.name.empty() ? fmt::format("body[{}]", i) : fmt::format("body \"{}\" (body[{}])", b.name, i);
}

std::string plane_label(const PlaneSpec& p, std::size_t i) {
    return p.name.empty() ? fmt::format("plane[{}]", i) : fmt::format("plane \"{}\" (plane[{}])", p.name, i);
}

std::string material_label(const materials::Material& m, std::size_t i) {
    return m.name.empty() ? fmt::format("material[{}]", i) : fmt::format("material \"{}\" (material[{}])", m.name, i);
}

bool same_name(std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
}

// How far a body may reach past a plane at `position` and still be on its side (touching it). For
// imported nodes a quarter of their median diameter: their extent is that of cubes (squares) of
// side d0 about them, which need not be the cells they stand for (a cell of dx by dz, dx != dz, is
// not the square of side sqrt(dx dz)); their nodes then still lie a quarter diameter or more on the
// plane's side.
double plane_tolerance(const BodySpec& b, double position) {
    if (b.shape == ShapeKind::Nodes) return 0.25 * nominal_spacing(b);
    return 1e-9 * std::max(b.spacing, std::abs(position));
}

bool known_shape(ShapeKind s) {
    switch (s) {
        case ShapeKind::Cylinder:
        case ShapeKind::Plate:
        case ShapeKind::Rectangle:
        case ShapeKind::Box:
        case ShapeKind::Sphere:
        case ShapeKind::Surface:
        case ShapeKind::Nodes: return true;
    }
    return false;
}

// Whether a body's shape is known: a surface before its file is read is not (a scene reader checks
// the scene before it reads the files; the checks of its extent wait for the Simulation's).
bool shape_known(const BodySpec& b) {
    if (b.shape == ShapeKind::Surface) return b.surface != nullptr;
    if (b.shape == ShapeKind::Nodes) return b.node_set != nullptr;
    return true;
}

// The interval an unrotated body occupies along an axis (before any node is placed).
std::pair<double, double> axis_extent(const BodySpec& b, GeometryKind g, int axis) {
    const int dim = dimension_of(g);
    const bool axial = axis == dim - 1;  // z
    const double o = b.origin[static_cast<std::size_t>(axis)];
    switch (b.shape) {
        case ShapeKind::Cylinder:
        case ShapeKind::Plate:
            if (axial) return {o, o + b.length};
            if (g == GeometryKind::Axisymmetric) return {0.0, b.radius};
            return {o - b.radius, o + b.radius};
        case ShapeKind::Sphere:
            if (g == GeometryKind::Axisymmetric && axis == 0) return {0.0, b.radius};
            return {o - b.radius, o + b.radius};
        case ShapeKind::Rectangle:
        case ShapeKind::Box: return {o, o + b.size[static_cast<std::size_t>(axis)]};
        case ShapeKind::Surface: {
            if (!b.surface) return {o, o};
            return {o + b.surface->lower()[static_cast<std::size_t>(axis)], o + b.surface->upper()[static_cast<std::size_t>(axis)]};
        }
        case ShapeKind::Nodes: {
            if (!b.node_set) return {o, o};
            return {o + b.node_set->lower()[static_cast<std::size_t>(axis)], o + b.node_set->upper()[static_cast<std::size_t>(axis)]};
        }
    }
    return {o, o};
}

// The point of the body's shape as described (unrotated) that its rotation takes to p: origin +
// R^T (p - origin) (BodySpec::rotation); p itself for an unrotated body.
std::array<double, 3> to_body_frame(const BodySpec& b, const std::array<double, 3>& p) {
    if (is_identity(b.rotation)) return p;
    const auto& o = b.origin;
    const auto q = turn_back(b.rotation, {p[0] - o[0], p[1] - o[1], p[2] - o[2]});
    return {o[0] + q[0], o[1] + q[1], o[2] + q[2]};
}

// The interval of n . x over body b (n a unit vector in scene components): exact for an unrotated
// body along an axis (axis_extent); otherwise the support of the shape as described, along n turned
// into the body's frame, n_b = R^T n, with n . x = n . o + n_b . (x_b - o): a cylinder's (its nose
// within it) and a sphere's exactly, a box's, a surface's or imported nodes' from their box.
std::pair<double, double> extent_along(const BodySpec& b, GeometryKind g, const std::array<double, 3>& n) {
    const int dim = dimension_of(g);
    if (is_identity(b.rotation)) {
        if (const auto a = aligned_axis(n, dim)) {
            const auto [lo, hi] = axis_extent(b, g, a->axis);
            return a->sign > 0 ? std::pair{lo, hi} : std::pair{-hi, -lo};
        }
    }
    const auto nb = turn_back(b.rotation, n);
    const auto& o = b.origin;
    double at_origin = 0.0;
    for (int c = 0; c < dim; ++c) at_origin += n[c] * o[c];
    double lo = 0.0, hi = 0.0;  // of n_b . (x_b - o)
    const auto add_interval = [&](double a, double z) {  // one term ranging over [min(a, z), max(a, z)]
        lo += std::min(a, z);
        hi += std::max(a, z);
    };
    switch (b.shape) {
        case ShapeKind::Cylinder:
        case ShapeKind::Plate: {
            const double along = nb[dim - 1];
            const double across = dim == 3 ? std::hypot(nb[0], nb[1]) : std::abs(nb[0]);
            add_interval(0.0, b.length * along);
            add_interval(-b.radius * across, b.radius * across);
            break;
        }
        case ShapeKind::Sphere: add_interval(-b.radius, b.radius); break;
        case ShapeKind::Rectangle:
        case ShapeKind::Box:
            for (int c = 0; c < dim; ++c) add_interval(0.0, nb[c] * b.size[c]);
            break;
        case ShapeKind::Surface:
        case ShapeKind::Nodes: {
            std::array<double, 3> lower{}, upper{};
            if (b.shape == ShapeKind::Surface && b.surface) lower = b.surface->lower(), upper = b.surface->upper();
            if (b.shape == ShapeKind::Nodes && b.node_set) lower = b.node_set->lower(), upper = b.node_set->upper();
            // The shape's coordinates are offsets from the origin: x_b - o lies in [lower, upper].
            for (int c = 0; c < dim; ++c) add_interval(nb[c] * lower[c], nb[c] * upper[c]);
            break;
        }
    }
    return {at_origin + lo, at_origin + hi};
}

// Where imported node x (its file's coordinates, metres) of body b is placed: origin + R x
// (bodies.cpp, add_imported_nodes).
std::array<double, 3> imported_node_at(const BodySpec& b, const std::array<double, 3>& x, int dim) {
    const std::array<double, 3> given{x[0], x[1], dim == 3 ? x[2] : 0.0};
    const auto turned = is_identity(b.rotation) ? given : turn(b.rotation, given);
    return {turned[0] + b.origin[0], turned[1] + b.origin[1], dim == 3 ? turned[2] + b.origin[2] : 0.0};
}

// The interval a body occupies along an axis (before any node is placed).
std::pair<double, double> extent(const BodySpec& b, GeometryKind g, int axis) {
    if (is_identity(b.rotation)) return axis_extent(b, g, axis);
    std::array<double, 3> e{0, 0, 0};
    e[static_cast<std::size_t>(axis)] = 1.0;
    return extent_along(b, g, e);
}

// Whether point p (scene coordinates: (x, z) in 2D, (x, y, z) in 3D) lies strictly inside body b's
// shape as written in the scene (the shape its lattice fills: a node belongs to a body when its cell
// centre is inside, docs/scene-format.md), turned by its rotation.
bool inside_shape(const BodySpec& b, GeometryKind g, const std::array<double, 3>& at) {
    const int dim = dimension_of(g);
    const std::array<double, 3> p = to_body_frame(b, at);
    const double z = p[static_cast<std::size_t>(dim - 1)];
    const auto& o = b.origin;
    switch (b.shape) {
        case ShapeKind::Cylinder:
        case ShapeKind::Plate: {
            const double z0 = o[static_cast<std::size_t>(dim - 1)];
            if (!(z > z0 && z < z0 + b.length)) return false;
            const double r = cylinder_radius_at(b, z - z0);
            if (dim == 2) return g == GeometryKind::Axisymmetric ? p[0] < r : std::abs(p[0] - o[0]) < r;
            return (p[0] - o[0]) * (p[0] - o[0]) + (p[1] - o[1]) * (p[1] - o[1]) < r * r;
        }
        case ShapeKind::Sphere: {
            double q = 0.0;
            for (int k = 0; k < dim; ++k) {
                const double c = g == GeometryKind::Axisymmetric && k == 0 ? 0.0 : o[static_cast<std::size_t>(k)];
                q += (p[static_cast<std::size_t>(k)] - c) * (p[static_cast<std::size_t>(k)] - c);
            }
            return q < b.radius * b.radius && q >= b.inner_radius * b.inner_radius;
        }
        case ShapeKind::Rectangle:
        case ShapeKind::Box:
            for (int k = 0; k < dim; ++k) {
                const auto c = static_cast<std::size_t>(k);
                if (!(p[c] > o[c] && p[c] < o[c] + b.size[c])) return false;
            }
            return true;
        case ShapeKind::Surface:
            return b.surface && b.surface->inside({p[0] - o[0], p[1] - o[1], p[2] - o[2]});
        case ShapeKind::Nodes:
            return b.node_set && b.node_set->covers({p[0] - o[0], p[1] - o[1], dim == 3 ? p[2] - o[2] : 0.0});
    }
    return false;
}

// Two bodies must not overlap: their nodes would start inside each other, the pairs across them
// would be crushed in the first step and the time step would collapse (a sphere placed 1 mm into a
// plate asked for a first time step of 1e-13 ns). Tested on the first body's lattice nodes (cell
// centres) where the two bodies' extents overlap, every node up to 4 million of them and a regular
// subset beyond; the message names both bodies, how many nodes overlap and where.
void check_overlap(const Scene& scene, std::size_t a, std::size_t b) {
    const GeometryKind g = scene.geometry;
    const int dim = dimension_of(g);
    const BodySpec& first = scene.bodies[a];
    const BodySpec& second = scene.bodies[b];
    if (!shape_known(first) || !shape_known(second)) return;
    std::array<double, 3> lo{}, hi{};
    for (int k = 0; k < dim; ++k) {
        const auto [lo_a, hi_a] = extent(first, g, k);
        const auto [lo_b, hi_b] = extent(second, g, k);
        lo[static_cast<std::size_t>(k)] = std::max(lo_a, lo_b);
        hi[static_cast<std::size_t>(k)] = std::min(hi_a, hi_b);
        if (!(lo[static_cast<std::size_t>(k)] < hi[static_cast<std::size_t>(k)])) return;  // apart or touching
    }
    std::size_t overlapping = 0;
    std::array<double, 3> example{};
    const auto report = [&](std::int64_t stride) {
        if (overlapping == 0) return;
        const std::string where = dim == 2 ? fmt::format("(x, z) = ({:.6g}, {:.6g}) mm", 1e3 * example[0], 1e3 * example[1])
                                           : fmt::format("(x, y, z) = ({:.6g}, {:.6g}, {:.6g}) mm", 1e3 * example[0],
                                                         1e3 * example[1], 1e3 * example[2]);
        fail(fmt::format("{} overlaps {}: {}{} of its nodes lie inside it, the first at {}; bodies may touch but not overlap "
                         "(move one, or make it smaller)",
                         body_label(first, a), body_label(second, b), stride > 1 ? "at least " : "", overlapping, where));
    };
    if (first.shape == ShapeKind::Nodes) {
        // Its own nodes, all of them.
        const NodeSetShape& set = *first.node_set;
        for (std::size_t k = 0; k < set.size(); ++k) {
            const auto p = imported_node_at(first, set.set().positions[k], dim);
            if (!inside_shape(second, g, p)) continue;
            if (overlapping++ == 0) example = p;
        }
        report(1);
        return;
    }
    const LatticeBlock block = body_lattice(scene, a);
    // The cells of the first body's block whose centres fall in the overlap of the extents (all of
    // them for a turned body, whose cells are in its own axes).
    const bool turned = !is_identity(block.rotation);
    std::array<std::int64_t, 3> first_cell{0, 0, 0}, last_cell{1, 1, 1};
    double cells = 1.0;
    for (int k = 0; k < dim; ++k) {
        const auto c = static_cast<std::size_t>(k);
        const double s = block.spacing[c];
        first_cell[c] = turned ? block.first[c]
                               : std::max(block.first[c], static_cast<std::int64_t>(std::floor((lo[c] - block.origin[c]) / s - 0.5)));
        last_cell[c] = turned ? block.last[c]
                              : std::min(block.last[c], static_cast<std::int64_t>(std::ceil((hi[c] - block.origin[c]) / s - 0.5)) + 1);
        if (last_cell[c] <= first_cell[c]) return;
        cells *= static_cast<double>(last_cell[c] - first_cell[c]);
    }
    const auto stride = static_cast<std::int64_t>(std::max(1.0, std::ceil(std::pow(cells / 4e6, 1.0 / dim))));
    for (std::int64_t k2 = first_cell[2]; k2 < last_cell[2]; k2 += dim == 3 ? stride : 1) {
        for (std::int64_t k1 = first_cell[1]; k1 < last_cell[1]; k1 += stride) {
            for (std::int64_t k0 = first_cell[0]; k0 < last_cell[0]; k0 += stride) {
                const std::array<std::int64_t, 3> cell{k0, k1, k2};
                std::array<double, 3> p{};
                for (int k = 0; k < dim; ++k) {
                    const auto c = static_cast<std::size_t>(k);
                    p[c] = block.origin[c] + (static_cast<double>(cell[c]) + 0.5) * block.spacing[c];
                }
                p = block.place(p);
                if (!inside_shape(first, g, p) || !inside_shape(second, g, p)) continue;
                if (overlapping++ == 0) example = p;
            }
        }
    }
    report(stride);
}

// The lattice spacing along an axis.
double spacing_along(const BodySpec& b, GeometryKind g, int axis) {
    if (dimension_of(g) == 2 && axis == 1 && b.spacing_z > 0.0) return b.spacing_z;
    return b.spacing;
}

void check_material(const materials::Material& m, std::size_t i) {
    if (m.name.empty()) {
        fail(fmt::format("{}: a material needs a name (bodies refer to it by name)", material_label(m, i)));
    }
    try {
        materials::validate(m);
    } catch (const std::exception& e) {
        fail(e.what());  // names the material and the field already
    }
}

void check_body(const Scene& scene, const BodySpec& b, std::size_t i) {
    const GeometryKind g = scene.geometry;
    const int dim = dimension_of(g);
    const std::string label = body_label(b, i);

    if (!known_shape(b.shape)) fail(fmt::format("{}.shape: unknown shape value {}", label, static_cast<int>(b.shape)));
    if (b.shape == ShapeKind::Rectangle && dim == 3) {
        fail(fmt::format("{}.shape: a rectangle is a 2D shape; a 3D scene takes cylinder, plate, box or sphere", label));
    }
    if (b.shape == ShapeKind::Box && dim == 2) {
        fail(fmt::format("{}.shape: a box is a 3D shape; {} takes cylinder, plate, rectangle or sphere", label,
                         g == GeometryKind::Axisymmetric ? "an axisymmetric scene" : "a plane-strain scene"));
    }

    if (!is_identity(b.rotation)) {
        if (g == GeometryKind::Axisymmetric) {
            fail(fmt::format("{}.rotation: an axisymmetric scene's bodies turn about its axis and cannot be rotated", label));
        }
        if (b.discretisation == Discretisation::Elements) {
            fail(fmt::format("{}.rotation: element bodies are meshed along the scene's axes and cannot be rotated", label));
        }
        if (auto problem = rotation_problem(b.rotation, dim)) fail(fmt::format("{}.rotation is not a rotation: {}", label, *problem));
    }

    bool known_material = false;
    for (const auto& m : scene.materials) known_material = known_material || m.name == b.material;
    if (!known_material) {
        std::string names;
        for (const auto& m : scene.materials) names += (names.empty() ? "" : ", ") + fmt::format("\"{}\"", m.name);
        fail(fmt::format("{}.material: \"{}\" is not among the scene's materials ({})", label, b.material,
                         names.empty() ? "none" : names));
    }

    for (int k = 0; k < dim; ++k) {
        if (!finite(b.origin[static_cast<std::size_t>(k)])) fail(fmt::format("{}.origin[{}] must be finite", label, k));
        if (!finite(b.velocity[static_cast<std::size_t>(k)])) fail(fmt::format("{}.velocity[{}] must be finite", label, k));
    }
    for (int k = 0; k < stress_components(dim); ++k) {
        if (!finite(b.initial_stress[static_cast<std::size_t>(k)])) {
            fail(fmt::format("{}.initial_stress[{}] must be finite", label, k));
        }
    }

    // Sizes.
    if (b.shape == ShapeKind::Surface) {
        if (dim != 3) fail(fmt::format("{}: a surface is a 3D shape (a closed triangulated surface)", label));
        // (A scene reader checks the scene before it reads the surface files: body_lattice refuses a
        // body whose surface is still missing when its nodes are made.)
        if (b.surface) check_surface(b.surface->triangles(), fmt::format("{}.file \"{}\"", label, b.surface_file));
        if (b.fill == CellFill::Trimmed) {
            fail(fmt::format("{}.fill = \"trimmed\" applies to cylinders, plates, spheres, rectangles and boxes; a surface's "
                             "cells are filled by their centres (sampling each boundary cell against the triangles would "
                             "cost a point-in-surface test per sample)",
                             label));
        }
    } else if (b.shape == ShapeKind::Nodes) {
        // Imported nodes (node_set.hpp): their own sizes, no lattice.
        if (b.node_set) {
            if (b.node_set->dim() != dim) {
                fail(fmt::format("{}: its node set is {}D, the scene {}D", label, b.node_set->dim(), dim));
            }
            check_node_set(b.node_set->set(), dim, g == GeometryKind::Axisymmetric,
                           fmt::format("{}.file \"{}\"", label, b.surface_file));
            if (g == GeometryKind::Axisymmetric && b.origin[0] != 0.0) {
                fail(fmt::format("{}.origin: in an axisymmetric scene imported nodes keep their radii, so origin x must be 0 "
                                 "(is {} m)", label, b.origin[0]));
            }
        }
        if (b.discretisation != Discretisation::Particles) {
            fail(fmt::format("{}.discretisation: imported nodes are particles (elements need a mesh of the shape)", label));
        }
        if (b.connectivity && *b.connectivity != ConnectivityMode::Variable) {
            fail(fmt::format("{}.connectivity: imported nodes have no lattice, so they take variable connectivity only", label));
        }
        if (b.lattice_neighbours != 0) {
            fail(fmt::format("{}.lattice_neighbours: imported nodes have no lattice (their connectivity is variable)", label));
        }
        if (b.fill) {
            fail(fmt::format("{}.fill: imported nodes have no lattice to fill (their file gives each node)", label));
        }
        if (b.spacing != 0.0 || b.spacing_z != 0.0) {
            fail(fmt::format("{}.spacing: imported nodes bring their own sizes (their volumes or areas); give no spacing", label));
        }
        return;
    } else if (is_round(b.shape)) {
        if (!(b.radius > 0.0 && finite(b.radius))) {
            fail(fmt::format("{}.radius = {} must be a positive length (m)", label, b.radius));
        }
        if (b.shape != ShapeKind::Sphere && !(b.length > 0.0 && finite(b.length))) {
            fail(fmt::format("{}.length = {} must be a positive length (m)", label, b.length));
        }
        if (g == GeometryKind::Axisymmetric && b.origin[0] != 0.0) {
            fail(fmt::format("{}.origin: an axisymmetric {} lies on the axis, so its origin x must be 0 (is {} m)", label,
                             name_of(b.shape), b.origin[0]));
        }
        if (b.nose) {
            // The nose (scene.hpp, NoseSpec): on a cylinder, within its length, of a profile that exists.
            const NoseSpec& n = *b.nose;
            if (b.shape != ShapeKind::Cylinder) {
                fail(fmt::format("{}.nose applies to a cylinder only, not a {}", label, name_of(b.shape)));
            }
            if (n.end != -1 && n.end != 1) fail(fmt::format("{}.nose.end = {} must be -1 (bottom) or 1 (top)", label, n.end));
            if (n.kind == NoseKind::Cone && !(n.length > 0.0 && finite(n.length))) {
                fail(fmt::format("{}.nose.length = {} must be a positive length (m) for a cone", label, n.length));
            }
            if (n.kind != NoseKind::Cone && n.length != 0.0) {
                fail(fmt::format("{}.nose.length: a {} nose's length follows from the radius{}; give none", label,
                                 name_of(n.kind), n.kind == NoseKind::Ogive ? " and calibre_radius" : ""));
            }
            if (n.kind == NoseKind::Ogive && !(n.calibre_radius >= 0.5 && finite(n.calibre_radius))) {
                fail(fmt::format("{}.nose.calibre_radius = {} must be at least 0.5 (calibres: the arc radius over the diameter; "
                                 "0.5 is a hemisphere)", label, n.calibre_radius));
            }
            if (n.kind != NoseKind::Ogive && n.calibre_radius != 0.0) {
                fail(fmt::format("{}.nose.calibre_radius applies to an ogive only, not a {}", label, name_of(n.kind)));
            }
            const double length = nose_length(n, b.radius);
            if (!(length <= b.length)) {
                fail(fmt::format("{}: its {} nose is {} m long, longer than the cylinder ({} m, the nose included)", label,
                                 name_of(n.kind), length, b.length));
            }
        }
        if (b.inner_radius != 0.0) {
            if (b.shape != ShapeKind::Sphere) {
                fail(fmt::format("{}.inner_radius applies to a sphere only (a ring in plane strain), not a {}", label,
                                 name_of(b.shape)));
            }
            if (!(b.inner_radius > 0.0 && finite(b.inner_radius))) {
                fail(fmt::format("{}.inner_radius = {} must be a length >= 0 (m; 0 = a solid sphere)", label, b.inner_radius));
            }
            if (!(b.inner_radius < b.radius)) {
                fail(fmt::format("{}.inner_radius = {} m must be less than its radius ({} m): nothing would be left of the {}",
                                 label, b.inner_radius, b.radius, g == GeometryKind::PlaneStrain ? "ring" : "shell"));
            }
            if (b.radius - b.inner_radius < 2.0 * b.spacing * (1.0 - 1e-12)) {
                fail(fmt::format("{}: spacing {} m puts fewer than 2 nodes across its wall ({} m from inner_radius to "
                                 "radius); use a spacing of at most {} m",
                                 label, b.spacing, b.radius - b.inner_radius, 0.5 * (b.radius - b.inner_radius)));
            }
        }
    } else {
        for (int k = 0; k < dim; ++k) {
            const double s = b.size[static_cast<std::size_t>(k)];
            if (!(s > 0.0 && finite(s))) {
                fail(fmt::format("{}.size[{}] = {} must be a positive length (m)", label, k, s));
            }
        }
        if (g == GeometryKind::Axisymmetric && b.origin[0] < 0.0) {
            fail(fmt::format("{}.origin: an axisymmetric rectangle must lie at x >= 0 (x is the radius), origin x is {} m",
                             label, b.origin[0]));
        }
    }

    // Spacings, and at least two nodes across every dimension of the body.
    if (!(b.spacing > 0.0 && finite(b.spacing))) {
        fail(fmt::format("{}.spacing = {} must be a positive length (m)", label, b.spacing));
    }
    if (dim == 3 && b.spacing_z != 0.0) {
        fail(fmt::format("{}.spacing_z applies to 2D scenes only (a 3D lattice has one spacing)", label));
    }
    if (!(b.spacing_z >= 0.0 && finite(b.spacing_z))) {
        fail(fmt::format("{}.spacing_z = {} must be a positive length (m), or 0 for the same as spacing", label, b.spacing_z));
    }
    for (int k = 0; k < dim && shape_known(b); ++k) {
        const auto [lo, hi] = extent(b, g, k);
        const double across = hi - lo;
        const double d = spacing_along(b, g, k);
        if (across < 2.0 * d * (1.0 - 1e-12)) {
            const bool radial = g == GeometryKind::Axisymmetric && k == 0 && is_round(b.shape);
            fail(fmt::format("{}: spacing {} m puts fewer than 2 nodes across its {} ({} m along {}); use a spacing of at "
                             "most {} m",
                             label, d, radial ? "radius" : "extent", across, axis_letter(k, dim), across / 2.0));
        }
    }

    if (b.discretisation != Discretisation::Particles && b.discretisation != Discretisation::Elements) {
        fail(fmt::format("{}.discretisation: unknown discretisation", label));
    }
    if (b.discretisation == Discretisation::Elements) {
        if (dim != 2) {
            fail(fmt::format("{}.discretisation = \"elements\": the element solver is 2D (axisymmetric or plane strain); "
                             "a 3D body takes particles",
                             label));
        }
        if (b.connectivity) {
            fail(fmt::format("{}.connectivity applies to particle bodies only (this body is discretised by elements)", label));
        }
        if (b.lattice_neighbours != 0) {
            fail(fmt::format("{}.lattice_neighbours applies to particle bodies only (this body is discretised by elements)",
                             label));
        }
        if (b.fill) fail(fmt::format("{}.fill applies to particle bodies only (this body is discretised by elements)", label));
    }
    if (b.lattice_neighbours != 0) {
        const int n = b.lattice_neighbours;
        const bool valid = dim == 2 ? (n == 4 || n == 8) : (n == 6 || n == 18 || n == 26);
        if (!valid) {
            fail(fmt::format("{}.lattice_neighbours = {} is not {} (or 0 for the default)", label, n,
                             dim == 2 ? "4 or 8" : "6, 18 or 26"));
        }
    }
    if (b.connectivity && !(*b.connectivity == ConnectivityMode::Fixed || *b.connectivity == ConnectivityMode::Variable ||
                            *b.connectivity == ConnectivityMode::Automatic)) {
        fail(fmt::format("{}.connectivity: unknown connectivity mode", label));
    }
    if (b.fill == CellFill::Rings) {
        // Rings of nodes about a cylinder's axis (bodies.hpp, ring_fill): no lattice, so no fixed lists.
        if (dim != 3) {
            fail(fmt::format("{}.fill = \"rings\" is for 3D bodies (an axisymmetric scene's nodes are rings already)", label));
        }
        if (b.shape != ShapeKind::Cylinder && b.shape != ShapeKind::Plate) {
            fail(fmt::format("{}.fill = \"rings\" applies to cylinders and plates, not a {}", label, name_of(b.shape)));
        }
        const ConnectivityMode mode = b.connectivity.value_or(scene.solver.connectivity);
        if (mode != ConnectivityMode::Variable) {
            fail(fmt::format("{}.fill = \"rings\" has no lattice to keep fixed lists on: the body's connectivity must be "
                             "\"variable\" (set [solver] connectivity or the body's own)",
                             label));
        }
        if (b.lattice_neighbours != 0) {
            fail(fmt::format("{}.lattice_neighbours: a body filled with rings has no lattice (its connectivity is variable)", label));
        }
    }
}

void check_plane(const Scene& scene, const PlaneSpec& p, std::size_t i) {
    const GeometryKind g = scene.geometry;
    const int dim = dimension_of(g);
    const std::string label = plane_label(p, i);
    if (p.kind != PlaneKind::Rigid && p.kind != PlaneKind::Symmetry) fail(fmt::format("{}.kind: unknown plane kind", label));
    const bool oblique = p.axis == -1;
    if (oblique) {
        if (g == GeometryKind::Axisymmetric) {
            fail(fmt::format("{}: an axisymmetric scene's planes are normal to x or z (a plane at another angle would be a "
                             "cone around the axis)", label));
        }
        double q = 0.0;
        for (int c = 0; c < 3; ++c) q += p.normal[c] * p.normal[c];
        if (!finite(q) || std::abs(q - 1.0) > 1e-12) {
            fail(fmt::format("{}.normal must be a finite unit vector (its length squared is {})", label, q));
        }
        if (dim == 2 && p.normal[2] != 0.0) {
            fail(fmt::format("{}.normal has a third component ({}) in a 2D scene, whose normals are [x, z]", label, p.normal[2]));
        }
        for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
            if (scene.bodies[k].discretisation == Discretisation::Elements) {
                fail(fmt::format("{}: its normal is not a coordinate axis, and {} is discretised by elements, whose contact "
                                 "with planes is along the scene's axes",
                                 label, body_label(scene.bodies[k], k)));
            }
        }
    } else if (p.axis < 0 || p.axis >= dim) {
        fail(fmt::format("{}.axis = {} is not a direction of {} scene ({})", label, p.axis,
                         g == GeometryKind::Axisymmetric ? "an axisymmetric" : dim == 2 ? "a plane-strain" : "a 3D",
                         dim == 2 ? "0 = x, 1 = z" : "0 = x, 1 = y, 2 = z"));
    }
    if (p.side != 1 && p.side != -1) {
        fail(fmt::format("{}.side = {} must be +1 (bodies above the plane) or -1 (below)", label, p.side));
    }
    if (!finite(p.position)) fail(fmt::format("{}.position must be finite", label));
    // Coulomb friction (RigidPlanes::apply_friction): rigid planes, particle bodies.
    if (p.friction_static != 0.0 || p.friction_dynamic != 0.0) {
        if (p.kind != PlaneKind::Rigid) fail(fmt::format("{}: friction applies to rigid planes only", label));
        if (!(p.friction_dynamic >= 0.0 && finite(p.friction_dynamic))) {
            fail(fmt::format("{}.friction = {} must be a number >= 0", label, p.friction_dynamic));
        }
        if (!(p.friction_static >= p.friction_dynamic && finite(p.friction_static))) {
            fail(fmt::format("{}.static_friction = {} must be at least friction = {}", label, p.friction_static,
                             p.friction_dynamic));
        }
        for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
            if (scene.bodies[k].discretisation == Discretisation::Elements) {
                fail(fmt::format("{}: friction acts on particle bodies only, and {} is discretised by elements (their "
                                 "contact with planes is frictionless)",
                                 label, body_label(scene.bodies[k], k)));
            }
        }
    }
    // The coordinate named in messages: the axis, or "n . x" for an oblique plane.
    const std::string letter = oblique ? std::string("n . x") : std::string(1, axis_letter(p.axis, dim));
    const auto n = plane_normal(p);
    if (g == GeometryKind::Axisymmetric && p.axis == 0 && p.position <= 0.0) {
        fail(fmt::format("{}: a plane normal to x must lie at x > 0 in an axisymmetric scene (the axis x = 0 is a "
                         "symmetry plane already); it is at x = {} m",
                         label, p.position));
    }
    for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
        const BodySpec& b = scene.bodies[k];
        if (!shape_known(b)) continue;
        const auto [lo, hi] = extent_along(b, g, n);
        const double tolerance = plane_tolerance(b, p.position);
        if (symmetry_plane_cuts(scene, k, i)) {
            if (b.shape == ShapeKind::Nodes) {
                fail(fmt::format("{} at {} = {} m cuts {}, whose nodes are imported: a symmetry plane may cut a body filled "
                                 "with a lattice (it keeps the cells on its side), but imported nodes must all lie on its "
                                 "side, a quarter of their median diameter or more from it",
                                 label, letter, p.position, body_label(b, k)));
            }
            if (b.shape != ShapeKind::Nodes && cell_fill(b, g) == CellFill::Rings) {
                // Rings are mirror-symmetric about the planes through the axis along the body's own x
                // and y (ring_fill), and about no other plane that cuts them.
                const auto own = turn_back(b.rotation, n);
                const double across = std::abs(own[0]) > std::abs(own[1]) ? std::abs(own[1]) : std::abs(own[0]);
                double through = -p.position;
                for (int c = 0; c < 3; ++c) through += n[c] * b.origin[c];
                if (!(std::abs(own[2]) < 1e-12 && across < 1e-12 && std::abs(through) <= 1e-9 * b.spacing)) {
                    fail(fmt::format("{} at {} = {} m cuts {}, which is filled with rings: a symmetry plane may cut such a body "
                                     "only through its axis, along its own x or y axis (the rings are mirror images "
                                     "across those two planes and no other)",
                                     label, letter, p.position, body_label(b, k)));
                }
                continue;
            }
            // A half or quarter model: the body is filled on the plane's side (body_lattice), and the
            // plane's ghosts continue it across.
            if (b.discretisation == Discretisation::Elements) {
                fail(fmt::format("{} at {} = {} m cuts {}, which is discretised by elements: element bodies may touch a "
                                 "symmetry plane but not be cut by it; give the element body's half or quarter as its shape",
                                 label, letter, p.position, body_label(b, k)));
            }
            if (g == GeometryKind::Axisymmetric && p.axis == 0) {
                fail(fmt::format("{} at x = {} m cuts {}: in an axisymmetric scene a plane normal to x is a cylinder "
                                 "around the axis, not a plane of symmetry; only a plane normal to z may cut a body",
                                 label, p.position, body_label(b, k)));
            }
            body_lattice(scene, k);  // throws when the plane does not lie on a cell face of the body's lattice
            continue;
        }
        if (p.side > 0 && lo < p.position - tolerance) {
            fail(fmt::format("{} at {} = {} m keeps bodies above it (side +1), but {} is on the wrong side: it reaches down "
                             "to {} = {} m",
                             label, letter, p.position, body_label(b, k), letter, lo));
        }
        if (p.side < 0 && hi > p.position + tolerance) {
            fail(fmt::format("{} at {} = {} m keeps bodies below it (side -1), but {} is on the wrong side: it reaches up "
                             "to {} = {} m",
                             label, letter, p.position, body_label(b, k), letter, hi));
        }
    }
}

// Every key's range or word list, from the table of solver options (solver_options.hpp), so that
// validation, the scene reader and study variants cannot disagree; then the rules that involve
// several keys (the stress-difference form's, the relaxing stiffness's), written by hand.
void check_solver(const SolverOptions& s) {
    for (const SolverOption& option : solver_option_table()) {
        if (auto message = option_error(option, s)) fail(std::move(*message));
    }
    // The stress-difference form makes no pair forces, and bond viscosity is one.
    if (s.force_form == ForceForm::StressDifference) {
        if (s.viscosity == ViscosityKind::Bond) {
            fail("solver.force_form = \"stress-difference\" takes viscosity = \"nodal\" or \"none\": bond viscosity is a "
                 "pair force");
        }
    }
    // A time constant without a stiffness to relax would be ignored without a word.
    if (s.hourglass_stiffness_relaxation > 0.0 && !(s.hourglass_stiffness > 0.0)) {
        fail(fmt::format("solver.hourglass_stiffness_relaxation = {:g} s needs solver.hourglass_stiffness > 0 (the stiffness "
                         "whose reference relaxes); it is 0",
                         s.hourglass_stiffness_relaxation));
    }
}

void check_stop(const StopCriteria& s) {
    if (!(s.end_time >= 0.0 && finite(s.end_time))) {
        fail(fmt::format("stop.end_time = {} must be a finite time >= 0 (s)", s.end_time));
    }
    if (!(s.kinetic_energy_fraction >= 0.0 && s.kinetic_energy_fraction < 1.0)) {
        fail(fmt::format("stop.kinetic_energy_fraction = {} is outside [0, 1)", s.kinetic_energy_fraction));
    }
    if (!(s.energy_error >= 0.0 && finite(s.energy_error))) {
        fail(fmt::format("stop.energy_error = {} must be a finite fraction >= 0 (0 = no energy guard)", s.energy_error));
    }
    if (s.end_time == 0.0 && s.kinetic_energy_fraction == 0.0 && s.max_steps == 0) {
        fail("stop: no end condition; set stop.end_time, stop.kinetic_energy_fraction or stop.max_steps");
    }
}

void check_output(const OutputOptions& o) {
    if (!(o.snapshot_interval >= 0.0 && finite(o.snapshot_interval))) {
        fail(fmt::format("output.snapshot_interval = {} must be a finite time >= 0 (s)", o.snapshot_interval));
    }
    if (o.history_every == 0) fail("output.history_every must be at least 1 (steps between history rows)");
    if (!(o.checkpoint_every_seconds >= 0.0 && finite(o.checkpoint_every_seconds))) {
        fail(fmt::format("output.checkpoint_every = {} s must be a finite wall-clock time >= 0", o.checkpoint_every_seconds));
    }
    const auto& fields = o.snapshot_format.fields;
    const std::vector<SnapshotField> all = all_snapshot_fields();
    for (std::size_t k = 0; k < fields.size(); ++k) {
        if (std::find(all.begin(), all.end(), fields[k]) == all.end()) {
            fail(fmt::format("output.fields[{}] = {} is not a snapshot field", k, static_cast<int>(fields[k])));
        }
        if (std::find(fields.begin(), fields.begin() + static_cast<std::ptrdiff_t>(k), fields[k]) != fields.begin() + static_cast<std::ptrdiff_t>(k)) {
            fail(fmt::format("output.fields names '{}' twice", name_of(fields[k])));
        }
    }
    if (o.snapshot_format.precision != SnapshotPrecision::Float64 && o.snapshot_format.precision != SnapshotPrecision::Float32) {
        fail(fmt::format("output.precision = {} is neither Float64 nor Float32", static_cast<int>(o.snapshot_format.precision)));
    }
}

std::string region_label(const PrescribedVelocitySpec& r, std::size_t i) {
    return r.name.empty() ? fmt::format("prescribed_velocity[{}]", i)
                          : fmt::format("prescribed_velocity \"{}\" (prescribed_velocity[{}])", r.name, i);
}

// Calls visit(p) for the initial node positions of body b (particles: lattice cell centres;
// elements: cell centres and corners, corners once per cell) in the cells that can reach the box
// [lo, hi], until visit returns true; returns whether it did.
template <class F>
bool any_initial_node(const Scene& scene, std::size_t b, const std::array<double, 3>& lo, const std::array<double, 3>& hi,
                      F&& visit) {
    const int dim = dimension_of(scene.geometry);
    if (const BodySpec& spec = scene.bodies[b]; spec.shape == ShapeKind::Nodes) {  // its imported nodes
        if (!is_identity(spec.rotation)) {  // turned: every node, placed
            for (std::size_t k = 0; k < spec.node_set->size(); ++k) {
                if (visit(imported_node_at(spec, spec.node_set->set().positions[k], dim))) return true;
            }
            return false;
        }
        const auto& o = spec.origin;
        std::array<double, 3> from = lo, to = hi;
        for (int c = 0; c < dim; ++c) {
            from[c] -= o[c];
            to[c] -= o[c];
        }
        return spec.node_set->any_in_box(from, to, [&](std::size_t k) {
            const auto& x = spec.node_set->set().positions[k];
            return visit(std::array<double, 3>{x[0] + o[0], x[1] + o[1], dim == 3 ? x[2] + o[2] : 0.0});
        });
    }
    const LatticeBlock block = body_lattice(scene, b);
    const bool elements = scene.bodies[b].discretisation == Discretisation::Elements;
    std::array<std::int64_t, 3> from = block.first, to = block.last;
    const bool turned = !is_identity(block.rotation);  // its cells are in its own axes: visit them all
    for (int c = 0; c < dim && !turned; ++c) {
        const double o = block.origin[c], s = block.spacing[c];
        const double first = double(block.first[c]) - 1.0, last = double(block.last[c]) + 1.0;
        if (std::isfinite(lo[c])) from[c] = std::max(from[c], std::int64_t(std::clamp(std::floor((lo[c] - o) / s) - 1.0, first, last)));
        if (std::isfinite(hi[c])) to[c] = std::min(to[c], std::int64_t(std::clamp(std::ceil((hi[c] - o) / s) + 1.0, first, last)));
    }
    if (dim == 2) {
        from[2] = 0;
        to[2] = 1;
    }
    for (std::int64_t kz = from[2]; kz < to[2]; ++kz) {
        for (std::int64_t ky = from[1]; ky < to[1]; ++ky) {
            for (std::int64_t kx = from[0]; kx < to[0]; ++kx) {
                const std::array<std::int64_t, 3> k{kx, ky, kz};
                std::array<double, 3> centre{0, 0, 0};
                for (int c = 0; c < dim; ++c) centre[c] = block.origin[c] + (double(k[c]) + 0.5) * block.spacing[c];
                if (block.inside && !block.inside(centre)) continue;
                if (visit(block.place(centre))) return true;
                if (!elements) continue;
                for (int corner = 0; corner < 4; ++corner) {  // element bodies are 2D
                    const std::array<double, 3> p{block.origin[0] + double(kx + (corner & 1)) * block.spacing[0],
                                                  block.origin[1] + double(ky + (corner >> 1)) * block.spacing[1], 0.0};
                    if (visit(p)) return true;
                }
            }
        }
    }
    return false;
}

// The largest distance of a body's points from its axis (prescribed.hpp, body_axis).
double largest_radius(const BodySpec& b, GeometryKind g) {
    if (is_round(b.shape)) return b.radius;
    if (b.shape == ShapeKind::Nodes && dimension_of(g) == 2) {
        const auto [x0, x1] = extent(b, g, 0);
        return g == GeometryKind::Axisymmetric ? x1 : 0.5 * (x1 - x0);
    }
    if (b.shape == ShapeKind::Surface || b.shape == ShapeKind::Nodes) {
        // (3D) half the diagonal of its box across z, from the box's centre line.
        const auto [x0, x1] = extent(b, g, 0);
        const auto [y0, y1] = extent(b, g, 1);
        return 0.5 * std::hypot(x1 - x0, y1 - y0);
    }
    if (g == GeometryKind::Axisymmetric) return b.origin[0] + b.size[0];
    if (g == GeometryKind::PlaneStrain) return 0.5 * b.size[0];
    return 0.5 * std::hypot(b.size[0], b.size[1]);
}

void check_prescribed_velocity(const Scene& scene, std::size_t k) {
    const PrescribedVelocitySpec& r = scene.prescribed_velocities[k];
    const GeometryKind g = scene.geometry;
    const int dim = dimension_of(g);
    const std::string label = region_label(r, k);
    const auto fail_here = [&](const std::string& message) { throw PrescribedVelocityError(message, k); };

    for (std::size_t j = 0; j < k; ++j) {
        if (!r.name.empty() && scene.prescribed_velocities[j].name == r.name) {
            fail_here(fmt::format("{}: the name is already used by prescribed_velocity[{}]", label, j));
        }
    }
    const auto body = std::find_if(scene.bodies.begin(), scene.bodies.end(), [&](const BodySpec& b) { return b.name == r.body; });
    if (body == scene.bodies.end()) {
        std::string names;
        for (const auto& b : scene.bodies) names += (names.empty() ? "" : ", ") + fmt::format("\"{}\"", b.name);
        fail_here(fmt::format("{}.body: \"{}\" is not a body of the scene (its bodies: {})", label, r.body, names));
    }
    const std::size_t b = static_cast<std::size_t>(body - scene.bodies.begin());

    // The motion.
    std::string components;
    for (int c = 0; c < dim; ++c) components += fmt::format("{}{}", c ? ", " : "", axis_letter(c, dim));
    if (held_components(r) == 0) {
        fail_here(fmt::format("{}.velocity prescribes no component: give at least one of {} (the others stay free)", label,
                              components));
    }
    for (int c = 0; c < 3; ++c) {
        if (!r.velocity[c]) continue;
        if (c >= dim) fail_here(fmt::format("{}.velocity: a 2D scene has no y component (its components are {})", label, components));
        if (!finite(*r.velocity[c])) fail_here(fmt::format("{}.velocity.{} must be finite", label, axis_letter(c, dim)));
    }
    if (!(r.ramp >= 0.0 && finite(r.ramp))) {
        fail_here(fmt::format("{}.ramp = {} must be a finite time >= 0 (s; 0 = the full velocity from t = 0)", label, r.ramp));
    }

    // The region.
    for (int c = 0; c < 3; ++c) {
        if (std::isnan(r.lower[c]) || std::isnan(r.upper[c])) fail_here(fmt::format("{}.region: a bound is not a number", label));
        if (c >= dim) {
            if (r.lower[c] != -INFINITY || r.upper[c] != INFINITY) fail_here(fmt::format("{}.region: a 2D scene has no y bounds", label));
            continue;
        }
        if (r.lower[c] > r.upper[c]) {
            fail_here(fmt::format("{}.region: its lower bound {} = {} m lies above its upper bound {} m", label,
                                  axis_letter(c, dim), r.lower[c], r.upper[c]));
        }
    }
    if (!(r.radius_min >= 0.0 && finite(r.radius_min)) || std::isnan(r.radius_max) || r.radius_max < r.radius_min) {
        fail_here(fmt::format("{}.region: the radii [{}, {}] m are not a range from a finite radius >= 0 up", label,
                              r.radius_min, r.radius_max));
    }
    const BodySpec& spec = *body;
    if (!is_identity(spec.rotation) && (r.radius_min > 0.0 || std::isfinite(r.radius_max))) {
        fail_here(fmt::format("{}.region: its radii are measured from the line along z through body \"{}\"'s centre, which "
                              "is not the axis of a turned body; give the region as bounds along x, y and z",
                              label, spec.name));
    }
    std::string spans;
    bool outside = shape_known(spec) && r.radius_min > largest_radius(spec, g) * (1.0 + 1e-12);
    for (int c = 0; c < dim && shape_known(spec); ++c) {
        const auto [lo, hi] = extent(spec, g, c);
        spans += fmt::format("{}{} from {:.6g} to {:.6g} mm", c ? ", " : "", axis_letter(c, dim), lo * 1e3, hi * 1e3);
        const double tolerance = 1e-9 * std::max(nominal_spacing(spec), std::max(std::abs(lo), std::abs(hi)));
        outside = outside || r.upper[c] < lo - tolerance || r.lower[c] > hi + tolerance;
    }
    if (outside) {
        fail_here(fmt::format("{}.region lies outside body \"{}\" (it spans {}; radii up to {:.6g} mm from its axis)", label,
                              spec.name, spans, largest_radius(spec, g) * 1e3));
    }
    // The checks on the body's nodes wait until its shape is known (a surface's file is read after
    // the scene reader's checks; the Simulation checks the scene again).
    if (!shape_known(spec)) return;
    const auto axis = body_axis(scene, b);
    const auto inside = [&](const PrescribedVelocitySpec& region, const std::array<double, 3>& p) {
        return in_region(region, g, axis, p);
    };
    if (!any_initial_node(scene, b, r.lower, r.upper, [&](const auto& p) { return inside(r, p); })) {
        if (spec.shape == ShapeKind::Nodes) {
            fail_here(fmt::format("{}.region holds no node of body \"{}\" (imported nodes, typically {:.4g} mm apart): "
                                  "widen it",
                                  label, spec.name, nominal_spacing(spec) * 1e3));
        }
        const LatticeBlock block = body_lattice(scene, b);
        fail_here(fmt::format("{}.region holds no node of body \"{}\": it lies between the rows of its lattice (spacing {:.4g} "
                              "mm); make it at least one spacing wide",
                              label, spec.name, block.spacing[0] * 1e3));
    }
    for (std::size_t j = 0; j < k; ++j) {
        const PrescribedVelocitySpec& other = scene.prescribed_velocities[j];
        if (other.body != r.body) continue;
        std::array<double, 3> lo, hi;
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::max(r.lower[c], other.lower[c]);
            hi[c] = std::min(r.upper[c], other.upper[c]);
        }
        if (any_initial_node(scene, b, lo, hi, [&](const auto& p) { return inside(r, p) && inside(other, p); })) {
            fail_here(fmt::format("{}.region shares nodes of body \"{}\" with {}: a node follows one prescribed velocity; "
                                  "make the regions disjoint",
                                  label, spec.name, region_label(other, j)));
        }
    }
    // A plane (or the axis) that the region's nodes touch and that the region would move them
    // along the normal of: through a rigid wall, off a symmetry plane.
    const double d0 = spec.shape == ShapeKind::Nodes ? nominal_spacing(spec) : [&] {
        const LatticeBlock block = body_lattice(scene, b);
        return dim == 3 ? block.spacing[0] : std::sqrt(block.spacing[0] * block.spacing[1]);
    }();
    const auto moves_along = [&](int a) { return r.velocity[a] && *r.velocity[a] != 0.0; };
    const auto touches = [&](int a, double position) {
        return any_initial_node(scene, b, r.lower, r.upper,
                                [&](const auto& p) { return inside(r, p) && std::abs(p[a] - position) < 0.75 * d0; });
    };
    if (g == GeometryKind::Axisymmetric && moves_along(0) && touches(0, 0.0)) {
        fail_here(fmt::format("{} moves nodes at the axis radially (velocity.x = {} m/s): nodes next to the axis cannot move "
                              "off it; hold x at 0 there or start the region at a radius of one spacing or more",
                              label, *r.velocity[0]));
    }
    for (std::size_t p = 0; p < scene.planes.size(); ++p) {
        const PlaneSpec& plane = scene.planes[p];
        if (plane.axis == -1) {  // an oblique plane: a prescribed velocity with a part along its normal
            const auto n = plane_normal(plane);
            double normal_part = 0.0;
            for (int c = 0; c < dim; ++c) {
                if (r.velocity[c]) normal_part += *r.velocity[c] * n[c];
            }
            const bool along = normal_part != 0.0;
            const bool touching = along && any_initial_node(scene, b, r.lower, r.upper, [&](const auto& q) {
                double at = 0.0;
                for (int c = 0; c < dim; ++c) at += n[c] * q[c];
                return inside(r, q) && std::abs(at - plane.position) < 0.75 * d0;
            });
            if (touching) {
                fail_here(fmt::format("{} moves nodes that touch {} at {} m/s along its normal (the prescribed components' "
                                      "part along it): they would be driven {} it; prescribe a velocity in the plane, "
                                      "or keep the region off the plane",
                                      label, plane_label(plane, p), normal_part,
                                      plane.kind == PlaneKind::Rigid ? "into or off" : "off"));
            }
            continue;
        }
        if (!moves_along(plane.axis) || !touches(plane.axis, plane.position)) continue;
        fail_here(fmt::format("{} moves nodes that touch {} along its normal (velocity.{} = {} m/s): they would be driven "
                              "{} it; hold {} at 0 there (a clamp on the plane) or keep the region off the plane",
                              label, plane_label(plane, p), axis_letter(plane.axis, dim), *r.velocity[plane.axis],
                              plane.kind == PlaneKind::Rigid ? "into or off" : "off", axis_letter(plane.axis, dim)));
    }
}

}  // namespace

std::string_view name_of(ShapeKind s) {
    switch (s) {
        case ShapeKind::Cylinder: return "cylinder";
        case ShapeKind::Plate: return "plate";
        case ShapeKind::Rectangle: return "rectangle";
        case ShapeKind::Box: return "box";
        case ShapeKind::Sphere: return "sphere";
        case ShapeKind::Surface: return "surface";
        case ShapeKind::Nodes: return "nodes";
    }
    return "?";
}

std::string_view name_of(Discretisation d) {
    switch (d) {
        case Discretisation::Particles: return "particles";
        case Discretisation::Elements: return "elements";
    }
    return "?";
}

bool is_round(ShapeKind s) { return s == ShapeKind::Cylinder || s == ShapeKind::Plate || s == ShapeKind::Sphere; }

std::string_view name_of(NoseKind k) {
    switch (k) {
        case NoseKind::Cone: return "cone";
        case NoseKind::Hemisphere: return "hemisphere";
        case NoseKind::Ogive: return "ogive";
    }
    return "?";
}

namespace {

// The arc radius of an ogive nose, rho = CRH x 2R (scene.hpp, NoseSpec).
double ogive_arc_radius(const NoseSpec& nose, double radius) { return nose.calibre_radius * 2.0 * radius; }

}  // namespace

double nose_length(const NoseSpec& nose, double radius) {
    switch (nose.kind) {
        case NoseKind::Cone: return nose.length;
        case NoseKind::Hemisphere: return radius;
        case NoseKind::Ogive:
            // sqrt(rho^2 - (rho - R)^2), written without the difference of two nearly equal squares
            // (a long ogive, rho >> R, would lose its length to round-off).
            return std::sqrt(radius * (2.0 * ogive_arc_radius(nose, radius) - radius));
    }
    return 0.0;
}

std::vector<std::string> scene_warnings(const Scene& scene) {
    std::vector<std::string> out;
    const int dim = dimension_of(scene.geometry);
    const auto length_text = [](double m) {
        return m >= 1.0 ? fmt::format("{:.4g} m", m) : m >= 1e-3 ? fmt::format("{:.4g} mm", m * 1e3) : fmt::format("{:.4g} um", m * 1e6);
    };
    for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
        const BodySpec& b = scene.bodies[k];
        const std::string label = fmt::format("body \"{}\" (body[{}])", b.name, k);
        double speed = 0.0;
        for (int c = 0; c < dim; ++c) speed += b.velocity[static_cast<std::size_t>(c)] * b.velocity[static_cast<std::size_t>(c)];
        speed = std::sqrt(speed);
        if (speed > 20e3) {
            out.push_back(fmt::format("{}: a speed of {:.4g} km/s is beyond any impact experiment (light-gas guns reach about 10 "
                                      "km/s, orbital debris 15 km/s): check its unit (m/s, km/s, mm/us)",
                                      label, speed * 1e-3));
        }
        // The body's extents: the smallest and the largest.
        double smallest = INFINITY, largest = 0.0;
        const auto extent = [&](double e) {
            smallest = std::min(smallest, e);
            largest = std::max(largest, e);
        };
        if (!shape_known(b)) {
            continue;
        } else if (b.shape == ShapeKind::Surface || b.shape == ShapeKind::Nodes) {
            for (int c = 0; c < dim; ++c) {
                const auto [lo, hi] = gpa::extent(b, scene.geometry, c);
                extent(hi - lo);
            }
        } else if (is_round(b.shape)) {
            extent(2.0 * b.radius);
            if (b.shape != ShapeKind::Sphere) extent(b.length);
        } else {
            for (int c = 0; c < dim; ++c) extent(b.size[static_cast<std::size_t>(c)]);
        }
        if (smallest < 10e-6) {
            out.push_back(fmt::format("{}: it is {} across, smaller than any impact specimen or projectile: check the units "
                                      "of its size (m, mm, um)", label, length_text(smallest)));
        }
        if (largest > 10.0) {
            out.push_back(fmt::format("{}: it is {} across, larger than any impact specimen or target: check the units of its "
                                      "size (m, mm, um)", label, length_text(largest)));
        }
    }
    // An oblique plane under the per-direction normalisation: those factors are taken along the
    // scene's axes, so the mirror image of a node's neighbourhood across an oblique plane does not
    // have the mirror image of its factors; the ghosts' forces are then not the mirror images the
    // energy identity needs (docs/orientation.md: -0.5 % in 200 steps of a plane-strain bar).
    if (scene.solver.normalisation == Normalisation::PerDirection) {
        for (std::size_t k = 0; k < scene.planes.size(); ++k) {
            if (scene.planes[k].axis != -1) continue;
            out.push_back(fmt::format("{}: its normal is not a coordinate axis, and the per-direction normalisation (the "
                                      "default) is taken along the scene's axes, so that its ghosts are not exact mirror "
                                      "images: the energy balance closes only to about 0.5 % (docs/orientation.md); set "
                                      "solver.normalisation = \"moment-matrix\", which is the same in every orientation",
                                      plane_label(scene.planes[k], k)));
        }
    }
    if (scene.stop.end_time > 0.1) {
        out.push_back(fmt::format("stop.end_time: {:.4g} s; impacts last micro- to milliseconds and a step is a fraction of the "
                                  "time sound takes across a node: check its unit (s, ms, us)", scene.stop.end_time));
    }
    return out;
}

CellFill cell_fill(const BodySpec& b, GeometryKind g) {
    if (b.fill) return *b.fill;
    const bool round = b.shape == ShapeKind::Cylinder || b.shape == ShapeKind::Plate || b.shape == ShapeKind::Sphere;
    return g == GeometryKind::ThreeD && round ? CellFill::Trimmed : CellFill::Centres;
}

double nominal_spacing(const BodySpec& b) {
    if (b.shape == ShapeKind::Nodes) return b.node_set ? b.node_set->typical_diameter() : 0.0;
    return b.spacing;
}

double cylinder_radius_at(const BodySpec& b, double height) {
    if (!(height >= 0.0 && height <= b.length)) return 0.0;
    if (!b.nose) return b.radius;
    const double nose = nose_length(*b.nose, b.radius);
    // s: the distance into the nose from its base (negative on the shank).
    const double s = b.nose->end < 0 ? nose - height : height - (b.length - nose);
    if (s <= 0.0) return b.radius;
    const double R = b.radius;
    switch (b.nose->kind) {
        case NoseKind::Cone: return R * (1.0 - s / nose);
        case NoseKind::Hemisphere: return std::sqrt(std::max(R * R - s * s, 0.0));
        case NoseKind::Ogive: {
            // sqrt(rho^2 - s^2) - (rho - R) = R - s^2 / (rho + sqrt(rho^2 - s^2)), without cancellation.
            const double rho = ogive_arc_radius(*b.nose, R);
            return std::max(R - s * s / (rho + std::sqrt(std::max(rho * rho - s * s, 0.0))), 0.0);
        }
    }
    return R;
}


namespace {

// Body `body`'s extent along the normal of scene.planes[plane], the plane's position and the
// tolerance of "on the plane"; none unless the plane is a valid symmetry plane.
struct SymmetrySpan {
    double lo, hi, position, tolerance;
};
std::optional<SymmetrySpan> symmetry_span(const Scene& scene, std::size_t body, std::size_t plane) {
    const int dim = dimension_of(scene.geometry);
    if (body >= scene.bodies.size() || plane >= scene.planes.size()) return std::nullopt;
    const PlaneSpec& p = scene.planes[plane];
    if (p.kind != PlaneKind::Symmetry || p.axis < -1 || p.axis >= dim || !finite(p.position)) return std::nullopt;
    const BodySpec& b = scene.bodies[body];
    if (!shape_known(b)) return std::nullopt;
    const auto [lo, hi] = extent_along(b, scene.geometry, plane_normal(p));
    return SymmetrySpan{lo, hi, p.position, plane_tolerance(b, p.position)};
}

}  // namespace

bool symmetry_plane_cuts(const Scene& scene, std::size_t body, std::size_t plane) {
    const auto s = symmetry_span(scene, body, plane);
    return s && s->lo < s->position - s->tolerance && s->hi > s->position + s->tolerance;
}

bool reaches_symmetry_plane(const Scene& scene, std::size_t body, std::size_t plane) {
    const auto s = symmetry_span(scene, body, plane);
    return s && s->lo < s->position + s->tolerance && s->hi > s->position - s->tolerance;
}

int symmetry_copies(const Scene& scene, std::size_t body) {
    int copies = 1;
    std::vector<std::array<double, 3>> normals;  // of the planes counted: parallel ones count once
    for (std::size_t k = 0; k < scene.planes.size(); ++k) {
        if (!reaches_symmetry_plane(scene, body, k)) continue;
        const auto n = plane_normal(scene.planes[k]);
        const bool parallel = std::any_of(normals.begin(), normals.end(), [&](const auto& m) {
            return std::abs(std::abs(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]) - 1.0) < 1e-9;
        });
        if (parallel) continue;
        normals.push_back(n);
        copies *= 2;
    }
    return copies;
}

std::array<double, 3> plane_normal(const PlaneSpec& p) {
    if (p.axis == -1) return p.normal;
    std::array<double, 3> n{0, 0, 0};
    if (p.axis >= 0 && p.axis < 3) n[static_cast<std::size_t>(p.axis)] = 1.0;
    return n;
}

Scene rotated_scene(const Scene& scene, const Rotation& rotation) {
    const int dim = dimension_of(scene.geometry);
    if (scene.geometry == GeometryKind::Axisymmetric) {
        throw InputError("rotation: an axisymmetric scene cannot be rotated (its axis is fixed)");
    }
    if (auto problem = rotation_problem(rotation, dim)) throw InputError(fmt::format("rotation is not a rotation: {}", *problem));
    if (!scene.prescribed_velocities.empty()) {
        throw InputError("rotation: the scene has prescribed-velocity regions, which are boxes in the scene's axes and do not "
                         "turn; rotate its bodies and planes one by one instead");
    }
    Scene out = scene;
    const auto turned = [&](const std::array<double, 3>& v) {
        const auto w = gpa::turn(rotation, v);
        return dim == 3 ? w : std::array<double, 3>{w[0], w[1], 0.0};
    };
    for (BodySpec& b : out.bodies) {
        b.origin = turned(b.origin);
        b.velocity = turned(b.velocity);
        b.rotation = compose(rotation, b.rotation);
        b.initial_stress = rotate_tensor(rotation, b.initial_stress, dim);
    }
    for (PlaneSpec& p : out.planes) {
        // n' . (R x) = n . x: the position of the plane's points along its normal is unchanged.
        p.normal = turned(plane_normal(p));
        p.axis = -1;
        // A quarter turn leaves round-off (cos(pi/2) = 6e-17) where the normal lies along an axis:
        // such a normal is that axis, so that the plane keeps the aligned plane's exact reflections.
        for (int c = 0; c < dim; ++c) {
            if (std::abs(std::abs(p.normal[c]) - 1.0) < 1e-12) {
                for (int k = 0; k < 3; ++k) p.normal[k] = k == c ? (p.normal[c] > 0.0 ? 1.0 : -1.0) : 0.0;
            }
        }
        if (const auto a = aligned_axis(p.normal, dim)) {
            p.axis = a->axis;
            p.position *= a->sign;
            p.side *= a->sign;
            p.normal = {0, 0, 0};
        }
    }
    for (GaugeSpec& gauge : out.gauges) {
        if (gauge.kind != GaugeKind::Point) {
            throw InputError(fmt::format("rotation: gauge \"{}\" is a free-surface gauge, whose normal is a coordinate axis; "
                                         "it does not turn",
                                         gauge.name));
        }
        gauge.at = turned(gauge.at);
    }
    return out;
}

namespace {

// Planes in other orientations (docs/orientation.md). The symmetry planes that reach one body must
// be parallel or perpendicular to one another, so that their images make one set of mirror copies
// (GhostSet combines perpendicular planes only). A body with fixed lattice lists (fixed or
// automatic connectivity) meets a plane only through the mirror images of its lattice neighbours,
// which need the plane along one of its lattice axes (lattice_mirror_planes; the same 1e-9).
void check_orientations(const Scene& scene) {
    const int dim = dimension_of(scene.geometry);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const BodySpec& body = scene.bodies[b];
        for (std::size_t k = 0; k < scene.planes.size(); ++k) {
            if (!reaches_symmetry_plane(scene, b, k)) continue;
            for (std::size_t m = k + 1; m < scene.planes.size(); ++m) {
                if (!reaches_symmetry_plane(scene, b, m)) continue;
                const auto n = plane_normal(scene.planes[k]), o = plane_normal(scene.planes[m]);
                const double cosine = std::abs(n[0] * o[0] + n[1] * o[1] + n[2] * o[2]);
                if (cosine > 1e-9 && cosine < 1.0 - 1e-9) {
                    fail(fmt::format("{} and {} both reach {} at {:.6g} degrees to each other: the symmetry planes of one body "
                                     "must be parallel or perpendicular, so that their mirror images are copies of the whole",
                                     plane_label(scene.planes[k], k), plane_label(scene.planes[m], m), body_label(body, b),
                                     std::acos(cosine) * 180.0 / std::numbers::pi));
                }
            }
        }
        const ConnectivityMode mode = body.connectivity.value_or(scene.solver.connectivity);
        if (body.discretisation != Discretisation::Particles || body.shape == ShapeKind::Nodes || mode == ConnectivityMode::Variable) {
            continue;
        }
        for (std::size_t k = 0; k < scene.planes.size(); ++k) {
            const auto nb = turn_back(body.rotation, plane_normal(scene.planes[k]));
            int axis = 0;
            for (int c = 1; c < dim; ++c) {
                if (std::abs(nb[c]) > std::abs(nb[axis])) axis = c;
            }
            bool along = true;
            for (int c = 0; c < dim; ++c) along = along && (c == axis || std::abs(nb[c]) < 1e-9);
            if (along) continue;
            fail(fmt::format("{} uses {} connectivity, and {} is oblique to its lattice (its normal in the body's own axes is "
                             "[{:.6g}, {:.6g}{}]): fixed nodes meet a plane only through the mirror images of their lattice "
                             "neighbours, which needs the plane along a lattice axis; give the body variable connectivity, or "
                             "turn the body with the plane",
                             body_label(body, b), mode == ConnectivityMode::Fixed ? "fixed" : "automatic",
                             plane_label(scene.planes[k], k), nb[0], nb[1], dim == 3 ? fmt::format(", {:.6g}", nb[2]) : std::string()));
        }
    }
}

}  // namespace

void validate_scene(const Scene& scene) {
    const GeometryKind g = scene.geometry;
    if (g != GeometryKind::Axisymmetric && g != GeometryKind::PlaneStrain && g != GeometryKind::ThreeD) {
        fail("geometry: unknown geometry");
    }

    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
        check_material(scene.materials[i], i);
        for (std::size_t j = 0; j < i; ++j) {
            if (same_name(scene.materials[j].name, scene.materials[i].name)) {
                fail(fmt::format("{}: the name is already used by {}", material_label(scene.materials[i], i),
                                 material_label(scene.materials[j], j)));
            }
        }
    }

    if (scene.bodies.empty()) fail("body: a scene needs at least one body");
    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        check_body(scene, scene.bodies[i], i);
        for (std::size_t j = 0; j < i; ++j) {
            if (!scene.bodies[i].name.empty() && scene.bodies[j].name == scene.bodies[i].name) {
                fail(fmt::format("{}: the name is already used by body[{}]", body_label(scene.bodies[i], i), j));
            }
        }
    }

    // Planes before overlaps: a symmetry plane that cuts a body changes the nodes it is filled with.
    for (std::size_t i = 0; i < scene.planes.size(); ++i) {
        check_plane(scene, scene.planes[i], i);
        for (std::size_t j = 0; j < i; ++j) {
            if (!scene.planes[i].name.empty() && scene.planes[j].name == scene.planes[i].name) {
                fail(fmt::format("{}: the name is already used by plane[{}]", plane_label(scene.planes[i], i), j));
            }
        }
    }

    check_orientations(scene);

    for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
        for (std::size_t j = i + 1; j < scene.bodies.size(); ++j) check_overlap(scene, i, j);
    }

    // Particle and element bodies in one scene would pass through each other: nothing couples the
    // two kinds yet (the paper links them through shared boundary nodes; the engine keeps both in
    // one step so that such a coupling can be added).
    const auto elements = std::count_if(scene.bodies.begin(), scene.bodies.end(), [](const BodySpec& b) {
        return b.discretisation == Discretisation::Elements;
    });
    if (elements > 0 && elements < static_cast<std::ptrdiff_t>(scene.bodies.size())) {
        std::size_t p = 0, e = 0;
        while (scene.bodies[p].discretisation != Discretisation::Particles) ++p;
        while (scene.bodies[e].discretisation != Discretisation::Elements) ++e;
        fail(fmt::format("{} is discretised by elements but {} by particles: a scene takes one kind for all its bodies "
                         "(particle-element coupling is not implemented yet, so they would not interact)",
                         body_label(scene.bodies[e], e), body_label(scene.bodies[p], p)));
    }


    if (scene.prescribed_velocities.size() > 255) {
        fail(fmt::format("prescribed_velocity: {} regions, at most 255", scene.prescribed_velocities.size()));
    }
    for (std::size_t k = 0; k < scene.prescribed_velocities.size(); ++k) check_prescribed_velocity(scene, k);

    validate_gauges(scene);
    check_solver(scene.solver);
    check_stop(scene.stop);
    check_output(scene.output);

    for (const auto& [key, value] : scene.reference) {
        if (!finite(value)) fail(fmt::format("reference.{} = {} must be finite", key, value));
    }
}

}  // namespace gpa
