#include "gpa/engine/bodies.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

std::size_t material_index(const Scene& scene, const std::string& name, const std::string& body) {
    for (std::size_t m = 0; m < scene.materials.size(); ++m) {
        if (scene.materials[m].name == name) return m;
    }
    throw InputError(fmt::format("body \"{}\": unknown material \"{}\"", body, name));
}

namespace {

// Cells across an extent and the spacing that fits it exactly.
std::pair<std::int64_t, double> fit(double extent, double spacing, const std::string& body, const char* what) {
    if (!(extent > 0.0) || !(spacing > 0.0) || !std::isfinite(extent) || !std::isfinite(spacing)) {
        throw InputError(fmt::format("body \"{}\": {} {} m and spacing {} m must be positive", body, what, extent, spacing));
    }
    const double cells = std::max(1.0, std::round(extent / spacing));
    if (cells > 1e7) throw InputError(fmt::format("body \"{}\": {} needs {} lattice cells", body, what, cells));
    return {static_cast<std::int64_t>(cells), extent / cells};
}

// A count of lattice cells the caller computed (extent / spacing, rounded its way), refused beyond
// fit's 1e7 as fit refuses it: a size many orders beyond any impact body (a unit slip) is caught here,
// where the checks that fill lattices (overlaps, regions) meet it before the memory estimate does.
std::int64_t checked_cells(double cells, const std::string& body, const char* what) {
    if (!(cells <= 1e7)) throw InputError(fmt::format("body \"{}\": {} needs {} lattice cells", body, what, cells));
    return static_cast<std::int64_t>(cells);
}

}  // namespace

LatticeBlock body_lattice(const Scene& scene, std::size_t index) {
    const BodySpec& b = scene.bodies.at(index);
    const int dim = dimension_of(scene.geometry);
    const bool axisymmetric = scene.geometry == GeometryKind::Axisymmetric;
    LatticeBlock block;
    const double dx = b.spacing;
    const double dz = dim == 2 && b.spacing_z > 0.0 ? b.spacing_z : dx;
    const auto& o = b.origin;
    if (dim == 2) {
        switch (b.shape) {
            case ShapeKind::Cylinder:
            case ShapeKind::Plate: {
                const auto [nz, sz] = fit(b.length, dz, b.name, "length");
                const auto [nx, sx] = fit(axisymmetric ? b.radius : 2.0 * b.radius, dx, b.name, axisymmetric ? "radius" : "diameter");
                block.origin = {axisymmetric ? 0.0 : o[0] - b.radius, o[1], 0.0};
                block.spacing = {sx, sz, 1.0};
                block.last = {nx, nz, 1};
                if (b.nose) {
                    // The nose: cells whose centre lies within its profile (scene.hpp, cylinder_radius_at).
                    const double cx = axisymmetric ? 0.0 : o[0], z0 = o[1];
                    block.inside = [=](const std::array<double, 3>& p) {
                        return std::abs(p[0] - cx) < cylinder_radius_at(b, p[1] - z0);
                    };
                }
                break;
            }
            case ShapeKind::Rectangle: {
                const auto [nx, sx] = fit(b.size[0], dx, b.name, "width (x)");
                const auto [nz, sz] = fit(b.size[1], dz, b.name, "height (z)");
                block.origin = {o[0], o[1], 0.0};
                block.spacing = {sx, sz, 1.0};
                block.last = {nx, nz, 1};
                break;
            }
            case ShapeKind::Sphere: {
                const auto [n, s] = fit(axisymmetric ? b.radius : 2.0 * b.radius, dx, b.name, "radius");
                const double r = b.radius, r_in = b.inner_radius, cx = axisymmetric ? 0.0 : o[0], cz = o[1];
                const std::int64_t nz = axisymmetric ? 2 * n : n;
                block.origin = {axisymmetric ? 0.0 : cx - r, cz - r, 0.0};
                block.spacing = {s, s, 1.0};
                block.last = {n, nz, 1};
                block.inside = [=](const std::array<double, 3>& p) {
                    const double q = (p[0] - cx) * (p[0] - cx) + (p[1] - cz) * (p[1] - cz);
                    return q < r * r && q >= r_in * r_in;
                };
                break;
            }
            case ShapeKind::Box:
                throw InputError(fmt::format("body \"{}\": a box is a 3D shape; use a rectangle in 2D", b.name));
            case ShapeKind::Surface:
                throw InputError(fmt::format("body \"{}\": a surface is a 3D shape", b.name));
            case ShapeKind::Nodes:
                throw InputError(fmt::format("body \"{}\": its nodes are imported; it has no lattice", b.name));
        }
    } else {
        switch (b.shape) {
            case ShapeKind::Cylinder:
            case ShapeKind::Plate: {
                const auto [nz, s] = fit(b.length, dx, b.name, "length");
                const std::int64_t half = checked_cells(std::ceil(b.radius / s - 1e-9), b.name, "radius");
                const double r = b.radius, cx = o[0], cy = o[1];
                block.origin = {cx, cy, o[2]};
                block.spacing = {s, s, s};
                block.first = {-half, -half, 0};
                block.last = {half, half, nz};
                const double z0 = o[2];
                block.inside = [=](const std::array<double, 3>& p) {
                    const double radius = b.nose ? cylinder_radius_at(b, p[2] - z0) : r;
                    return (p[0] - cx) * (p[0] - cx) + (p[1] - cy) * (p[1] - cy) < radius * radius;
                };
                break;
            }
            case ShapeKind::Box: {
                const auto [nz, s] = fit(b.size[2], dx, b.name, "size z");
                block.origin = o;
                block.spacing = {s, s, s};
                block.last = {std::max<std::int64_t>(1, checked_cells(std::round(b.size[0] / s), b.name, "size x")),
                              std::max<std::int64_t>(1, checked_cells(std::round(b.size[1] / s), b.name, "size y")), nz};
                break;
            }
            case ShapeKind::Sphere: {
                const auto [n, s] = fit(2.0 * b.radius, dx, b.name, "diameter");
                const double r = b.radius, r_in = b.inner_radius;
                const auto c = o;
                block.origin = {c[0] - r, c[1] - r, c[2] - r};
                block.spacing = {s, s, s};
                block.last = {n, n, n};
                block.inside = [=](const std::array<double, 3>& p) {
                    double q = 0.0;
                    for (int k = 0; k < 3; ++k) q += (p[k] - c[k]) * (p[k] - c[k]);
                    return q < r * r && q >= r_in * r_in;
                };
                break;
            }
            case ShapeKind::Rectangle:
                throw InputError(fmt::format("body \"{}\": a rectangle is a 2D shape; use a box in 3D", b.name));
            case ShapeKind::Nodes:
                throw InputError(fmt::format("body \"{}\": its nodes are imported; it has no lattice", b.name));
            case ShapeKind::Surface: {
                // The cells of the spacing as given, from the lower corner of the surface's box (moved
                // by the origin), across its extent; those whose centre is inside are filled.
                if (!b.surface) {
                    throw InputError(fmt::format("body \"{}\": its surface (file \"{}\") has not been read: read the scene with "
                                                 "io::load_scene, or call io::resolve_scene_files",
                                                 b.name, b.surface_file));
                }
                const std::shared_ptr<const SurfaceInside> inside = b.surface;
                const double s = b.spacing;
                block.origin = {o[0] + inside->lower()[0], o[1] + inside->lower()[1], o[2] + inside->lower()[2]};
                block.spacing = {s, s, s};
                for (int c = 0; c < 3; ++c) {
                    const double cells = std::ceil((inside->upper()[c] - inside->lower()[c]) / s - 1e-9);
                    if (!(cells >= 1.0) || cells > 1e7) {
                        throw InputError(fmt::format("body \"{}\": its surface needs {} lattice cells along axis {} at spacing {} m",
                                                     b.name, cells, c, s));
                    }
                    block.last[static_cast<std::size_t>(c)] = static_cast<std::int64_t>(cells);
                }
                block.inside = [inside, o](const std::array<double, 3>& p) {
                    return inside->inside({p[0] - o[0], p[1] - o[1], p[2] - o[2]});
                };
                break;
            }
        }
    }
    // A symmetry plane through the body keeps the cells on its side (a half or quarter model). It
    // must lie on a face of the body's cells: the ghost of a node s/2 from the plane is then s/2
    // behind it, where the full body's lattice has its mirror node, and fixed lists continue across
    // it (fill_lattice).
    // A turned body (or an oblique plane) is cut in the body's own axes, where the plane must lie
    // along a lattice axis.
    block.rotation = b.rotation;
    block.pivot = b.origin;
    block.trim = cell_fill(b, scene.geometry) == CellFill::Trimmed;
    for (std::size_t k = 0; k < scene.planes.size(); ++k) {
        if (!symmetry_plane_cuts(scene, index, k)) continue;
        const PlaneSpec& given = scene.planes[k];
        MirrorPlane own{given.axis, given.position, given.side, 0, given.normal};
        const auto in_block = lattice_mirror_planes(block, {own}, dim);
        if (in_block.empty()) {
            const auto n = plane_normal(given);
            throw InputError(fmt::format(
                "plane \"{}\" (plane[{}]) with normal [{:.6g}, {:.6g}{}] cuts body \"{}\" obliquely to its lattice: a "
                "symmetry plane through a body must lie along the body's lattice axes (turned with its rotation), so "
                "that its ghosts continue the lattice",
                given.name, k, n[0], n[1], dim == 3 ? fmt::format(", {:.6g}", n[2]) : std::string(), b.name));
        }
        const MirrorPlane& plane = in_block.front();
        const auto a = static_cast<std::size_t>(plane.axis);
        const double cells = (plane.position - block.origin[a]) / block.spacing[a];
        if (std::abs(cells - std::round(cells)) > 1e-6) {
            const double below = block.origin[a] + std::floor(cells) * block.spacing[a];
            const char letter = axis_letter(static_cast<int>(a), dim);
            throw InputError(fmt::format(
                "plane \"{}\" (plane[{}]) at {} = {} m{} cuts body \"{}\" between two faces of its lattice's cells ({} = {} m "
                "and {} m): a symmetry plane through a body must lie on a cell face, so that its ghosts continue the "
                "lattice; move the plane or the body's origin (a cylinder's or sphere's cell faces pass through its centre "
                "in 3D; in 2D when it is an even number of cells across)",
                given.name, k, letter, plane.position, is_identity(b.rotation) && given.axis >= 0 ? "" : " (in the body's own axes)",
                b.name, letter, below, below + block.spacing[a]));
        }
        const double position = plane.position;
        const int side = plane.side;
        block.inside = [inner = std::move(block.inside), a, position, side](const std::array<double, 3>& p) {
            return side * (p[a] - position) > 0.0 && (!inner || inner(p));
        };
    }
    return block;
}

// Bisection on eps_v in (-0.5, 1) (bodies.hpp).
double initial_volumetric_strain(const materials::Material& m, double p, const std::string& body) {
    if (p == 0.0) return 0.0;
    const auto pressure_at = [&](double eps_v) {
        return materials::evaluate_eos(m.eos, m.density, m.density / (1.0 + eps_v), 0.0).pressure;
    };
    double lo = -0.5, hi = 1.0;
    if ((pressure_at(lo) - p) * (pressure_at(hi) - p) > 0.0) {
        throw InputError(fmt::format("body \"{}\": initial mean stress {} Pa is beyond what the equation of state of "
                                     "\"{}\" reaches", body, -p, m.name));
    }
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        // pressure falls as eps_v grows (expansion)
        if (pressure_at(mid) > p) lo = mid; else hi = mid;
    }
    return 0.5 * (lo + hi);
}

std::vector<RingNode> ring_fill(const BodySpec& b) {
    const double spacing = b.spacing;
    const auto [layers, height] = fit(b.length, spacing, b.name, "length");
    if (!(b.radius > 0.0) || !std::isfinite(b.radius)) {
        throw InputError(fmt::format("body \"{}\": radius {} m must be positive", b.name, b.radius));
    }
    checked_cells(std::round(b.radius / spacing), b.name, "radius");
    // The layers along the axis: height, volume and the height of the volume's centroid.
    struct Layer {
        double height = 0.0, volume = 0.0, centroid = 0.0;
    };
    std::vector<Layer> slabs;
    for (std::int64_t k = 0; k < layers; ++k) {
        const double bottom = static_cast<double>(k) * height;
        Layer layer{height, std::numbers::pi * b.radius * b.radius * height, bottom + 0.5 * height};
        if (b.nose) {
            // Over a nose, pi r(z)^2 and z pi r(z)^2 integrated by Simpson's rule on 64 intervals:
            // exact where r^2 is quadratic in z (the cone, the hemisphere) but for the kink at the
            // nose's base within a layer (tests/test_fill.cpp measured the body's volume off by
            // 2e-7 with a cone, 1e-10 with the other noses).
            constexpr int intervals = 64;
            double volume = 0.0, moment = 0.0;
            for (int q = 0; q <= intervals; ++q) {
                const double z = bottom + height * q / intervals;
                const double r = cylinder_radius_at(b, z);
                const double weight = q == 0 || q == intervals ? 1.0 : (q % 2 ? 4.0 : 2.0);
                volume += weight * std::numbers::pi * r * r;
                moment += weight * z * std::numbers::pi * r * r;
            }
            layer.volume = volume * height / (3.0 * intervals);
            layer.centroid = layer.volume > 0.0 ? moment * height / (3.0 * intervals) / layer.volume : layer.centroid;
        }
        if (layer.volume > 0.0) slabs.push_back(layer);
    }
    // A layer less than half a spacing in radius (the last of a cone or an ogive) joins its larger
    // neighbour, so that no ring is a sliver (a small d0 would shorten the stable step).
    const auto thin = [&](const Layer& l) { return l.volume < std::numbers::pi * 0.25 * spacing * spacing * l.height; };
    for (std::size_t k = 0; slabs.size() > 1 && k < slabs.size();) {
        if (!thin(slabs[k])) {
            ++k;
            continue;
        }
        const std::size_t other = k == 0 ? 1 : k + 1 == slabs.size() ? k - 1 : (slabs[k - 1].volume > slabs[k + 1].volume ? k - 1 : k + 1);
        Layer& into = slabs[other];
        const Layer& from = slabs[k];
        into.centroid = (into.centroid * into.volume + from.centroid * from.volume) / (into.volume + from.volume);
        into.volume += from.volume;
        into.height += from.height;
        slabs.erase(slabs.begin() + static_cast<std::ptrdiff_t>(k));
        k = 0;
    }
    std::vector<RingNode> out;
    for (const Layer& layer : slabs) {
        // Rings over the radius of the cylinder of the layer's volume and height.
        const double radius = std::sqrt(layer.volume / (std::numbers::pi * layer.height));
        const auto rings = static_cast<int>(std::max(1.0, std::round(radius / spacing)));
        const double width = radius / rings;
        for (int m = 0; m < rings; ++m) {
            const double r = (m + 0.5) * width;
            // A multiple of 4 of nodes about a spacing apart along the ring: at the angles (q + 1/2)
            // 2 pi / count the ring is its own mirror image across x = 0 and y = 0 with no node on
            // either (an even count that is not a multiple of 4 puts a node on x = 0).
            const int count = 4 * std::max(1, static_cast<int>(std::lround(0.5 * std::numbers::pi * r / spacing)));
            const double each = std::numbers::pi * (2 * m + 1) * width * width * layer.height / count;
            for (int q = 0; q < count; ++q) {
                const double angle = (q + 0.5) * 2.0 * std::numbers::pi / count;
                out.push_back({{r * std::cos(angle), r * std::sin(angle), layer.centroid}, each});
            }
        }
    }
    return out;
}

namespace {

// Appends body `index`'s lattice (body_lattice, fill_lattice) with its fixed lists.
std::size_t add_lattice_nodes(NodeStore& nodes, const Scene& scene, std::size_t index, std::size_t material,
                              const std::vector<MirrorPlane>& mirrors) {
    const BodySpec& b = scene.bodies.at(index);
    LatticeBlock block = body_lattice(scene, index);
    block.density = scene.materials[material].density;
    block.velocity = b.velocity;
    block.body = static_cast<std::int32_t>(index);
    block.material = static_cast<std::int32_t>(material);
    const ConnectivityMode mode = b.connectivity.value_or(scene.solver.connectivity);
    block.connectivity = mode == ConnectivityMode::Variable ? Connectivity::Variable : Connectivity::Fixed;
    const int dim = nodes.dim();
    block.lattice_neighbours = b.lattice_neighbours ? b.lattice_neighbours : (dim == 3 ? 26 : 8);
    // The default stencil is the neighbourhood of the undeformed lattice: the box of 8 (26) at
    // a <= 1, and every lattice node within 2 a spacings beyond it (spec section 2: r < 2 h, h =
    // a d0), so that fixed and variable nodes see the same neighbours until the lattice deforms.
    if (b.lattice_neighbours == 0 && scene.solver.influence_distance > 1.0) block.stencil_reach = 2.0 * scene.solver.influence_distance;
    block.mirror_planes = lattice_mirror_planes(block, mirrors, dim);
    const std::size_t first = fill_lattice(nodes, block);
    if (nodes.size() == first) {
        throw InputError(fmt::format("body \"{}\": its lattice holds no node (spacing {} m too coarse for its size)", b.name, b.spacing));
    }
    return first;
}

// Appends `count` nodes of body `index` that no lattice holds, as fill_lattice appends a lattice's:
// node k at offset(k) from the body's origin in the body's own axes (turned by its rotation), of
// size size(k) (a volume; in 2D a section, axisymmetric: of its ring) and diameter diameter(k),
// with variable connectivity and no fixed lists.
template <class Offset, class Size, class Diameter>
std::size_t add_free_nodes(NodeStore& nodes, const Scene& scene, std::size_t index, std::size_t material, std::size_t count,
                           Offset offset, Size size_of, Diameter diameter_of) {
    const BodySpec& b = scene.bodies.at(index);
    const int dim = nodes.dim();
    const double density = scene.materials[material].density;
    const std::size_t first = nodes.size();
    nodes.resize(first + count);
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t i = first + k;
        const std::array<double, 3> given = offset(k);
        const std::array<double, 3> x = is_identity(b.rotation) ? given : turn(b.rotation, given);
        for (int c = 0; c < dim; ++c) {
            nodes.position[c][i] = x[c] + b.origin[c];
            nodes.initial_position[c][i] = nodes.position[c][i];
            nodes.velocity[c][i] = b.velocity[c];
        }
        // As for a lattice cell (fill_lattice): the ring of section A in axisymmetric geometry.
        const double size = size_of(k);
        const double v0 = nodes.geometry() == GeometryKind::Axisymmetric ? 2.0 * std::numbers::pi * nodes.position[0][i] * size : size;
        nodes.initial_volume[i] = v0;
        nodes.volume[i] = v0;
        nodes.mass[i] = density * v0;
        nodes.initial_diameter[i] = diameter_of(k);
        nodes.diameter[i] = nodes.initial_diameter[i];
        if (dim == 3) {
            for (int c = 0; c < 6; ++c) nodes.left_cauchy_green[c][i] = c < 3 ? 1.0 : 0.0;
        }
        nodes.body[i] = static_cast<std::int32_t>(index);
        nodes.id[i] = static_cast<std::uint32_t>(i);  // the fill order (node_store.hpp)
        nodes.material[i] = static_cast<std::int32_t>(material);
        nodes.connectivity[i] = Connectivity::Variable;
    }
    // No fixed lists: the resize above gave every new node an empty row (or none, while no node
    // has lattice neighbours: node_store.hpp).
    return first;
}

// Appends the imported nodes of body `index` (node_set.hpp), each with its own volume and diameter.
std::size_t add_imported_nodes(NodeStore& nodes, const Scene& scene, std::size_t index, std::size_t material) {
    const BodySpec& b = scene.bodies.at(index);
    if (!b.node_set) {
        throw InputError(fmt::format("body \"{}\": its nodes (file \"{}\") have not been read: read the scene with "
                                     "io::load_scene, or call io::resolve_scene_files",
                                     b.name, b.surface_file));
    }
    const NodeSetShape& set = *b.node_set;
    const int dim = nodes.dim();
    if (set.dim() != dim) throw InputError(fmt::format("body \"{}\": its node set is {}D, the scene {}D", b.name, set.dim(), dim));
    // The file's coordinates are offsets from the origin.
    return add_free_nodes(
        nodes, scene, index, material, set.size(),
        [&](std::size_t k) {
            const auto& given = set.set().positions[k];
            return std::array<double, 3>{given[0], given[1], dim == 3 ? given[2] : 0.0};
        },
        [&](std::size_t k) { return set.set().sizes[k]; }, [&](std::size_t k) { return set.diameter(k); });
}

// Appends the rings of body `index` (ring_fill) on the kept side of every symmetry plane that cuts
// it (scene.cpp admits only planes through its axis along its own x or y, across which the rings
// are their own mirror images, so that the planes' ghosts continue the body). A node's diameter
// is the side of the cube of its volume, as for imported nodes.
std::size_t add_ring_nodes(NodeStore& nodes, const Scene& scene, std::size_t index, std::size_t material) {
    const BodySpec& b = scene.bodies.at(index);
    std::vector<RingNode> rings = ring_fill(b);
    for (std::size_t k = 0; k < scene.planes.size(); ++k) {
        if (!symmetry_plane_cuts(scene, index, k)) continue;
        const PlaneSpec& plane = scene.planes[k];
        const auto n = plane_normal(plane);
        std::erase_if(rings, [&](const RingNode& node) {
            const std::array<double, 3> x = is_identity(b.rotation) ? node.position : turn(b.rotation, node.position);
            double along = -plane.position;
            for (int c = 0; c < 3; ++c) along += n[c] * (x[c] + b.origin[c]);
            return !(plane.side * along > 0.0);
        });
    }
    if (rings.empty()) throw InputError(fmt::format("body \"{}\": its rings hold no node", b.name));
    return add_free_nodes(
        nodes, scene, index, material, rings.size(), [&](std::size_t k) { return rings[k].position; },
        [&](std::size_t k) { return rings[k].volume; }, [&](std::size_t k) { return std::cbrt(rings[k].volume); });
}

}  // namespace

std::size_t add_body_nodes(NodeStore& nodes, const Scene& scene, std::size_t index, const std::vector<MirrorPlane>& mirrors) {
    const BodySpec& b = scene.bodies.at(index);
    const std::size_t material = material_index(scene, b.material, b.name);
    const auto& mat = scene.materials[material];
    const int dim = nodes.dim();
    const bool rings = b.shape != ShapeKind::Nodes && dim == 3 && cell_fill(b, scene.geometry) == CellFill::Rings;
    const std::size_t first = b.shape == ShapeKind::Nodes ? add_imported_nodes(nodes, scene, index, material)
                              : rings                     ? add_ring_nodes(nodes, scene, index, material)
                                                          : add_lattice_nodes(nodes, scene, index, material, mirrors);
    // Initial stress: deviator into s, mean stress into an initial compression.
    const auto& sig = b.initial_stress;
    const double mean = dim == 2 ? (sig[0] + sig[1] + sig[3]) / 3.0 : (sig[0] + sig[1] + sig[2]) / 3.0;
    const double eps_v = initial_volumetric_strain(mat, -mean, b.name);
    for (std::size_t i = first; i < nodes.size(); ++i) {
        for (int c = 0; c < stress_components(dim); ++c) {
            const bool normal = dim == 2 ? (c != 2) : (c < 3);
            nodes.deviatoric_stress[c][i] = sig[c] - (normal ? mean : 0.0);
        }
        nodes.volumetric_strain[i] = eps_v;
        nodes.volume[i] = nodes.initial_volume[i] * (1.0 + eps_v);
        nodes.temperature[i] = mat.room_temperature;
    }
    update_size_weights(nodes, first, nodes.size());
    return first;
}

}  // namespace gpa
