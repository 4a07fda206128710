#include "gpa/io/scene_file.hpp"
#include "gpa/io/node_file.hpp"
#include "gpa/io/stl.hpp"

#include <new>
#include "gpa/io/reference.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
#include <system_error>

#include <fmt/format.h>

#include "gpa/io/material_library.hpp"
#include "material_table.hpp"
#include "solver_reading.hpp"
#include "toml_reading.hpp"

namespace gpa::io {

namespace {

using namespace detail;
using D = Dimension;

constexpr std::uintmax_t max_scene_file_bytes = 16u << 20;

const std::vector<std::string_view> scene_keys{
    "name", "description", "geometry", "material", "body", "plane", "prescribed_velocity", "gauge", "solver", "stop",
    "output", "reference", "rotation",
};
const std::vector<std::string_view> body_keys{
    "name",    "shape",     "material", "origin",         "size",         "radius",            "diameter",
    "length",  "spacing",   "spacing_z", "velocity",      "initial_stress", "connectivity",    "lattice_neighbours",
    "discretisation", "inner_radius", "nose", "file", "unit", "rotation", "fill",
};
const std::vector<std::string_view> plane_keys{"name", "kind", "axis", "position", "normal", "point", "side", "lift_off",
                                               "friction", "static_friction"};
const std::vector<std::string_view> gauge_keys{"name", "kind", "at", "body", "radius", "normal", "fields"};
const std::vector<std::string_view> prescribed_keys{"name", "body", "region", "velocity", "ramp"};
const std::vector<std::string_view> region_keys{"box", "above", "below", "beyond_radius", "within_radius"};
const std::vector<std::string_view> stop_keys{"end_time", "kinetic_energy_fraction", "max_steps", "energy_error"};
const std::vector<std::string_view> output_keys{"snapshots", "snapshot_interval", "history_every", "checkpoint_every", "fields", "precision",
                                                "peak_radius"};

const Choices<ConnectivityMode> connectivity_words{
    {"fixed", ConnectivityMode::Fixed}, {"variable", ConnectivityMode::Variable}, {"automatic", ConnectivityMode::Automatic}};

// --- the scene's materials ----------------------------------------------------------------

// The materials a scene defines, plus library materials as bodies name them.
class SceneMaterials {
public:
    explicit SceneMaterials(std::vector<materials::Material> defined) : materials_(std::move(defined)) {}

    // The scene's name for `name` (letter case ignored), adding a library material on first use.
    std::optional<std::string> resolve(std::string_view name) {
        for (const auto& m : materials_) {
            if (same_name(m.name, name)) return m.name;
        }
        if (const auto* m = find_builtin_material(name)) {
            materials_.push_back(*m);
            return m->name;
        }
        return std::nullopt;
    }

    std::string known_names() const {
        std::string names;
        for (const auto& m : materials_) names += (names.empty() ? "" : ", ") + m.name;
        for (const auto& m : builtin_materials()) {
            bool listed = false;
            for (const auto& own : materials_) listed = listed || same_name(own.name, m.name);
            if (!listed) names += (names.empty() ? "" : ", ") + m.name;
        }
        return names;
    }

    std::vector<materials::Material> take() { return std::move(materials_); }

private:
    std::vector<materials::Material> materials_;
};

// --- helpers ---------------------------------------------------------------------------------

std::string labelled_path(std::string_view kind, const toml::table& table, std::size_t index) {
    if (const toml::node* name = table.get("name")) {
        if (const auto* s = name->as_string()) return fmt::format("{} {} ({}[{}])", kind, in_quotes(s->get()), kind, index);
    }
    return fmt::format("{}[{}]", kind, index);
}

// The tables of an array-of-tables key ([[body]], [[plane]]).
std::vector<const toml::table*> tables_of(const TableReader& top, std::string_view key) {
    std::vector<const toml::table*> out;
    const toml::node* node = top.find(key);
    if (!node) return out;
    const auto* array = node->as_array();
    if (!array) {
        top.fail_at(key, fmt::format("expected [[{}]] tables (an array of tables), got {}: write [[{}]] above each {}",
                                     key, type_name(*node), key, key));
    }
    for (std::size_t i = 0; i < array->size(); ++i) {
        const toml::node& element = (*array)[i];
        const auto* table = element.as_table();
        if (!table) {
            top.reporter().fail(line_of(element), fmt::format("{}[{}]", key, i),
                                fmt::format("expected a table, got {}", type_name(element)));
        }
        out.push_back(table);
    }
    return out;
}

// A sub-table such as [solver]; an absent one reads as empty.
const toml::table& sub_table(const TableReader& top, std::string_view key, const toml::table& empty) {
    const toml::node* node = top.find(key);
    if (!node) return empty;
    const auto* table = node->as_table();
    if (!table) top.fail_at(key, fmt::format("expected a table ([{}]), got {}", key, type_name(*node)));
    return *table;
}

std::string_view scene_phrase(GeometryKind g) {
    switch (g) {
        case GeometryKind::Axisymmetric: return "an axisymmetric scene";
        case GeometryKind::PlaneStrain: return "a plane-strain scene";
        case GeometryKind::ThreeD: break;
    }
    return "a 3D scene";
}

std::string_view components_of(int dim) { return dim == 2 ? "[x, z]" : "[x, y, z]"; }

// Each component below the speed of light (Limit::BelowLightSpeed) may still add up to a speed
// beyond it.
void check_speed(const TableReader& r, std::string_view key, const std::array<double, 3>& v) {
    const double speed = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(speed < speed_of_light)) {
        r.fail_at(key, fmt::format("a speed of {:.4g} m/s is out of range: a velocity must be below the speed of light, {} m/s", speed,
                                   speed_of_light));
    }
}

std::array<double, 3> to_vector3(const std::vector<double>& v) {
    std::array<double, 3> out{0, 0, 0};
    for (std::size_t i = 0; i < v.size() && i < 3; ++i) out[i] = v[i];
    return out;
}

// The unit vector along the first dim components of v, written in any length: nothing for a zero
// vector. A power of two brings the largest component near 1 first (exactly), so that lengths
// beyond the range of a double's square ([1e200, 1e200, 0]) normalise as well as any other.
std::optional<std::array<double, 3>> direction_of(const std::array<double, 3>& v, int dim) {
    double largest = 0.0;
    for (int c = 0; c < dim; ++c) largest = std::max(largest, std::abs(v[c]));
    if (!(largest > 0.0) || !std::isfinite(largest)) return std::nullopt;
    int exponent = 0;
    std::frexp(largest, &exponent);
    std::array<double, 3> scaled{0, 0, 0};
    for (int c = 0; c < dim; ++c) scaled[c] = std::ldexp(v[c], -exponent);
    return unit_vector(scaled, dim);
}

// `rotation = { axis = [x, y, z], angle = "30 deg" }` (3D) or `rotation = { angle = "30 deg" }`
// (plane strain) in the table `r` reads, a body's or the scene's (`in_axisymmetric` names it in an
// axisymmetric scene, for the message); nothing when the key is absent. Axisymmetric scenes have no
// rotations: their axis is fixed.
std::optional<Rotation> read_rotation(const TableReader& r, GeometryKind geometry, std::string_view in_axisymmetric) {
    const toml::node* node = r.find("rotation");
    if (!node) return std::nullopt;
    const int dim = dimension_of(geometry);
    if (geometry == GeometryKind::Axisymmetric) {
        r.fail_at("rotation", fmt::format("does not apply to {}: its symmetry axis is fixed along z (bodies and scenes turn in "
                                          "plane-strain and 3d scenes)", in_axisymmetric));
    }
    const std::string_view example = dim == 3 ? "{ axis = [0, 0, 1], angle = \"30 deg\" }" : "{ angle = \"30 deg\" }";
    const auto* table = node->as_table();
    if (!table) r.fail_at("rotation", fmt::format("expected a table such as {}, got {}", example, as_written(*node)));
    const TableReader t(r.reporter(), *table, r.key_path("rotation"), "a rotation", {"axis", "angle"});
    if (dim == 2 && t.has("axis")) {
        t.fail_at("axis", "does not apply in a plane-strain scene: a rotation there turns the (x, z) plane about y; give "
                          "angle only (positive from x towards z)");
    }
    const double angle = t.required_quantity("angle", D::Angle);
    if (!(std::abs(angle) <= 2.0 * std::numbers::pi)) {
        t.fail_at("angle", fmt::format("{:.6g} rad ({:.6g} deg) is more than a full turn: give an angle from -360 to 360 deg (a "
                                       "plain number is in radians; write degrees as \"30 deg\")", angle, angle * 180.0 / std::numbers::pi));
    }
    if (dim == 2) return rotation_in_plane(angle);
    const auto axis = t.quantities("axis", D::Dimensionless, 3, Limit::Any, "[x, y, z]");
    if (!axis) t.fail_missing("axis", "the direction the rotation turns about, [x, y, z] of any length, e.g. [0, 0, 1]");
    const auto unit = direction_of(to_vector3(*axis), 3);
    if (!unit) t.fail_at("axis", "is a zero vector: give a direction to turn about, [x, y, z] of any length, e.g. [0, 0, 1]");
    return rotation_about(*unit, angle);
}

// --- bodies ----------------------------------------------------------------------------------

std::array<double, 6> read_initial_stress(const TableReader& body, GeometryKind geometry) {
    const int dim = dimension_of(geometry);
    const std::vector<std::string_view> names =
        dim == 3 ? std::vector<std::string_view>{"xx", "yy", "zz", "yz", "xz", "xy"}
        : geometry == GeometryKind::Axisymmetric ? std::vector<std::string_view>{"xx", "zz", "xz", "tt"}
                                                 : std::vector<std::string_view>{"xx", "zz", "xz", "yy"};
    std::string order = "[";
    for (std::size_t i = 0; i < names.size(); ++i) order += (i ? ", " : "") + std::string(names[i]);
    order += "]";

    std::array<double, 6> stress{0, 0, 0, 0, 0, 0};
    const toml::node* node = body.find("initial_stress");
    if (const auto* table = node->as_table()) {
        const TableReader t(body.reporter(), *table, body.key_path("initial_stress"),
                            fmt::format("the initial stress in {}", scene_phrase(geometry)), names);
        for (std::size_t i = 0; i < names.size(); ++i) {
            if (const auto v = t.quantity(names[i], D::Pressure)) stress[i] = *v;
        }
        return stress;
    }
    if (!node->as_array()) {
        body.fail_at("initial_stress", fmt::format("expected a table of stress components ({} = ...) or an array {}, got {}",
                                                   names[0], order, type_name(*node)));
    }
    const auto values = body.quantities("initial_stress", D::Pressure, names.size(), Limit::Any, order);
    for (std::size_t i = 0; i < values->size(); ++i) stress[i] = (*values)[i];
    return stress;
}

BodySpec read_body(const Reporter& reporter, const toml::table& table, std::size_t index, GeometryKind geometry,
                   SceneMaterials& scene_materials) {
    const TableReader r(reporter, table, labelled_path("body", table, index), "a body", body_keys);
    const int dim = dimension_of(geometry);
    BodySpec b;
    b.name = r.string("name").value_or(fmt::format("body{}", index));
    if (b.name.empty()) r.fail_at("name", "a body's name must not be empty (leave the key out for \"body<index>\")");

    const auto shape = r.choice<ShapeKind>("shape", {{"cylinder", ShapeKind::Cylinder},
                                                     {"plate", ShapeKind::Plate},
                                                     {"rectangle", ShapeKind::Rectangle},
                                                     {"box", ShapeKind::Box},
                                                     {"sphere", ShapeKind::Sphere},
                                                     {"surface", ShapeKind::Surface},
                                                     {"nodes", ShapeKind::Nodes}});
    if (!shape) r.fail_missing("shape", "cylinder, plate, rectangle, box, sphere, surface or nodes");
    b.shape = *shape;
    if (b.shape == ShapeKind::Surface && dim == 2) {
        r.fail_at("shape", fmt::format("\"surface\" (a closed triangulated surface from an STL file) is a 3D shape; {} takes "
                                       "cylinder, plate, rectangle or sphere", scene_phrase(geometry)));
    }
    if (b.shape == ShapeKind::Box && dim == 2) {
        r.fail_at("shape", fmt::format("\"box\" is a 3D shape; {} takes cylinder, plate, rectangle or sphere",
                                       scene_phrase(geometry)));
    }
    if (b.shape == ShapeKind::Rectangle && dim == 3) {
        r.fail_at("shape", "\"rectangle\" is a 2D shape; a 3D scene takes cylinder, plate, box or sphere");
    }

    const std::string material = r.required_string("material", "a library material or a scene [[material]] name");
    if (const auto resolved = scene_materials.resolve(material)) {
        b.material = *resolved;
    } else {
        r.fail_at("material", fmt::format("unknown material {}; known materials: {} (or define it in a [[material]] table)",
                                          in_quotes(material), scene_materials.known_names()));
    }

    const std::string_view components = components_of(dim);
    if (const auto origin = r.quantities("origin", D::Length, static_cast<std::size_t>(dim), Limit::Any, components)) {
        b.origin = to_vector3(*origin);
    }

    const std::string_view shape_name = name_of(b.shape);
    const bool imported = b.shape == ShapeKind::Surface || b.shape == ShapeKind::Nodes;
    if (imported) {
        const bool surface = b.shape == ShapeKind::Surface;
        const std::string what = surface ? "the STL file of the closed surface" : "the CSV or VTK file of the nodes";
        for (const std::string_view key : {"radius", "diameter", "length", "size", "inner_radius", "nose"}) {
            if (r.has(key)) {
                r.fail_at(key, surface ? "does not apply to a surface (its STL file gives its shape)"
                                       : "does not apply to imported nodes (their file gives their positions and sizes)");
            }
        }
        for (const std::string_view key : {"spacing", "spacing_z", "lattice_neighbours", "fill"}) {
            if (!surface && r.has(key)) {
                r.fail_at(key, "does not apply to imported nodes: they have no lattice (their file gives each node's size)");
            }
        }
        b.surface_file = r.required_string("file", what + ", relative to the scene file");
        if (b.surface_file.empty()) r.fail_at("file", "is empty: give " + what);
        // The unit of the file's numbers: a length unit ("mm") or a length ("25.4 mm").
        const std::string unit = r.required_string("unit", surface ? "the length unit of the STL file's numbers, e.g. \"mm\""
                                                                    : "the length unit of the positions (sizes in its square "
                                                                      "or cube), e.g. \"mm\"");
        std::optional<double> metres;
        for (const std::string& text : {unit, "1 " + unit}) {
            if (metres) break;
            try {
                metres = parse_quantity(text, D::Length);
            } catch (const std::exception&) {
            }
        }
        if (!metres || !(*metres > 0.0)) {
            r.fail_at("unit", fmt::format("\"{}\" is not a length unit (m, mm, um, in, ...) nor a positive length", unit));
        }
        b.surface_unit = *metres;
    } else if (is_round(b.shape)) {
        if (r.has("radius") && r.has("diameter")) r.fail_at("diameter", "give radius or diameter, not both");
        if (const auto radius = r.quantity("radius", D::Length, Limit::Positive)) {
            b.radius = *radius;
        } else if (const auto diameter = r.quantity("diameter", D::Length, Limit::Positive)) {
            b.radius = 0.5 * *diameter;
        } else {
            r.fail_missing("radius", fmt::format("or diameter: the size of the {}", shape_name));
        }
        if (r.has("size")) {
            r.fail_at("size", fmt::format("does not apply to a {} (give radius{})", shape_name,
                                          b.shape == ShapeKind::Sphere ? "" : " and length"));
        }
    } else {
        for (const std::string_view key : {"radius", "diameter", "length"}) {
            if (r.has(key)) r.fail_at(key, fmt::format("does not apply to a {} (give size = {})", shape_name, components));
        }
        const auto size = r.quantities("size", D::Length, static_cast<std::size_t>(dim), Limit::Positive, components);
        if (!size) r.fail_missing("size", fmt::format("the {}'s edge lengths {}", shape_name, components));
        b.size = to_vector3(*size);
    }
    if (b.shape == ShapeKind::Cylinder || b.shape == ShapeKind::Plate) {
        const auto length = r.quantity("length", D::Length, Limit::Positive);
        if (!length) r.fail_missing("length", fmt::format("the {}'s length along z", shape_name));
        b.length = *length;
    } else if (b.shape == ShapeKind::Sphere && r.has("length")) {
        r.fail_at("length", "does not apply to a sphere (give radius or diameter)");
    }
    if (!imported) {
        for (const std::string_view key : {"file", "unit"}) {
            if (r.has(key)) {
                r.fail_at(key, fmt::format("applies to a surface or imported nodes only (shape = \"surface\" or \"nodes\"), "
                                           "not a {}", shape_name));
            }
        }
    }
    if (r.has("inner_radius")) {
        if (b.shape != ShapeKind::Sphere) {
            r.fail_at("inner_radius", fmt::format("applies to a sphere only (a hollow sphere; a ring in plane strain), not a {}",
                                                  shape_name));
        }
        b.inner_radius = *r.quantity("inner_radius", D::Length, Limit::NonNegative);
        if (!(b.inner_radius < b.radius)) {
            r.fail_at("inner_radius", fmt::format("{} m must be less than the radius, {} m: nothing would be left of the {}",
                                                  b.inner_radius, b.radius, geometry == GeometryKind::PlaneStrain ? "ring" : "shell"));
        }
    }

    if (const toml::node* nose = r.find("nose")) {
        if (b.shape != ShapeKind::Cylinder) r.fail_at("nose", fmt::format("applies to a cylinder only, not a {}", shape_name));
        const auto* nose_table = nose->as_table();
        if (!nose_table) {
            r.fail_at("nose", fmt::format("expected a table such as {{ shape = \"cone\", length = \"10 mm\" }}, got {}",
                                          as_written(*nose)));
        }
        const TableReader t(reporter, *nose_table, r.key_path("nose"), "a nose", {"shape", "length", "calibre_radius", "end"});
        NoseSpec n;
        const auto kind = t.choice<NoseKind>("shape", {{"cone", NoseKind::Cone}, {"hemisphere", NoseKind::Hemisphere},
                                                       {"ogive", NoseKind::Ogive}});
        if (!kind) t.fail_missing("shape", "cone, hemisphere or ogive");
        n.kind = *kind;
        if (n.kind == NoseKind::Cone) {
            n.length = t.required_quantity("length", D::Length, Limit::Positive);
        } else if (t.has("length")) {
            t.fail_at("length", fmt::format("a {} nose's length follows from the radius{}; leave it out", name_of(n.kind),
                                            n.kind == NoseKind::Ogive ? " and calibre_radius" : ""));
        }
        if (n.kind == NoseKind::Ogive) {
            n.calibre_radius = t.required_quantity("calibre_radius", D::Dimensionless, Limit::Positive);
            if (!(n.calibre_radius >= 0.5)) {
                t.fail_at("calibre_radius", fmt::format("{} is below 0.5: the arc radius of a tangent ogive is at least the "
                                                        "cylinder's radius (0.5 calibres is a hemisphere)", n.calibre_radius));
            }
        } else if (t.has("calibre_radius")) {
            t.fail_at("calibre_radius", fmt::format("applies to an ogive only, not a {}", name_of(n.kind)));
        }
        if (const auto end = t.choice<int>("end", {{"bottom", -1}, {"top", 1}})) n.end = *end;
        if (!(nose_length(n, b.radius) <= b.length)) {
            t.fail_table(fmt::format("the {} nose is {:.6g} mm long, longer than the cylinder's length, {:.6g} mm (the nose "
                                     "is part of it)", name_of(n.kind), nose_length(n, b.radius) * 1e3, b.length * 1e3));
        }
        b.nose = n;
    }

    if (b.shape != ShapeKind::Nodes) b.spacing = r.required_quantity("spacing", D::Length, Limit::Positive);
    if (r.has("spacing_z")) {
        if (dim == 3) r.fail_at("spacing_z", "applies to 2D scenes only: a 3D lattice has one spacing in every direction");
        b.spacing_z = *r.quantity("spacing_z", D::Length, Limit::Positive);
    }
    if (const auto velocity = r.quantities("velocity", D::Velocity, static_cast<std::size_t>(dim), Limit::BelowLightSpeed, components)) {
        b.velocity = to_vector3(*velocity);
        check_speed(r, "velocity", {b.velocity[0], b.velocity[1], b.velocity[2]});
    }
    if (r.has("initial_stress")) b.initial_stress = read_initial_stress(r, geometry);
    if (const auto d = r.choice<Discretisation>("discretisation", {{"particles", Discretisation::Particles},
                                                                  {"elements", Discretisation::Elements}})) {
        b.discretisation = *d;
        if (b.discretisation == Discretisation::Elements && dim == 3) {
            r.fail_at("discretisation", "\"elements\" is 2D only (axisymmetric or plane strain); a 3D body takes particles");
        }
    }
    b.connectivity = r.choice<ConnectivityMode>("connectivity", connectivity_words);
    if (const auto n = r.whole_number("lattice_neighbours", 0, 26)) b.lattice_neighbours = static_cast<int>(*n);
    b.fill = r.choice<CellFill>("fill", {{"centres", CellFill::Centres}, {"trimmed", CellFill::Trimmed}, {"rings", CellFill::Rings}});
    if (const auto rotation = read_rotation(r, geometry, "a body in an axisymmetric scene")) {
        if (b.discretisation == Discretisation::Elements) {
            r.fail_at("rotation", "applies to particle bodies only: an element body's mesh follows the scene's axes");
        }
        b.rotation = *rotation;
    }
    return b;
}

// --- planes ----------------------------------------------------------------------------------

PlaneSpec read_plane(const Reporter& reporter, const toml::table& table, std::size_t index, GeometryKind geometry) {
    const TableReader r(reporter, table, labelled_path("plane", table, index), "a plane", plane_keys);
    const int dim = dimension_of(geometry);
    PlaneSpec p;
    p.name = r.string("name").value_or(fmt::format("plane{}", index));
    if (p.name.empty()) r.fail_at("name", "a plane's name must not be empty (leave the key out for \"plane<index>\")");

    const auto kind = r.choice<PlaneKind>("kind", {{"rigid", PlaneKind::Rigid}, {"symmetry", PlaneKind::Symmetry}});
    if (!kind) r.fail_missing("kind", "rigid or symmetry");
    p.kind = *kind;

    // Where the plane lies: axis and position, or normal and a point on it. A normal along a
    // coordinate axis becomes the axis form, so that the plane is the very one `axis` would give.
    const std::string_view components = components_of(dim);
    int flip = 1;  // -1 for a normal along a negative coordinate axis: the axis form's side is the other
    if (r.has("normal")) {
        if (r.has("axis")) r.fail_at("normal", "give axis and position, or normal and point, not both");
        if (r.has("position")) {
            r.fail_at("position", fmt::format("applies with axis; a plane given by its normal takes point = {} (any point on "
                                              "it) instead", components));
        }
        const auto written = r.quantities("normal", D::Dimensionless, static_cast<std::size_t>(dim), Limit::Any, components);
        const auto normal = direction_of(to_vector3(*written), dim);
        if (!normal) r.fail_at("normal", fmt::format("is a zero vector: a normal needs a direction, {} of any length", components));
        if (!r.has("point")) r.fail_missing("point", fmt::format("a point on the plane, {} with units (with normal)", components));
        const auto point = to_vector3(*r.quantities("point", D::Length, static_cast<std::size_t>(dim), Limit::Any, components));
        if (const auto aligned = aligned_axis(*normal, dim)) {
            p.axis = aligned->axis;
            p.position = point[static_cast<std::size_t>(aligned->axis)];
            flip = aligned->sign;
        } else {
            if (geometry == GeometryKind::Axisymmetric) {
                r.fail_at("normal", "is oblique: an axisymmetric scene takes planes normal to x or z only (a plane there turns "
                                    "about the axis), normal = [1, 0] or [0, 1]");
            }
            p.axis = -1;
            p.normal = *normal;
            p.position = 0.0;
            for (int c = 0; c < dim; ++c) p.position += p.normal[static_cast<std::size_t>(c)] * point[static_cast<std::size_t>(c)];
        }
    } else {
        if (r.has("point")) {
            r.fail_at("point", "applies with normal (a plane through a point, normal to a direction); with axis give position");
        }
        const auto axis = dim == 2 ? r.choice<int>("axis", {{"x", 0}, {"z", 1}})
                                   : r.choice<int>("axis", {{"x", 0}, {"y", 1}, {"z", 2}});
        if (!axis) {
            r.fail_missing("axis", fmt::format("the plane's normal: {} (or normal = {} with point = {})",
                                               dim == 2 ? "x or z" : "x, y or z", components, components));
        }
        p.axis = *axis;
        p.position = r.required_quantity("position", D::Length);
    }

    if (const toml::node* side = r.find("side")) {
        const auto* word = side->as_string();
        if (word && (word->get() == "above" || word->get() == "below")) {
            p.side = word->get() == "above" ? +1 : -1;
        } else if (const auto* number = side->as_integer(); number && (number->get() == 1 || number->get() == -1)) {
            p.side = static_cast<int>(number->get());
        } else {
            r.fail_at("side", fmt::format("{} is not \"above\", \"below\", 1 or -1 (the side of the plane the bodies are on)",
                                          as_written(*side)));
        }
    }
    p.side *= flip;
    if (const auto lift_off = r.boolean("lift_off")) {
        if (p.kind == PlaneKind::Symmetry) {
            r.fail_at("lift_off", "applies to rigid planes only (a symmetry plane always holds its nodes)");
        }
        p.lift_off = *lift_off;
    }
    // Coulomb friction: `friction` the coefficient of sliding, `static_friction` that of sticking
    // (default: the same).
    for (const std::string_view key : {"friction", "static_friction"}) {
        if (r.has(key) && p.kind == PlaneKind::Symmetry) {
            r.fail_at(key, "applies to rigid planes only (a symmetry plane is a mirror: nothing slides on it)");
        }
    }
    if (const auto mu = r.quantity("friction", D::Dimensionless, Limit::NonNegative)) p.friction_dynamic = p.friction_static = *mu;
    if (const auto mu = r.quantity("static_friction", D::Dimensionless, Limit::NonNegative)) {
        if (!r.has("friction")) r.fail_at("static_friction", "needs friction (the coefficient of sliding) too");
        if (*mu < p.friction_dynamic) {
            r.fail_at("static_friction", fmt::format("{} is below friction = {}: sticking takes at least the force of sliding",
                                                     *mu, p.friction_dynamic));
        }
        p.friction_static = *mu;
    }
    return p;
}

// --- gauges ------------------------------------------------------------------------------------

GaugeSpec read_gauge(const Reporter& reporter, const toml::table& table, std::size_t index, GeometryKind geometry) {
    const TableReader r(reporter, table, labelled_path("gauge", table, index), "a gauge", gauge_keys);
    const int dim = dimension_of(geometry);
    GaugeSpec g;
    g.name = r.required_string("name", "the gauge's name, which names its file gauge_<name>.csv");
    const auto kind = r.choice<GaugeKind>("kind", {{"point", GaugeKind::Point}, {"free_surface", GaugeKind::FreeSurface}});
    if (kind) g.kind = *kind;
    const auto at = r.quantities("at", D::Length, static_cast<std::size_t>(dim), Limit::Any, components_of(dim));
    if (!at) r.fail_missing("at", fmt::format("the gauge's point at t = 0, {} with units", components_of(dim)));
    g.at = to_vector3(*at);
    if (const auto body = r.string("body")) g.body = *body;
    if (const auto radius = r.quantity("radius", D::Length, Limit::NonNegative)) g.radius = *radius;
    if (const toml::node* normal = r.find("normal")) {
        if (g.kind != GaugeKind::FreeSurface) {
            r.fail_at("normal", "applies to free-surface gauges only (kind = \"free_surface\")");
        }
        const auto* word = normal->as_string();
        const std::string axes = dim == 3 ? "xyz" : "xz";
        const std::string text = word ? word->get() : std::string();
        if (text.size() != 2 || (text[0] != '+' && text[0] != '-') || axes.find(text[1]) == std::string::npos) {
            r.fail_at("normal", fmt::format("{} is not an outward normal: write a sign and an axis, {}", as_written(*normal),
                                            dim == 3 ? "\"+x\", \"-x\", \"+y\", \"-y\", \"+z\" or \"-z\""
                                                     : "\"+x\", \"-x\", \"+z\" or \"-z\""));
        }
        g.normal_sign = text[0] == '+' ? 1 : -1;
        g.normal_axis = static_cast<int>(axes.find(text[1]));
    } else if (g.kind == GaugeKind::FreeSurface) {
        r.fail_missing("normal", "the outward normal of the face, a sign and an axis such as \"-z\"");
    }
    if (const toml::node* fields = r.find("fields")) {
        const auto* list = fields->as_array();
        if (!list || list->empty()) r.fail_at("fields", fmt::format("expected a list of field names, got {}", as_written(*fields)));
        std::string known;
        for (const auto word : gauge_field_words()) known += (known.empty() ? "" : ", ") + std::string(word);
        for (std::size_t k = 0; k < list->size(); ++k) {
            const auto* word = (*list)[k].as_string();
            GaugeField f{};
            if (!word || !gauge_field_of(word->get(), f)) {
                r.fail_at("fields", fmt::format("{} is not a gauge field; the fields are {}", as_written((*list)[k]), known));
            }
            g.fields.push_back(f);
        }
    }
    return g;
}

// --- prescribed velocities ------------------------------------------------------------------

// The component names of a geometry ("x", "z" or "x", "y", "z").
std::vector<std::string_view> component_names(int dim) {
    return dim == 2 ? std::vector<std::string_view>{"x", "z"} : std::vector<std::string_view>{"x", "y", "z"};
}

// A table of per-component values (velocity = { z = "5 m/s" }, above = { z = "38 mm" }): the
// component index and the node of each key given. A name the geometry does not have is an error
// that says which it has.
std::vector<std::pair<int, const toml::node*>> component_table(const TableReader& parent, std::string_view key,
                                                               GeometryKind geometry, std::string_view example) {
    const toml::node* node = parent.find(key);
    const auto* table = node->as_table();
    if (!table) {
        parent.fail_at(key, fmt::format("expected a table of components such as {}, got {}", example, type_name(*node)));
    }
    const int dim = dimension_of(geometry);
    const auto names = component_names(dim);
    for (const auto& [name, value] : *table) {
        const std::string_view k = name.str();
        const std::string where = fmt::format("{}.{}", parent.key_path(key), printable(k));
        if (dim == 2 && k == "y") {
            parent.reporter().fail(line_of(value), where, fmt::format("{} has no y component: its components are x and z",
                                                                      scene_phrase(geometry)));
        }
        if (geometry == GeometryKind::Axisymmetric && (k == "r" || k == "radial")) {
            parent.reporter().fail(line_of(value), where, "the radial component of an axisymmetric scene is called x");
        }
    }
    const TableReader t(parent.reporter(), *table, parent.key_path(key), fmt::format("a table of components in {}", scene_phrase(geometry)),
                        names);
    if (table->empty()) parent.fail_at(key, fmt::format("is empty: give at least one component, such as {}", example));
    std::vector<std::pair<int, const toml::node*>> out;
    for (int c = 0; c < dim; ++c) {
        if (const toml::node* v = t.find(names[static_cast<std::size_t>(c)])) out.emplace_back(c, v);
    }
    return out;
}

PrescribedVelocitySpec read_prescribed_velocity(const Reporter& reporter, const toml::table& table, std::size_t index,
                                                GeometryKind geometry) {
    const TableReader r(reporter, table, labelled_path("prescribed_velocity", table, index), "a prescribed velocity",
                        prescribed_keys);
    const int dim = dimension_of(geometry);
    const std::string_view components = components_of(dim);
    PrescribedVelocitySpec p;
    p.name = r.string("name").value_or(fmt::format("velocity{}", index));
    if (p.name.empty()) r.fail_at("name", "a prescribed velocity's name must not be empty (leave the key out for \"velocity<index>\")");
    p.body = r.required_string("body", "the name of the body whose nodes it holds");

    // The region: every condition given must hold.
    const toml::node* region_node = r.find("region");
    if (!region_node) {
        r.fail_missing("region", "the nodes it holds, e.g. region = { above = { z = \"38 mm\" } } (keys box, above, below, "
                                 "beyond_radius, within_radius)");
    }
    const auto* region_table = region_node->as_table();
    if (!region_table) {
        r.fail_at("region", fmt::format("expected a table such as {{ above = {{ z = \"38 mm\" }} }}, got {}", type_name(*region_node)));
    }
    const TableReader g(reporter, *region_table, r.key_path("region"), "a region", region_keys);
    if (region_table->empty()) r.fail_at("region", "is empty: give box, above, below, beyond_radius or within_radius");
    std::array<const char*, 3> lower_from{nullptr, nullptr, nullptr}, upper_from{nullptr, nullptr, nullptr};
    const auto bound = [&](std::string_view key, int c, double value, bool lower, const char* from) {
        auto& source = lower ? lower_from[c] : upper_from[c];
        if (source) {
            g.fail_at(key, fmt::format("gives the {} bound of {} that {} gives already", lower ? "lower" : "upper",
                                       component_names(dim)[static_cast<std::size_t>(c)], source));
        }
        source = from;
        (lower ? p.lower : p.upper)[static_cast<std::size_t>(c)] = value;
    };
    if (g.has("box")) {
        const auto* box = g.find("box")->as_table();
        if (!box) g.fail_at("box", fmt::format("expected a table {{ min = {}, max = {} }}, got {}", components, components, type_name(*g.find("box"))));
        const TableReader b(reporter, *box, g.key_path("box"), "a box", {"min", "max"});
        const auto lo = b.quantities("min", D::Length, static_cast<std::size_t>(dim), Limit::Any, components);
        const auto hi = b.quantities("max", D::Length, static_cast<std::size_t>(dim), Limit::Any, components);
        if (!lo) b.fail_missing("min", fmt::format("the lower corner {}", components));
        if (!hi) b.fail_missing("max", fmt::format("the upper corner {}", components));
        for (int c = 0; c < dim; ++c) {
            if ((*lo)[c] > (*hi)[c]) {
                b.fail_at("max", fmt::format("lies below min along {} ({} < {} m)", component_names(dim)[static_cast<std::size_t>(c)],
                                             (*hi)[c], (*lo)[c]));
            }
            bound("box", c, (*lo)[c], true, "box");
            bound("box", c, (*hi)[c], false, "box");
        }
    }
    for (const auto& [key, lower] : {std::pair<std::string_view, bool>{"above", true}, {"below", false}}) {
        if (!g.has(key)) continue;
        for (const auto& [c, node] : component_table(g, key, geometry, "{ z = \"38 mm\" }")) {
            const double value = read_quantity(reporter, *node, fmt::format("{}.{}", g.key_path(key),
                                                                            component_names(dim)[static_cast<std::size_t>(c)]),
                                               D::Length, Limit::Any);
            bound(key, c, value, lower, lower ? "above" : "below");
        }
    }
    if (const auto v = g.quantity("beyond_radius", D::Length, Limit::NonNegative)) p.radius_min = *v;
    if (const auto v = g.quantity("within_radius", D::Length, Limit::Positive)) p.radius_max = *v;
    if (p.radius_min > p.radius_max) {
        g.fail_at("within_radius", fmt::format("{} m is less than beyond_radius = {} m: no radius is in both", p.radius_max, p.radius_min));
    }

    // The velocity: a table of the prescribed components, or an array of all of them.
    const toml::node* velocity = r.find("velocity");
    if (!velocity) {
        r.fail_missing("velocity", fmt::format("the prescribed components, e.g. velocity = {{ z = \"5 m/s\" }}, or all of them, "
                                               "velocity = {}", components));
    }
    if (velocity->is_array()) {
        const auto all = r.quantities("velocity", D::Velocity, static_cast<std::size_t>(dim), Limit::BelowLightSpeed, components);
        for (int c = 0; c < dim; ++c) p.velocity[static_cast<std::size_t>(c)] = (*all)[static_cast<std::size_t>(c)];
    } else {
        for (const auto& [c, node] : component_table(r, "velocity", geometry, "{ z = \"5 m/s\" }")) {
            p.velocity[static_cast<std::size_t>(c)] =
                read_quantity(reporter, *node, fmt::format("{}.{}", r.key_path("velocity"), component_names(dim)[static_cast<std::size_t>(c)]),
                              D::Velocity, Limit::BelowLightSpeed);
        }
    }
    check_speed(r, "velocity", {p.velocity[0].value_or(0.0), p.velocity[1].value_or(0.0), p.velocity[2].value_or(0.0)});
    if (const auto ramp = r.quantity("ramp", D::Time, Limit::NonNegative)) p.ramp = *ramp;
    return p;
}

// --- options -------------------------------------------------------------------------------

// Every key of the engine's table of solver options, read through the code that study variants
// use too (solver_reading.hpp); their ranges are validate_scene's.
// A `preset` (solver_options.hpp, SolverPreset) applies first; the keys beside it override it.
SolverOptions read_solver(const Reporter& reporter, const toml::table& table) {
    std::vector<std::string_view> keys = solver_option_keys();
    keys.push_back("preset");
    const TableReader r(reporter, table, "solver", "[solver]", keys);
    SolverOptions s;
    std::vector<std::string_view> presets;
    for (const SolverPreset& p : solver_presets()) presets.push_back(p.name);
    if (const auto index = r.word_index("preset", presets)) apply_solver_preset(solver_presets()[*index], s);
    for (const SolverOption& option : solver_option_table()) read_solver_option(r, option, s);
    return s;
}

StopCriteria read_stop(const Reporter& reporter, const toml::table& table) {
    const TableReader r(reporter, table, "stop", "[stop]", stop_keys);
    StopCriteria s;
    if (const auto v = r.quantity("end_time", D::Time, Limit::NonNegative)) s.end_time = *v;
    if (const auto v = r.quantity("kinetic_energy_fraction", D::Dimensionless, Limit::NonNegative)) {
        s.kinetic_energy_fraction = *v;
    }
    if (const auto v = r.whole_number("max_steps", 0, std::numeric_limits<long long>::max())) {
        s.max_steps = static_cast<std::size_t>(*v);
    }
    if (const auto v = r.quantity("energy_error", D::Dimensionless, Limit::NonNegative)) s.energy_error = *v;
    return s;
}

OutputOptions read_output(const Reporter& reporter, const toml::table& table) {
    const TableReader r(reporter, table, "output", "[output]", output_keys);
    OutputOptions o;
    if (const auto v = r.whole_number("snapshots", 0, std::numeric_limits<long long>::max())) {
        o.snapshots = static_cast<std::size_t>(*v);
    }
    if (const auto v = r.quantity("snapshot_interval", D::Time, Limit::NonNegative)) o.snapshot_interval = *v;
    if (const auto v = r.whole_number("history_every", 1, std::numeric_limits<long long>::max())) {
        o.history_every = static_cast<std::size_t>(*v);
    }
    // checkpoint_every: a whole number of steps, or a wall-clock time ("10 min").
    if (const toml::node* every = r.find("checkpoint_every")) {
        if (every->is_string()) {
            o.checkpoint_every_seconds = r.required_quantity("checkpoint_every", D::Time, Limit::NonNegative);
            o.checkpoint_every_steps = 0;
        } else {
            o.checkpoint_every_steps = static_cast<std::size_t>(*r.whole_number("checkpoint_every", 0, std::numeric_limits<long long>::max()));
            o.checkpoint_every_seconds = 0.0;
        }
    }
    if (const auto v = r.quantity("peak_radius", D::Length, Limit::Positive)) o.peak_radius = *v;
    // fields: the snapshot arrays, in the order written; "all" stands for every field.
    if (const toml::node* fields = r.find("fields")) {
        const auto* list = fields->as_array();
        std::string known = "\"all\"";
        for (const SnapshotField f : all_snapshot_fields()) known += fmt::format(", \"{}\"", name_of(f));
        if (!list) {
            r.fail_at("fields", fmt::format("expected a list of field names (an empty list for positions and ids alone), got {}",
                                            as_written(*fields)));
        }
        o.snapshot_format.fields.clear();
        for (std::size_t k = 0; k < list->size(); ++k) {
            const auto* word = (*list)[k].as_string();
            std::vector<SnapshotField> named;
            SnapshotField f{};
            if (word && word->get() == "all") {
                named = all_snapshot_fields();
            } else if (word && snapshot_field_of(word->get(), f)) {
                named = {f};
            } else {
                r.fail_at("fields", fmt::format("{} is not a snapshot field; the fields are {} (id and position are always written)",
                                                as_written((*list)[k]), known));
            }
            for (const SnapshotField n : named) {
                const auto& chosen = o.snapshot_format.fields;
                if (std::find(chosen.begin(), chosen.end(), n) != chosen.end()) {
                    const bool with_all = named.size() > 1 || std::any_of(list->begin(), list->begin() + static_cast<std::ptrdiff_t>(k), [](const toml::node& w) {
                        const auto* text = w.as_string();
                        return text && text->get() == "all";
                    });
                    r.fail_at("fields", fmt::format("\"{}\" is named twice{}", name_of(n), with_all ? " (\"all\" names every field)" : ""));
                }
                o.snapshot_format.fields.push_back(n);
            }
        }
    }
    if (const auto p = r.choice<SnapshotPrecision>("precision", {{"float64", SnapshotPrecision::Float64},
                                                                  {"float32", SnapshotPrecision::Float32}})) {
        o.snapshot_format.precision = *p;
    }
    return o;
}

// [reference]: free-form keys; each value a number or a quantity of any dimension, kept in SI.
void read_reference(const Reporter& reporter, const toml::table& table, Scene& scene) {
    for (const auto& [key, node] : table) {
        const std::string path = fmt::format("reference.{}", printable(key.str()));
        const std::size_t line = line_of(node);
        if (key.str() == "source" || key.str() == "elements") {
            const auto* s = node.as_string();
            if (!s) reporter.fail(line, path, fmt::format("expected a string, got {}", type_name(node)));
            if (key.str() == "elements" && s->get().empty()) {
                reporter.fail(line, path, "the file name is empty: name the element reference (a file gpa study --reference wrote), "
                                          "or leave the key out");
            }
            (key.str() == "source" ? scene.reference_source : scene.element_reference) = s->get();
            continue;
        }
        double value = 0.0;
        if (const auto* i = node.as_integer()) {
            value = static_cast<double>(i->get());
        } else if (const auto* f = node.as_floating_point()) {
            value = f->get();
            if (!std::isfinite(value)) reporter.fail(line, path, fmt::format("{} is not allowed: a reference value must be finite", as_written(node)));
        } else if (const auto* s = node.as_string()) {
            try {
                value = parse_any_quantity(s->get()).value;
            } catch (const UnitError& e) {
                reporter.fail(line, path, e.what());
            }
        } else {
            reporter.fail(line, path,
                          fmt::format("expected a number or a quantity such as \"16.21 mm\" (or `source = \"...\"`), got {}",
                                      type_name(node)));
        }
        scene.reference[std::string(key.str())] = value;
    }
}

// What parse_scene needs besides the Scene: the lines of the tables the engine's checks may name
// by index, and the top-level rotation, applied once the scene as written is checked.
struct ReadExtras {
    std::vector<std::size_t> region_lines, gauge_lines;
    std::optional<Rotation> rotation;
    std::size_t rotation_line = 0;
};

Scene read_scene(std::string_view text, const Reporter& reporter, ReadExtras& extras) {
    check_text(text, reporter);
    const toml::table root = parse_toml(text, reporter);
    if (root.empty()) {
        reporter.fail(0, "", "the file is empty: a scene needs at least `geometry`, one [[body]] and a [stop] table");
    }
    const TableReader top(reporter, root, "", "a scene", scene_keys);
    Scene scene;
    scene.name = top.string("name").value_or(std::filesystem::path(reporter.file()).stem().string());
    scene.description = top.string("description").value_or("");

    const auto geometry = top.choice<GeometryKind>("geometry", {{"axisymmetric", GeometryKind::Axisymmetric},
                                                                {"plane-strain", GeometryKind::PlaneStrain},
                                                                {"3d", GeometryKind::ThreeD}});
    if (!geometry) top.fail_missing("geometry", "\"axisymmetric\", \"plane-strain\" or \"3d\"");
    scene.geometry = *geometry;

    SceneMaterials scene_materials(
        read_materials(reporter, top.find("material"), OutsideMaterials{find_builtin_material, builtin_material_names}));

    const auto body_tables = tables_of(top, "body");
    if (body_tables.empty()) top.fail_missing("body", "at least one [[body]] table");
    for (std::size_t i = 0; i < body_tables.size(); ++i) {
        scene.bodies.push_back(read_body(reporter, *body_tables[i], i, scene.geometry, scene_materials));
    }
    const auto plane_tables = tables_of(top, "plane");
    for (std::size_t i = 0; i < plane_tables.size(); ++i) {
        scene.planes.push_back(read_plane(reporter, *plane_tables[i], i, scene.geometry));
    }
    const auto region_tables = tables_of(top, "prescribed_velocity");
    for (std::size_t i = 0; i < region_tables.size(); ++i) {
        scene.prescribed_velocities.push_back(read_prescribed_velocity(reporter, *region_tables[i], i, scene.geometry));
        extras.region_lines.push_back(line_of(*region_tables[i]));
    }
    const auto gauge_tables = tables_of(top, "gauge");
    for (std::size_t i = 0; i < gauge_tables.size(); ++i) {
        scene.gauges.push_back(read_gauge(reporter, *gauge_tables[i], i, scene.geometry));
        extras.gauge_lines.push_back(line_of(*gauge_tables[i]));
    }
    scene.materials = scene_materials.take();

    const toml::table empty;
    scene.solver = read_solver(reporter, sub_table(top, "solver", empty));
    scene.stop = read_stop(reporter, sub_table(top, "stop", empty));
    scene.output = read_output(reporter, sub_table(top, "output", empty));
    read_reference(reporter, sub_table(top, "reference", empty), scene);
    extras.rotation = read_rotation(top, scene.geometry, "an axisymmetric scene");
    if (extras.rotation) extras.rotation_line = line_of(*top.find("rotation"));
    // The neighbourhood of local peaks is fixed by the scene as written (twice its first body's
    // spacing unless given), so that the refined runs of a study measure over the same one.
    if (scene.output.peak_radius == 0.0 && !scene.bodies.empty()) scene.output.peak_radius = 2.0 * nominal_spacing(scene.bodies.front());
    return scene;
}

// The scene-level rules (shapes for the geometry, planes, spacings, option ranges, materials,
// the nodes of prescribed-velocity regions) are the engine's, the same for a Scene built in
// code; an error about one region or gauge points at its table. `turned`: the scene is the one
// the top-level rotation made, which messages say.
void check_scene(const Scene& scene, const Reporter& reporter, const ReadExtras& extras, bool turned) {
    const std::string_view after = turned ? "after the top-level rotation: " : "";
    try {
        validate_scene(scene);
    } catch (const PrescribedVelocityError& e) {
        reporter.fail(e.index() < extras.region_lines.size() ? extras.region_lines[e.index()] : 0, "", fmt::format("{}{}", after, e.what()));
    } catch (const GaugeError& e) {
        reporter.fail(e.index() < extras.gauge_lines.size() ? extras.gauge_lines[e.index()] : 0, "", fmt::format("{}{}", after, e.what()));
    } catch (const InputError& e) {
        reporter.fail(turned ? extras.rotation_line : 0, turned ? "rotation" : "", fmt::format("{}{}", after, e.what()));
    }
}

}  // namespace

Scene parse_scene(std::string_view text, const std::string& file_name_for_messages) {
    const Reporter reporter(file_name_for_messages);
    ReadExtras extras;
    Scene scene = read_scene(text, reporter, extras);
    check_scene(scene, reporter, extras, false);
    if (!extras.rotation) return scene;
    // The whole scene turned about the origin, as written and checked; what cannot turn (regions,
    // free-surface gauges) is refused at the rotation's line. The turned scene is checked again: a
    // rule with a tolerance (a symmetry plane on the lattice's cell faces) meets turned round-off.
    try {
        scene = rotated_scene(scene, *extras.rotation);
    } catch (const InputError& e) {
        // The engine's message may name the key already ("rotation: ..."): name it once.
        const std::string_view message = e.what();
        const bool named = message.starts_with("rotation: ");
        reporter.fail(extras.rotation_line, "rotation", named ? message.substr(10) : message);
    }
    check_scene(scene, reporter, extras, true);
    return scene;
}

std::string read_scene_text(const std::filesystem::path& file) {
    const std::string name = file.string();
    const Reporter reporter(name);
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (ec || !std::filesystem::exists(status)) reporter.fail(0, "", "cannot read the scene file: it does not exist");
    if (std::filesystem::is_directory(status)) reporter.fail(0, "", "cannot read the scene file: it is a directory");
    std::ifstream in(file, std::ios::binary);
    if (!in) reporter.fail(0, "", "cannot open the scene file for reading");
    // Read in pieces up to one byte past the limit, whatever the file is (a device such as
    // /dev/zero, a pipe or a file still growing reports no size, or a wrong one).
    std::string text;
    char buffer[1 << 16];
    while (in) {
        in.read(buffer, sizeof buffer);
        text.append(buffer, static_cast<std::size_t>(in.gcount()));
        if (text.size() > max_scene_file_bytes) {
            reporter.fail(0, "", fmt::format("is longer than {} bytes: too large for a scene file", max_scene_file_bytes));
        }
    }
    if (in.bad()) reporter.fail(0, "", "reading the scene file failed");
    return text;
}

std::string resolve_scene_files(Scene& scene, const std::filesystem::path& scene_file, const MemoryLimit& memory) {
    // The surfaces of bodies of shape "surface": read, checked and made ready for their inside test.
    for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
        BodySpec& b = scene.bodies[k];
        if (b.shape != ShapeKind::Surface || b.surface) continue;
        const std::filesystem::path file = std::filesystem::path(b.surface_file).is_relative()
                                               ? (scene_file.parent_path() / b.surface_file).lexically_normal()
                                               : std::filesystem::path(b.surface_file);
        try {
            b.surface = std::make_shared<SurfaceInside>(std::make_shared<TriangleSurface>(read_stl(file, b.surface_unit, memory)));
        } catch (const LimitError& e) {
            throw LimitError(fmt::format("{}: body[{}] \"{}\".file: {}", scene_file.string(), k, b.name, e.what()));
        } catch (const InputError& e) {
            throw SceneError(fmt::format("{}: body[{}] \"{}\".file: {}", scene_file.string(), k, b.name, e.what()));
        } catch (const std::bad_alloc&) {
            throw SceneError(fmt::format("{}: body[{}] \"{}\".file: {}: not enough memory to read it and make its inside test",
                                         scene_file.string(), k, b.name, file.string()));
        }
    }
    // The nodes of bodies of shape "nodes": read and checked.
    for (std::size_t k = 0; k < scene.bodies.size(); ++k) {
        BodySpec& b = scene.bodies[k];
        if (b.shape != ShapeKind::Nodes || b.node_set) continue;
        const std::filesystem::path file = std::filesystem::path(b.surface_file).is_relative()
                                               ? (scene_file.parent_path() / b.surface_file).lexically_normal()
                                               : std::filesystem::path(b.surface_file);
        try {
            auto set = std::make_shared<const NodeSet>(read_node_file(file, b.surface_unit, scene.geometry, memory));
            b.node_set = std::make_shared<const NodeSetShape>(std::move(set), dimension_of(scene.geometry));
        } catch (const LimitError& e) {
            throw LimitError(fmt::format("{}: body[{}] \"{}\".file: {}", scene_file.string(), k, b.name, e.what()));
        } catch (const InputError& e) {
            throw SceneError(fmt::format("{}: body[{}] \"{}\".file: {}", scene_file.string(), k, b.name, e.what()));
        } catch (const std::bad_alloc&) {
            throw SceneError(fmt::format("{}: body[{}] \"{}\".file: {}: not enough memory to read its nodes", scene_file.string(),
                                         k, b.name, file.string()));
        }
    }
    if (scene.element_reference.empty()) return {};
    if (std::filesystem::path(scene.element_reference).is_relative()) {
        scene.element_reference = (scene_file.parent_path() / scene.element_reference).lexically_normal().string();
    }
    std::error_code ec;
    if (!std::filesystem::exists(scene.element_reference, ec)) {
        return fmt::format("{}: reference.elements: {} is not there: the run will not be compared with element results "
                           "(copy the reference beside the scene, or write one with gpa study --reference)",
                           scene_file.string(), scene.element_reference);
    }
    try {
        read_element_reference(scene.element_reference);
    } catch (const InputError& e) {
        throw InputError(fmt::format("{}: reference.elements: {}", scene_file.string(), e.what()));
    }
    return {};
}

Scene load_scene(const std::filesystem::path& file, std::string* warning, const MemoryLimit& memory) {
    Scene scene = parse_scene(read_scene_text(file), file.string());
    std::string w = resolve_scene_files(scene, file, memory);
    // The checks that wait for the shapes of imported bodies (overlaps, planes, regions), now that
    // their files are read.
    if (std::any_of(scene.bodies.begin(), scene.bodies.end(),
                    [](const BodySpec& b) { return b.shape == ShapeKind::Surface || b.shape == ShapeKind::Nodes; })) {
        try {
            validate_scene(scene);
        } catch (const InputError& e) {
            Reporter(file.string()).fail(0, "", e.what());
        }
    }
    if (warning) *warning = std::move(w);
    return scene;
}

}  // namespace gpa::io
