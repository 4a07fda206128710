// Pictures of snapshots (render.hpp): the snapshot's nodes and cells become discs and triangles
// in the picture plane, the frame fits them into the plot area at one scale in both directions,
// and they are filled pixel by pixel (a pixel belongs to a shape when its centre lies inside),
// then the colour bar, the text and the length scale are drawn around them.

#include "gpa/io/render.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <cstring>
#include <limits>

#include <fmt/format.h>
#include <png.h>

#include "bitmap_font.hpp"
#include "gpa/io/atomic_file.hpp"

namespace gpa::io {

namespace fs = std::filesystem;

// --- Image -------------------------------------------------------------------------------------

Image::Image(int w, int h, Rgb fill) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3) {
    for (std::size_t k = 0; k < rgb.size(); k += 3) {
        rgb[k] = fill.r;
        rgb[k + 1] = fill.g;
        rgb[k + 2] = fill.b;
    }
}

Rgb Image::at(int x, int y) const {
    const std::size_t k = (static_cast<std::size_t>(y) * width + x) * 3;
    return {rgb[k], rgb[k + 1], rgb[k + 2]};
}

void Image::set(int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    const std::size_t k = (static_cast<std::size_t>(y) * width + x) * 3;
    rgb[k] = c.r;
    rgb[k + 1] = c.g;
    rgb[k + 2] = c.b;
}

// --- Colour map --------------------------------------------------------------------------------

Rgb colour_map(double t) {
    // Nine stops, interpolated linearly in sRGB; their CIE L* rises from 15 to 91 in steps of
    // 4 to 6 per sixteenth (checked by the tests).
    struct Stop {
        double t;
        double r, g, b;
    };
    static constexpr std::array<Stop, 9> stops{{{0.000, 68, 1, 84},
                                                {0.125, 71, 44, 123},
                                                {0.250, 59, 82, 139},
                                                {0.375, 44, 113, 142},
                                                {0.500, 33, 145, 140},
                                                {0.625, 39, 173, 129},
                                                {0.750, 94, 201, 98},
                                                {0.875, 170, 220, 50},
                                                {1.000, 253, 231, 37}}};
    if (!(t > 0.0)) t = 0.0;  // NaN too
    if (t > 1.0) t = 1.0;
    std::size_t k = 0;
    while (k + 2 < stops.size() && t > stops[k + 1].t) ++k;
    const Stop& a = stops[k];
    const Stop& b = stops[k + 1];
    const double f = (t - a.t) / (b.t - a.t);
    const auto mix = [f](double x, double y) { return static_cast<std::uint8_t>(std::lround(x + (y - x) * f)); };
    return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

// --- Views -------------------------------------------------------------------------------------

std::optional<ViewDirection> view_direction_named(std::string_view text) {
    if (text == "+x" || text == "x") return ViewDirection::PlusX;
    if (text == "-x") return ViewDirection::MinusX;
    if (text == "+y" || text == "y") return ViewDirection::PlusY;
    if (text == "-y") return ViewDirection::MinusY;
    if (text == "+z" || text == "z") return ViewDirection::PlusZ;
    if (text == "-z") return ViewDirection::MinusZ;
    return std::nullopt;
}

std::string_view name_of(ViewDirection v) {
    switch (v) {
        case ViewDirection::PlusX: return "+x";
        case ViewDirection::MinusX: return "-x";
        case ViewDirection::PlusY: return "+y";
        case ViewDirection::MinusY: return "-y";
        case ViewDirection::PlusZ: return "+z";
        case ViewDirection::MinusZ: return "-z";
    }
    return "?";
}

ViewPoint project(const std::array<double, 3>& p, ViewDirection view) {
    const double x = p[0], y = p[1], z = p[2];
    // (right, up, view direction) with right = view x up, so that (right, up, -view) is right-handed.
    switch (view) {
        case ViewDirection::PlusY: return {x, z, y};
        case ViewDirection::MinusY: return {-x, z, -y};
        case ViewDirection::PlusX: return {-y, z, x};
        case ViewDirection::MinusX: return {y, z, -x};
        case ViewDirection::MinusZ: return {x, y, -z};
        case ViewDirection::PlusZ: return {-x, y, z};
    }
    return {x, z, y};
}

// --- Fields ------------------------------------------------------------------------------------

FieldChoice parse_field_choice(std::string_view text, GeometryKind geometry) {
    FieldChoice c;
    const auto colon = text.find(':');
    c.name = std::string(text.substr(0, colon));
    if (c.name.empty()) throw InputError(fmt::format("--field '{}': no field name", text));
    if (colon == std::string_view::npos) {
        c.label = c.name;
        return c;
    }
    const std::string_view part = text.substr(colon + 1);
    const bool three_d = geometry == GeometryKind::ThreeD;
    if (part == "magnitude" || part == "mag") {
        c.label = "|" + c.name + "|";
        return c;
    }
    // A symmetric tensor (the stress) is stored as VTK's XX, YY, ZZ, XY, YZ, XZ; 2D runs as (x, z,
    // out of plane), so that their xx, zz, out-of-plane and xz are components 0, 1, 2 and 3
    // (docs/outputs.md). The out-of-plane component is the hoop stress of an axisymmetric run.
    const std::string out_of_plane = geometry == GeometryKind::Axisymmetric ? "hoop" : "yy";
    if (part == "x") {
        c.component = 0;
    } else if (part == "y" && three_d) {
        c.component = 1;
    } else if (part == "z") {
        c.component = three_d ? 2 : 1;  // 2D vectors are stored as (x, z, 0)
    } else if (part == "xx") {
        c.component = 0;
        c.tensor = true;
    } else if (part == (three_d ? "yy" : "zz")) {
        c.component = 1;
        c.tensor = true;
    } else if (part == (three_d ? "zz" : out_of_plane)) {
        c.component = 2;
        c.tensor = true;
    } else if (three_d && (part == "xy" || part == "yz" || part == "xz")) {
        c.component = part == "xy" ? 3 : part == "yz" ? 4 : 5;
        c.tensor = true;
    } else if (!three_d && part == "xz") {
        c.component = 3;
        c.tensor = true;
    } else {
        throw InputError(fmt::format("--field '{}': '{}' is not a component; {} runs have {} for vectors, {} for tensors, "
                                     "or magnitude",
                                     text, part, name_of(geometry), three_d ? "x, y, z" : "x and z",
                                     three_d ? "xx, yy, zz, xy, yz, xz" : fmt::format("xx, zz, {}, xz", out_of_plane)));
    }
    c.label = c.name + ":" + std::string(part);
    return c;
}

std::string_view field_unit(std::string_view name) {
    static const std::array<std::pair<std::string_view, std::string_view>, 19> units{{
        {"velocity", "m/s"},
        {"force", "N"},
        {"pressure", "Pa"},
        {"stress", "Pa"},
        {"displacement", "m"},
        {"initial_position", "m"},
        {"plastic_work", "J/kg"},
        {"von_mises_stress", "Pa"},
        {"viscous_pressure", "Pa"},
        {"temperature", "K"},
        {"diameter", "m"},
        {"mass", "kg"},
        {"density", "kg/m^3"},
        {"internal_energy", "J/kg"},
        {"plastic_strain", ""},
        {"damage", ""},
        {"failed", ""},
        {"volumetric_strain", ""},
        {"connectivity", ""},
    }};
    for (const auto& [n, u] : units) {
        if (n == name) return u;
    }
    return "";
}

namespace {

// The SI prefix of a value in a unit: exponent and the unit written with it.
struct DisplayUnit {
    int exponent = 0;
    std::string unit;
};

DisplayUnit display_unit(double magnitude, std::string_view unit) {
    // The exponents of the prefixes each unit is shown with, largest first; kg takes grams' prefixes.
    std::string base(unit);
    int offset = 0;
    std::vector<int> exponents;
    if (unit == "Pa" || unit == "J/kg") {
        exponents = {9, 6, 3, 0};
    } else if (unit == "m" || unit == "s") {
        exponents = {0, -3, -6, -9};
    } else if (unit == "N") {
        exponents = {9, 6, 3, 0, -3};
    } else if (unit == "kg") {
        base = "g";
        offset = 3;
        exponents = {3, 0, -3, -6};
    }
    if (exponents.empty()) return {0, base};
    const auto prefix = [](int x) -> std::string {
        switch (x) {
            case 9: return "G";
            case 6: return "M";
            case 3: return "k";
            case -3: return "m";
            case -6: return "u";
            case -9: return "n";
            default: return "";
        }
    };
    const double m = std::abs(magnitude) * std::pow(10.0, offset);
    int e = offset;  // zero (or not finite): the unit as written
    if (m > 0.0 && std::isfinite(m)) {
        e = exponents.back();
        for (int x : exponents) {
            // 0.9995: a value that rounds to 1000 at three digits takes the next prefix
            if (m >= 0.9995 * std::pow(10.0, x)) {
                e = x;
                break;
            }
        }
    }
    return {e - offset, prefix(e) + base};
}

std::string number_text(double v) {
    if (!std::isfinite(v)) return std::isnan(v) ? "nan" : (v > 0 ? "inf" : "-inf");
    if (v == 0.0) return "0";
    return fmt::format("{:.3g}", v);
}

}  // namespace

std::string format_quantity(double value, std::string_view unit) {
    const DisplayUnit d = display_unit(value, unit);
    const std::string number = number_text(value / std::pow(10.0, d.exponent));
    return d.unit.empty() ? number : number + " " + d.unit;
}

// --- Snapshots ---------------------------------------------------------------------------------

LoadedSnapshot load_snapshot(const SnapshotIndex& series, std::size_t index) {
    if (index >= series.snapshots.size()) {
        throw InputError(fmt::format("{}: no snapshot {}; it lists {} (0 to {})", series.pvd.string(), index,
                                     series.snapshots.size(), series.snapshots.size() - 1));
    }
    LoadedSnapshot s;
    s.index = index;
    s.entry = series.snapshots[index];
    for (const auto& file : s.entry.files) {
        std::error_code ec;
        if (!fs::exists(file, ec)) {
            throw SnapshotError(fmt::format("{}: no such file (listed in {} as snapshot {} at t = {})", file.string(),
                                            series.pvd.string(), index, format_quantity(s.entry.time, "s")));
        }
        s.parts.emplace_back(file);
    }
    return s;
}

std::size_t snapshot_nearest(const SnapshotIndex& series, double t) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < series.snapshots.size(); ++k) {
        if (std::abs(series.snapshots[k].time - t) < std::abs(series.snapshots[best].time - t)) best = k;
    }
    return best;
}

namespace {

// The values of one array reduced to one number per point or cell: the component, or the
// magnitude of a vector.
std::vector<double> reduce(const std::vector<double>& values, int components, std::optional<int> component) {
    const std::size_t n = components > 0 ? values.size() / static_cast<std::size_t>(components) : 0;
    std::vector<double> out(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double* v = values.data() + i * static_cast<std::size_t>(components);
        if (component) {
            out[i] = v[*component];
        } else if (components == 1) {
            out[i] = v[0];
        } else {
            double s = 0.0;
            for (int c = 0; c < components; ++c) s += v[c] * v[c];
            out[i] = std::sqrt(s);
        }
    }
    return out;
}

}  // namespace

std::vector<FieldSummary> list_fields(const LoadedSnapshot& snapshot) {
    std::vector<FieldSummary> out;
    for (const auto& part : snapshot.parts) {
        for (const auto& info : part.arrays()) {
            const bool particles = part.type() == "PolyData";
            if (particles && info.location == DataLocation::Cell) continue;
            const std::string where =
                particles ? "particles" : info.location == DataLocation::Point ? "element points" : "element cells";
            auto it = std::find_if(out.begin(), out.end(), [&](const FieldSummary& f) { return f.name == info.name; });
            if (it == out.end()) {
                out.push_back({info.name, info.components, where, std::numeric_limits<double>::infinity(),
                               -std::numeric_limits<double>::infinity(), 0});
                it = out.end() - 1;
            } else {
                it->where += ", " + where;
            }
            // A tensor (6 components): the range over its components; a vector: of its magnitude.
            const std::vector<double> all = part.values(info.name, info.location);
            for (double v : info.components == 6 ? all : reduce(all, info.components, std::nullopt)) {
                if (!std::isfinite(v)) continue;
                it->min = std::min(it->min, v);
                it->max = std::max(it->max, v);
                ++it->values;
            }
        }
    }
    for (auto& f : out) {
        if (f.values == 0) f.min = f.max = 0.0;
    }
    return out;
}

// --- Render ------------------------------------------------------------------------------------

namespace {

struct Disc {
    double u, v, radius, depth;
    double value;
    bool has_value;
    bool failed = false;
    int region = 0;      // 0 free; k + 1 held by the scene's prescribed velocity k
    bool image = false;  // the mirror image of a node (2D, mirrored)
    std::size_t source = 0;  // the node's place among the discs before mirroring
    bool counts = true;      // the one drawn disc of its node that the counts and the range take
};

struct Triangle {
    std::array<ViewPoint, 3> corner;
    std::array<double, 3> value;  // the same three times for a cell field
    bool has_value;
    double depth;
    bool failed = false;  // its cell has failed
    bool image = false;   // a mirror image
    std::size_t source = 0;  // its place among the triangles before mirroring
    bool counts = true;      // the one drawn copy of it that the counts and the range take
};

// The field on one part: its values per point or per cell, or nullopt when the part lacks it.
struct PartField {
    DataLocation location;
    std::vector<double> values;
};

std::optional<PartField> part_field(const VtkFile& f, const FieldChoice& choice) {
    const bool particles = f.type() == "PolyData";
    for (DataLocation l : {DataLocation::Cell, DataLocation::Point}) {
        if (particles && l == DataLocation::Cell) continue;
        if (const VtkArrayInfo* info = f.find(choice.name, l)) {
            if (choice.component && info->components == 1) {
                throw InputError(fmt::format("--field {}: {} is a scalar field (no components)", choice.label, choice.name));
            }
            if (choice.component && *choice.component >= info->components) {
                throw InputError(fmt::format("--field {}: {} has {} components in {}", choice.label, choice.name,
                                             info->components, f.path().filename().string()));
            }
            const bool tensor = info->components == 6;
            if (choice.component && choice.tensor != tensor) {
                throw InputError(fmt::format("--field {}: {} is a {}; name a {} component", choice.label, choice.name,
                                             tensor ? "tensor" : "vector", tensor ? "tensor's (xx, ...)" : "vector's (x, ...)"));
            }
            if (!choice.component && tensor) {
                throw InputError(fmt::format("--field {}: {} is a tensor: name a component ({}:xx, ...; docs/render.md lists them), or "
                                             "draw its equivalent, von_mises_stress",
                                             choice.label, choice.name, choice.name));
            }
            return PartField{l, reduce(f.values(choice.name, l), info->components, choice.component)};
        }
    }
    return std::nullopt;
}

bool finite(const ViewPoint& p) { return std::isfinite(p.u) && std::isfinite(p.v) && std::isfinite(p.depth); }

// A stand-in spacing for files without a diameter field: the side of the cell each point would
// have if the points filled their bounding box evenly.
double estimated_spacing(const std::vector<ViewPoint>& points, bool three_d, const std::vector<double>& raw) {
    std::array<double, 3> lo{}, hi{};
    lo.fill(std::numeric_limits<double>::infinity());
    hi.fill(-std::numeric_limits<double>::infinity());
    std::size_t n = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!finite(points[i])) continue;
        for (int c = 0; c < 3; ++c) {
            lo[c] = std::min(lo[c], raw[3 * i + c]);
            hi[c] = std::max(hi[c], raw[3 * i + c]);
        }
        ++n;
    }
    if (n == 0) return 1e-3;
    const int dims = three_d ? 3 : 2;
    double largest = 0.0;
    for (int c = 0; c < dims; ++c) largest = std::max(largest, hi[c] - lo[c]);
    if (largest <= 0.0) return 1e-3;
    double measure = 1.0;
    for (int c = 0; c < dims; ++c) measure *= hi[c] - lo[c] > 0.0 ? hi[c] - lo[c] : largest / std::sqrt(double(n));
    return std::pow(measure / double(n), 1.0 / dims);
}

void fill_rect(Image& img, int x0, int y0, int x1, int y1, Rgb c) {
    for (int y = std::max(y0, 0); y < std::min(y1, img.height); ++y) {
        for (int x = std::max(x0, 0); x < std::min(x1, img.width); ++x) img.set(x, y, c);
    }
}

void draw_text(Image& img, int x, int y, std::string_view text, int scale, Rgb c) {
    for (std::size_t k = 0; k < text.size(); ++k) {
        const int gx = x + static_cast<int>(k) * detail::glyph_advance * scale;
        for (int row = 0; row < detail::glyph_height; ++row) {
            for (int col = 0; col < detail::glyph_width; ++col) {
                if (detail::glyph_pixel(text[k], col, row)) {
                    fill_rect(img, gx + col * scale, y + row * scale, gx + (col + 1) * scale, y + (row + 1) * scale, c);
                }
            }
        }
    }
}

// Shortens text to at most `width` pixels (ending in "...").
std::string fitted(std::string text, int width, int scale) {
    if (detail::text_width(text, scale) <= width) return text;
    while (!text.empty() && detail::text_width(text + "...", scale) > width) text.pop_back();
    return text + "...";
}

struct Area {
    int x0, y0, x1, y1;  // [x0, x1) x [y0, y1)
};

// One value to a colour: the range's ends for values beyond it, the middle of the map for a
// range of one value.
Rgb colour_of(double v, bool has_value, double lo, double hi) {
    if (!has_value) return no_field_colour;
    if (!std::isfinite(v)) return not_finite_colour;
    if (!(hi > lo)) return colour_map(0.5);
    return colour_map((v - lo) / (hi - lo));
}

// A pixel coordinate as an int, clamped far outside any picture: a window of a few nanometres
// puts distant nodes at astronomical pixel coordinates, which an int cannot hold.
int pixel_index(double v) { return std::isnan(v) ? -100000000 : static_cast<int>(std::clamp(v, -1e8, 1e8)); }

void draw_disc(Image& img, const Area& plot, const PictureFrame& frame, const Disc& d, Rgb colour) {
    const auto [px, py] = frame.pixel(d.u, d.v);
    const double r = d.radius * frame.scale;
    const int x0 = std::max(plot.x0, pixel_index(std::floor(px - r)));
    const int x1 = std::min(plot.x1 - 1, pixel_index(std::ceil(px + r)));
    const int y0 = std::max(plot.y0, pixel_index(std::floor(py - r)));
    const int y1 = std::min(plot.y1 - 1, pixel_index(std::ceil(py + r)));
    bool any = false;
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            const double dx = x + 0.5 - px, dy = y + 0.5 - py;
            if (dx * dx + dy * dy <= r * r) {
                img.set(x, y, colour);
                any = true;
            }
        }
    }
    // A disc smaller than a pixel still shows: the pixel holding its centre.
    const int cx = pixel_index(std::floor(px)), cy = pixel_index(std::floor(py));
    if (!any && cx >= plot.x0 && cx < plot.x1 && cy >= plot.y0 && cy < plot.y1) img.set(cx, cy, colour);
}

void draw_triangle(Image& img, const Area& plot, const PictureFrame& frame, const Triangle& t,
                   const std::function<Rgb(double, bool)>& paint) {
    std::array<std::array<double, 2>, 3> p;
    for (int k = 0; k < 3; ++k) p[k] = frame.pixel(t.corner[k].u, t.corner[k].v);
    const auto edge = [](const std::array<double, 2>& a, const std::array<double, 2>& b, double x, double y) {
        return (b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0]);
    };
    const double area = edge(p[0], p[1], p[2][0], p[2][1]);
    if (area == 0.0 || !std::isfinite(area)) return;
    const double minx = std::min({p[0][0], p[1][0], p[2][0]}), maxx = std::max({p[0][0], p[1][0], p[2][0]});
    const double miny = std::min({p[0][1], p[1][1], p[2][1]}), maxy = std::max({p[0][1], p[1][1], p[2][1]});
    const int x0 = std::max(plot.x0, pixel_index(std::floor(minx)));
    const int x1 = std::min(plot.x1 - 1, pixel_index(std::ceil(maxx)));
    const int y0 = std::max(plot.y0, pixel_index(std::floor(miny)));
    const int y1 = std::min(plot.y1 - 1, pixel_index(std::ceil(maxy)));
    for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
            const double cx = x + 0.5, cy = y + 0.5;
            // Barycentric weights from the edge functions; a pixel centre on an edge belongs to both.
            const double w0 = edge(p[1], p[2], cx, cy) / area;
            const double w1 = edge(p[2], p[0], cx, cy) / area;
            const double w2 = edge(p[0], p[1], cx, cy) / area;
            if (w0 < 0.0 || w1 < 0.0 || w2 < 0.0) continue;
            const double v = w0 * t.value[0] + w1 * t.value[1] + w2 * t.value[2];
            img.set(x, y, paint(v, t.has_value));
        }
    }
}

// The scene's rigid and symmetry planes the view sees edge-on, as lines of the picture plane:
// u = c (vertical), v = c (horizontal) or, for an oblique plane, nu u + nv v = c. 2D scenes store
// (x, z) as the first two coordinates, as the snapshots do; a 2D plane normal to x is mirrored with
// the run, and so is an oblique one.
struct PlaneLine {
    const PlaneSpec* plane;
    bool vertical;
    double at;             // u or v; an oblique line's c
    double toward_bodies;  // +1: the bodies lie towards +u (+v), or along +(nu, nv)
    bool oblique = false;
    double nu = 0.0, nv = 0.0;  // an oblique line's unit normal in the picture plane
};

// An oblique plane (PlaneSpec::axis = -1) as a line: edge-on when its normal lies in the picture
// plane (to round-off); one seen at a slant is no line and is left out, as a plane facing the
// viewer is. A normal that projects onto a picture axis gives a vertical or horizontal line.
void add_oblique_plane_line(std::vector<PlaneLine>& lines, const PlaneSpec& plane, bool three_d, ViewDirection view,
                            bool mirror) {
    const std::array<double, 3> normal = plane_normal(plane);
    const ViewPoint n = three_d ? project(normal, view) : ViewPoint{normal[0], normal[1], 0.0};
    const double in_picture = std::hypot(n.u, n.v);
    if (!(std::abs(n.depth) <= 1e-9) || !(in_picture > 0.0)) return;
    const double nu = n.u / in_picture, nv = n.v / in_picture;
    const double at = plane.position / in_picture;  // n . x = position with n . x = in_picture (nu u + nv v)
    if (nv == 0.0 || nu == 0.0) {
        const bool vertical_line = nv == 0.0;
        const double sign = vertical_line ? nu : nv;  // +-1
        lines.push_back({&plane, vertical_line, at * sign, plane.side * sign});
        if (mirror && vertical_line && at != 0.0) lines.push_back({&plane, true, -at * sign, -plane.side * sign});
        return;
    }
    lines.push_back({&plane, false, at, static_cast<double>(plane.side), true, nu, nv});
    if (mirror) lines.push_back({&plane, false, at, static_cast<double>(plane.side), true, -nu, nv});
}

std::vector<PlaneLine> plane_lines_of(const Scene* scene, bool three_d, ViewDirection view, bool mirror) {
    std::vector<PlaneLine> lines;
    if (!scene) return lines;
    for (const PlaneSpec& plane : scene->planes) {
        if (plane.axis > (three_d ? 2 : 1)) continue;
        if (plane.axis < 0) {
            add_oblique_plane_line(lines, plane, three_d, view, mirror);
            continue;
        }
        std::array<double, 3> normal{}, point{};
        normal[static_cast<std::size_t>(plane.axis)] = 1.0;
        point[static_cast<std::size_t>(plane.axis)] = plane.position;
        const ViewPoint n = three_d ? project(normal, view) : ViewPoint{normal[0], normal[1], 0.0};
        const ViewPoint at = three_d ? project(point, view) : ViewPoint{point[0], point[1], 0.0};
        if (n.u == 0.0 && n.v == 0.0) continue;  // faces the viewer
        const bool vertical_line = n.u != 0.0;
        const double side = plane.side * (vertical_line ? n.u : n.v);
        lines.push_back({&plane, vertical_line, vertical_line ? at.u : at.v, side});
        if (mirror && vertical_line && at.u != 0.0) lines.push_back({&plane, true, -at.u, -side});
    }
    return lines;
}

// Widens a drawing's extent {umin, umax} x {vmin, vmax} to hold the plane lines (an oblique line
// crosses any extent's lines of constant u or v somewhere: it widens nothing).
void reach_to_planes(const std::vector<PlaneLine>& lines, double& umin, double& umax, double& vmin, double& vmax) {
    for (const PlaneLine& l : lines) {
        if (l.oblique) continue;
        double& low = l.vertical ? umin : vmin;
        double& high = l.vertical ? umax : vmax;
        low = std::min(low, l.at);
        high = std::max(high, l.at);
    }
}

// Draws an oblique plane line as the straight ones are drawn (rigid: solid, with short strokes on
// the side away from the bodies; symmetry: dashed; its name on the wall's side), stepping a pixel
// at a time along it across the plot area. `s` is the picture's scale of lines and text. Whether
// any of it lies in the plot area.
bool draw_oblique_plane_line(Image& img, const Area& plot, const PictureFrame& frame, const PlaneLine& l, int s, int text_h) {
    // The line's point nearest the origin, its direction and its normal towards the bodies, in
    // pixels (y grows downwards, v upwards).
    const auto [cx, cy] = frame.pixel(l.at * l.nu, l.at * l.nv);
    const double dx = -l.nv, dy = -l.nu;
    const double ax = -l.toward_bodies * l.nu, ay = l.toward_bodies * l.nv;  // away from the bodies
    const double mx = 0.5 * (plot.x0 + plot.x1), my = 0.5 * (plot.y0 + plot.y1);
    const double middle = (mx - cx) * dx + (my - cy) * dy;
    const double reach = 0.5 * std::hypot(plot.x1 - plot.x0, plot.y1 - plot.y0) + 1.0;
    if (!std::isfinite(middle) || std::abs((mx - cx) * ax + (my - cy) * ay) > reach) return false;
    const auto inside = [&](double x, double y) { return x >= plot.x0 && x < plot.x1 && y >= plot.y0 && y < plot.y1; };
    const bool dashed = l.plane->kind == PlaneKind::Symmetry;
    const int thick = std::max(s, 1);
    const int steps = static_cast<int>(std::ceil(2.0 * reach));
    double first_x = 0.0, first_y = 0.0;
    bool any = false;
    for (int q = 0; q <= steps; ++q) {
        const double t = middle - reach + q;
        const double x = cx + t * dx, y = cy + t * dy;
        if (!inside(x, y)) continue;
        if (!any) first_x = x, first_y = y;
        any = true;
        if (dashed && (q / (6 * s)) % 2 == 1) continue;
        const int px = pixel_index(std::round(x)) - s / 2, py = pixel_index(std::round(y)) - s / 2;
        fill_rect(img, std::max(px, plot.x0), std::max(py, plot.y0), std::min(px + thick, plot.x1), std::min(py + thick, plot.y1),
                  text_colour);
        if (!dashed && q % (8 * s) == 3 * s) {
            for (int k = 0; k < 5 * s; ++k) {
                const double sx = x + k * (dx + ax), sy = y + k * (dy + ay);
                if (inside(sx, sy)) img.set(pixel_index(std::round(sx)), pixel_index(std::round(sy)), text_colour);
            }
        }
    }
    if (!any) return false;
    // Its name on the wall's side, a name's width in from where the line enters the plot area: the
    // corner of the name's box nearest the line 6 s from it, the rest farther (kept within the area).
    const std::string label = fitted(l.plane->name, (plot.x1 - plot.x0) / 2, s);
    const int name_w = detail::text_width(label, s);
    const double along = name_w + 8.0 * s;
    const double lx = first_x + along * dx + 6.0 * s * ax + (ax < 0.0 ? -name_w : 0.0);
    const double ly = first_y + along * dy + 6.0 * s * ay + (ay < 0.0 ? -text_h : 0.0);
    const int x = std::clamp(pixel_index(std::round(lx)), plot.x0, std::max(plot.x0, plot.x1 - name_w));
    const int y = std::clamp(pixel_index(std::round(ly)), plot.y0, std::max(plot.y0, plot.y1 - text_h));
    draw_text(img, x, y, label, s, text_colour);
    return true;
}

}  // namespace

Picture render_snapshot(const LoadedSnapshot& snapshot, GeometryKind geometry, const RenderOptions& options) {
    const bool three_d = geometry == GeometryKind::ThreeD;
    if (options.width < min_width || options.width > max_side) {
        throw InputError(fmt::format("picture width {} px: it must be {} to {}", options.width, min_width, max_side));
    }
    if (options.height != 0 && (options.height < min_height || options.height > max_side)) {
        throw InputError(fmt::format("picture height {} px: it must be {} to {}", options.height, min_height, max_side));
    }
    for (const auto& end : {options.range_min, options.range_max}) {
        if (end && !std::isfinite(*end)) throw InputError(fmt::format("colour range end {} is not a finite number", *end));
    }
    if (three_d && options.mirror.value_or(false)) throw InputError("mirroring applies to 2D runs only (this run is 3D)");
    if (!three_d && options.view) {
        throw InputError(fmt::format("a view direction applies to 3D runs only (this run is {}: it is drawn in the x-z plane)",
                                     name_of(geometry)));
    }
    const FieldChoice choice = parse_field_choice(options.field, geometry);
    const ViewDirection view = options.view.value_or(ViewDirection::PlusY);
    const bool mirror = !three_d && options.mirror.value_or(geometry == GeometryKind::Axisymmetric);

    Picture picture;
    picture.mirrored = mirror;
    picture.unit = std::string(field_unit(choice.name));
    std::vector<Disc> discs;
    std::vector<Triangle> triangles;
    bool field_found = false;
    const auto to_view = [&](const double* p) -> ViewPoint {
        if (three_d) return project({p[0], p[1], p[2]}, view);
        return {p[0], p[1], 0.0};  // 2D: stored (x, z, 0)
    };
    for (const auto& part : snapshot.parts) {
        const std::optional<PartField> field = part_field(part, choice);
        field_found = field_found || field.has_value();
        const std::vector<double> raw = part.points();
        std::vector<ViewPoint> points(part.point_count());
        for (std::size_t i = 0; i < points.size(); ++i) points[i] = to_view(raw.data() + 3 * i);
        // The part's failure flags (point data of particles, cell data of element bodies).
        std::vector<double> failed;
        if (options.mark_failed && choice.name != "failed") {
            const DataLocation at = part.type() == "PolyData" ? DataLocation::Point : DataLocation::Cell;
            if (const VtkArrayInfo* f = part.find("failed", at); f && f->components == 1) failed = part.values("failed", at);
        }
        if (part.type() == "PolyData") {
            std::vector<double> held;
            if (const VtkArrayInfo* h = part.find("prescribed_velocity", DataLocation::Point); h && h->components == 1) {
                held = part.values("prescribed_velocity", DataLocation::Point);
            }
            std::vector<double> diameter;
            if (const VtkArrayInfo* d = part.find("diameter", DataLocation::Point); d && d->components == 1) {
                diameter = part.values("diameter", DataLocation::Point);
            }
            const double spacing = diameter.empty() ? estimated_spacing(points, three_d, raw) : 0.0;
            for (std::size_t i = 0; i < points.size(); ++i) {
                if (!finite(points[i])) {
                    ++picture.not_finite_positions;
                    continue;
                }
                const double d = diameter.empty() || !(diameter[i] > 0.0) || !std::isfinite(diameter[i]) ? spacing : diameter[i];
                const double value = field ? field->values[i] : 0.0;
                discs.push_back({points[i].u, points[i].v, 0.5 * (d > 0.0 ? d : spacing), points[i].depth, value, field.has_value(),
                                 !failed.empty() && failed[i] != 0.0,
                                 held.empty() || !(held[i] >= 1.0 && held[i] <= 255.0) ? 0 : static_cast<int>(held[i])});
                if (!field) ++picture.without_field;
            }
        } else {
            const VtkCells cells = part.cells();
            for (std::size_t c = 0; c < cells.types.size(); ++c) {
                const std::size_t begin = c == 0 ? 0 : static_cast<std::size_t>(cells.offsets[c - 1]);
                const std::size_t end = static_cast<std::size_t>(cells.offsets[c]);
                const std::uint8_t type = cells.types[c];
                if ((type != 5 && type != 7 && type != 9) || end - begin < 3) continue;  // triangle, polygon, quad
                if (!field) ++picture.without_field;
                // A fan from the first corner (a quadrilateral or convex polygon).
                for (std::size_t k = begin + 1; k + 1 < end; ++k) {
                    const std::array<std::size_t, 3> ids{static_cast<std::size_t>(cells.connectivity[begin]),
                                                         static_cast<std::size_t>(cells.connectivity[k]),
                                                         static_cast<std::size_t>(cells.connectivity[k + 1])};
                    Triangle t{};
                    bool ok = true;
                    for (int j = 0; j < 3; ++j) {
                        t.corner[j] = points[ids[j]];
                        ok = ok && finite(t.corner[j]);
                        t.value[j] = !field ? 0.0 : field->location == DataLocation::Cell ? field->values[c] : field->values[ids[j]];
                    }
                    if (!ok) {
                        ++picture.not_finite_positions;
                        continue;
                    }
                    t.has_value = field.has_value();
                    t.failed = !failed.empty() && failed[c] != 0.0;
                    t.depth = (t.corner[0].depth + t.corner[1].depth + t.corner[2].depth) / 3.0;
                    triangles.push_back(t);
                }
            }
        }
    }
    if (!field_found) {
        std::vector<std::string> names;
        for (const auto& f : list_fields(snapshot)) names.push_back(f.name);
        std::sort(names.begin(), names.end());
        std::string files;
        for (const auto& f : snapshot.entry.files) files += (files.empty() ? "" : ", ") + f.filename().string();
        throw InputError(fmt::format("no field '{}' in snapshot {} ({}); the fields are: {}", choice.name, snapshot.index, files,
                                     fmt::join(names, ", ")));
    }
    if (discs.empty() && triangles.empty()) {
        throw InputError(fmt::format("snapshot {} ({}) has nothing to draw: no nodes or cells with finite positions",
                                     snapshot.index, snapshot.entry.files.front().string()));
    }
    // Counts, the colour range and the legends take each node and cell once, whether drawn by
    // itself, by its mirror image or both: the first of its copies still drawn.
    const auto count_own = [&] {
        const auto mark = [](auto& items) {
            std::size_t sources = 0;
            for (const auto& item : items) sources = std::max(sources, item.source + 1);
            std::vector<char> seen(sources, 0);
            std::size_t n = 0;
            for (auto& item : items) {
                item.counts = !seen[item.source];
                seen[item.source] = 1;
                n += item.counts;
            }
            return n;
        };
        picture.discs = mark(discs);
        picture.triangles = mark(triangles);
    };
    for (std::size_t i = 0; i < discs.size(); ++i) discs[i].source = i;
    for (std::size_t i = 0; i < triangles.size(); ++i) triangles[i].source = i;
    if (mirror) {
        const std::size_t n = discs.size();
        for (std::size_t i = 0; i < n; ++i) {
            Disc d = discs[i];
            d.u = -d.u;
            d.image = true;
            discs.push_back(d);
        }
        const std::size_t m = triangles.size();
        for (std::size_t i = 0; i < m; ++i) {
            Triangle t = triangles[i];
            for (auto& c : t.corner) c.u = -c.u;
            t.image = true;
            triangles.push_back(t);
        }
    }
    count_own();
    if (options.region) {
        // Keep what reaches into the window (a node whose own disc lies outside it may still be
        // drawn by its mirror image; it is then counted once, as a node drawn).
        // Plain copies, not a structured binding: lambdas below capture them (C++20 as clang 14 reads it
        // does not allow capturing structured bindings).
        const double left = (*options.region)[0], right = (*options.region)[1], bottom = (*options.region)[2],
                     top = (*options.region)[3];
        if (!(left < right) || !(bottom < top)) {
            throw InputError(fmt::format("region {} to {} by {} to {}: each range must end above where it starts",
                                         format_quantity(left, "m"), format_quantity(right, "m"), format_quantity(bottom, "m"),
                                         format_quantity(top, "m")));
        }
        double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
        const auto inside = [&](double u, double v, double r) {
            umin = std::min(umin, u - r);
            umax = std::max(umax, u + r);
            vmin = std::min(vmin, v - r);
            vmax = std::max(vmax, v + r);
            return u + r >= left && u - r <= right && v + r >= bottom && v - r <= top;
        };
        std::erase_if(discs, [&](const Disc& d) { return !inside(d.u, d.v, d.radius); });
        std::erase_if(triangles, [&](const Triangle& t) {
            bool any = false;
            for (const auto& c : t.corner) any = inside(c.u, c.v, 0.0) || any;
            const auto [ul, uh] = std::minmax({t.corner[0].u, t.corner[1].u, t.corner[2].u});
            const auto [vl, vh] = std::minmax({t.corner[0].v, t.corner[1].v, t.corner[2].v});
            return !(any || (uh >= left && ul <= right && vh >= bottom && vl <= top));
        });
        if (discs.empty() && triangles.empty()) {
            throw InputError(fmt::format("snapshot {}: nothing to draw in the region {} to {} by {} to {}; the snapshot spans {} "
                                         "to {} by {} to {}",
                                         snapshot.index, format_quantity(left, "m"), format_quantity(right, "m"),
                                         format_quantity(bottom, "m"), format_quantity(top, "m"), format_quantity(umin, "m"),
                                         format_quantity(umax, "m"), format_quantity(vmin, "m"), format_quantity(vmax, "m")));
        }
        count_own();
    }
    if (three_d) {
        // Painter's order: the farthest first, the file's order among equals.
        const auto farther = [](const auto& a, const auto& b) { return a.depth > b.depth; };
        std::stable_sort(discs.begin(), discs.end(), farther);
        std::stable_sort(triangles.begin(), triangles.end(), farther);
    }

    // The colour range: the option's, or that of the finite values drawn.
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    const auto count_value = [&](double v, bool has) {
        if (!has) return;
        if (!std::isfinite(v)) {
            ++picture.not_finite_values;
            return;
        }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    };
    // Over the nodes and cells once (count_own).
    for (const Disc& d : discs) {
        if (d.counts) count_value(d.value, d.has_value);
    }
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        if (!triangles[i].counts) continue;
        for (double v : triangles[i].value) count_value(v, triangles[i].has_value);
    }
    if (!(lo <= hi)) lo = hi = 0.0;  // nothing finite
    if (options.range_min || options.range_max) {
        const double rlo = options.range_min.value_or(lo), rhi = options.range_max.value_or(hi);
        if (!(rlo < rhi)) {
            const std::string unit(field_unit(choice.name));
            throw InputError(fmt::format("colour range {} to {} ({}): it must end above where it starts (the field's own range "
                                         "is {} to {})",
                                         format_quantity(rlo, unit), format_quantity(rhi, unit), choice.label,
                                         format_quantity(lo, unit), format_quantity(hi, unit)));
        }
        for (const Disc& d : discs) {
            if (!d.counts || !d.has_value || !std::isfinite(d.value)) continue;
            picture.below_range += d.value < rlo;
            picture.above_range += d.value > rhi;
        }
        for (std::size_t i = 0; i < triangles.size(); ++i) {
            if (!triangles[i].counts || !triangles[i].has_value) continue;
            const auto [low, high] = std::minmax({triangles[i].value[0], triangles[i].value[1], triangles[i].value[2]});
            picture.below_range += low < rlo;
            picture.above_range += high > rhi;
        }
        lo = rlo;
        hi = rhi;
    }
    picture.range_min = lo;
    picture.range_max = hi;

    // Body and material indices are categories: a colour and a name each (the scene's names when
    // the run's scene is known), unless a colour range was asked for.
    picture.categorical = (choice.name == "body" || choice.name == "material") && !choice.component && !options.range_min &&
                          !options.range_max;
    std::vector<long long> categories;
    if (picture.categorical) {
        const auto add = [&](double v, bool has) {
            if (has && std::isfinite(v)) categories.push_back(std::llround(v));
        };
        for (const Disc& d : discs) add(d.value, d.has_value && d.counts);
        for (const Triangle& t : triangles) add(t.value[0], t.has_value && t.counts);
        std::sort(categories.begin(), categories.end());
        categories.erase(std::unique(categories.begin(), categories.end()), categories.end());
    }
    const auto category_name = [&](long long k) {
        const Scene* scene = options.scene;
        if (scene && k >= 0) {
            const auto i = static_cast<std::size_t>(k);
            if (choice.name == "body" && i < scene->bodies.size()) return fmt::format("{} {}", k, scene->bodies[i].name);
            if (choice.name == "material" && i < scene->materials.size()) return fmt::format("{} {}", k, scene->materials[i].name);
        }
        return fmt::format("{} {}", choice.name, k);
    };
    const std::function<Rgb(double, bool)> paint = [&](double v, bool has) {
        if (picture.categorical && has && std::isfinite(v)) return category_colour(std::llround(v));
        return colour_of(v, has, lo, hi);
    };
    for (const Disc& d : discs) picture.failed += d.counts && d.failed;
    for (const Triangle& t : triangles) picture.failed += t.counts && t.failed;

    // Layout: text at the top, the colour bar (or legend) on the right, coordinates along the left
    // and bottom edges of the drawing, notes at the bottom.
    const DisplayUnit shown = display_unit(std::max(std::abs(lo), std::abs(hi)), picture.unit);
    const double divisor = std::pow(10.0, shown.exponent);
    const bool uniform = !(hi > lo);
    const std::array<double, 5> tick_fractions{1.0, 0.75, 0.5, 0.25, 0.0};
    std::vector<std::string> tick_labels;
    if (picture.categorical) {
        for (const long long k : categories) tick_labels.push_back(category_name(k));
    } else if (uniform) {
        tick_labels.push_back(number_text(lo / divisor) + " (uniform)");
    } else {
        for (double f : tick_fractions) tick_labels.push_back(number_text((lo + f * (hi - lo)) / divisor));
    }
    const int width = options.width;
    // The text's scale: one font pixel per 450 picture pixels of the shorter side given, 1 to 4.
    const int s = std::clamp(static_cast<int>(std::lround(std::min(width, options.height > 0 ? options.height : width) / 450.0)),
                             1, 4);
    const int margin = 8 * s, text_h = detail::text_height(s), line = detail::line_height * s;
    int label_w = 0;
    for (const auto& l : tick_labels) label_w = std::max(label_w, detail::text_width(l, s));
    label_w = std::min(label_w, width / 3);  // long names are shortened to fit
    const int bar_w = 16 * s, tick_len = 4 * s;
    const int right = margin + bar_w + tick_len + 2 * s + label_w + margin;
    const int top = margin + 2 * line + margin / 2 + line;  // title, field and time; the vertical axis' name
    const int bottom = margin / 2 + tick_len + 2 * s + line + line + margin / 2;  // ticks, their labels, notes

    const std::vector<PlaneLine> plane_lines = plane_lines_of(options.scene, three_d, view, mirror);

    double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
    const auto extend = [&](double u, double v, double r) {
        umin = std::min(umin, u - r);
        umax = std::max(umax, u + r);
        vmin = std::min(vmin, v - r);
        vmax = std::max(vmax, v + r);
    };
    if (options.region) {
        extend((*options.region)[0], (*options.region)[2], 0.0);
        extend((*options.region)[1], (*options.region)[3], 0.0);
    } else {
        for (const auto& d : discs) extend(d.u, d.v, d.radius);
        for (const auto& t : triangles) {
            for (const auto& c : t.corner) extend(c.u, c.v, 0.0);
        }
        // The drawing reaches to the planes, so that a gap between a body and its wall shows.
        reach_to_planes(plane_lines, umin, umax, vmin, vmax);
    }
    double world_w = umax - umin, world_h = vmax - vmin;
    const double world_size = std::max(world_w, world_h) > 0.0 ? std::max(world_w, world_h) : 1e-3;
    world_w = std::max(world_w, 1e-3 * world_size);
    world_h = std::max(world_h, 1e-3 * world_size);

    // The coordinates shown along the axes: each picture axis is a world axis, perhaps reversed
    // (3D views such as -y have x growing to the left), in one length unit for both.
    struct Axis {
        char name;
        double sign;
    };
    const auto axis_of = [&](int picture_axis) -> Axis {
        if (!three_d) return picture_axis == 0 ? Axis{'x', 1.0} : Axis{'z', 1.0};
        for (int a = 0; a < 3; ++a) {
            std::array<double, 3> e{};
            e[a] = 1.0;
            const ViewPoint p = project(e, view);
            const double along = picture_axis == 0 ? p.u : p.v;
            if (along != 0.0) return Axis{static_cast<char>('x' + a), along};
        }
        return Axis{'?', 1.0};
    };
    const Axis horizontal = axis_of(0), vertical = axis_of(1);
    const DisplayUnit length_unit = display_unit(std::max({std::abs(umin), std::abs(umax), std::abs(vmin), std::abs(vmax)}), "m");
    const double length_divisor = std::pow(10.0, length_unit.exponent);
    // Round tick steps (1, 2 or 5 times a power of ten) giving at most `most` ticks over [a, b].
    const auto ticks_over = [](double a, double b, int most) {
        std::vector<double> out;
        const double span = b - a;
        if (!(span > 0.0) || most < 2) return out;
        const double raw = span / most;
        const double decade = std::pow(10.0, std::floor(std::log10(raw)));
        double step = 10.0 * decade;
        for (double f : {1.0, 2.0, 5.0}) {
            if (f * decade >= raw) {
                step = f * decade;
                break;
            }
        }
        // From an integer index, so that a step below the doubles' resolution at a (a window of
        // nanometres far from the origin) cannot stall the loop: at most `most` + 1 ticks.
        const double first = std::ceil(a / step);
        for (int k = 0; k <= most; ++k) {
            const double t = (first + k) * step;
            if (t > b + 1e-9 * span) break;
            if (out.empty() || t > out.back()) out.push_back(std::abs(t) < 1e-9 * span ? 0.0 : t);
        }
        return out;
    };
    const auto coordinate_text = [&](double picture_coordinate, const Axis& axis) {
        return number_text(axis.sign * picture_coordinate / length_divisor);
    };
    // The left margin holds the vertical axis' labels, six characters wide whatever the values
    // (round ticks of three digits: "-12.5", "0.25"), so that the drawing's width, and with it a
    // free height's proportions, do not depend on the coordinates.
    const int left = margin + detail::text_width("-000.0", s) + tick_len + 2 * s;

    const int plot_w = width - left - right;
    int height = options.height;
    if (height == 0) {
        const double wanted = top + bottom + plot_w * world_h / world_w;
        height = static_cast<int>(std::clamp(std::ceil(wanted), double(min_height), double(std::min(max_side, 2 * width))));
    }
    const Area plot{left, top, width - right, height - bottom};
    if (plot.x1 - plot.x0 < 16 || plot.y1 - plot.y0 < 16) {
        throw InputError(fmt::format("picture {}x{} px leaves no room for the drawing beside the colour bar and text; make it larger",
                                     width, height));
    }
    const double plot_wd = plot.x1 - plot.x0, plot_hd = plot.y1 - plot.y0;
    PictureFrame frame;
    frame.scale = 0.98 * std::min(plot_wd / world_w, plot_hd / world_h);
    frame.u_left = 0.5 * (umin + umax) - 0.5 * plot_wd / frame.scale;
    frame.v_top = 0.5 * (vmin + vmax) + 0.5 * plot_hd / frame.scale;
    frame.left = plot.x0;
    frame.top = plot.y0;
    picture.frame = frame;

    Image img(width, height, background_colour);
    // Failure: a black dot at the centre of each failed node (of 0.35 times its radius, at least
    // 0.75 pixel) and of each failed triangle (of a pixel), drawn with its node or triangle, so
    // that in 3D what lies in front covers it too.
    for (const auto& t : triangles) {
        draw_triangle(img, plot, frame, t, paint);
        if (!t.failed) continue;
        const double u = (t.corner[0].u + t.corner[1].u + t.corner[2].u) / 3.0, v = (t.corner[0].v + t.corner[1].v + t.corner[2].v) / 3.0;
        draw_disc(img, plot, frame, {u, v, 1.0 / frame.scale, t.depth, 0.0, true}, text_colour);
    }
    for (const auto& d : discs) {
        draw_disc(img, plot, frame, d, paint(d.value, d.has_value));
        if (d.failed) draw_disc(img, plot, frame, {d.u, d.v, std::max(0.35 * d.radius, 0.75 / frame.scale), d.depth, 0.0, true}, text_colour);
    }

    // The planes: a line across the drawing (rigid: solid, with short strokes on the side away
    // from the bodies; symmetry: dashed) and the plane's name beside it on the wall's side.
    for (const PlaneLine& l : plane_lines) {
        if (l.oblique) {
            if (draw_oblique_plane_line(img, plot, frame, l, s, text_h)) ++picture.planes_drawn;
            continue;
        }
        const auto [px, py] = frame.pixel(l.vertical ? l.at : 0.0, l.vertical ? 0.0 : l.at);
        const int p = pixel_index(std::round(l.vertical ? px : py));
        if (l.vertical ? (p < plot.x0 || p >= plot.x1) : (p < plot.y0 || p >= plot.y1)) continue;
        const int from = l.vertical ? plot.y0 : plot.x0, to = l.vertical ? plot.y1 : plot.x1;
        const bool dashed = l.plane->kind == PlaneKind::Symmetry;
        const int thick = std::max(s, 1);
        for (int q = from; q < to; ++q) {
            if (dashed && ((q - from) / (6 * s)) % 2 == 1) continue;
            if (l.vertical) {
                fill_rect(img, p - s / 2, q, p - s / 2 + thick, q + 1, text_colour);
            } else {
                fill_rect(img, q, p - s / 2, q + 1, p - s / 2 + thick, text_colour);
            }
        }
        // The wall's side in pixels: -x on screen for bodies towards +u; +y (down) for bodies towards +v.
        const int away = l.vertical ? (l.toward_bodies > 0 ? -1 : 1) : (l.toward_bodies > 0 ? 1 : -1);
        if (!dashed) {
            for (int q = from + 3 * s; q < to; q += 8 * s) {
                for (int k = 0; k < 5 * s; ++k) {
                    if (l.vertical) {
                        img.set(p + away * k, q + k, text_colour);
                    } else {
                        img.set(q + k, p + away * k, text_colour);
                    }
                }
            }
        }
        // Its name on the wall's side past the strokes, or on the other side where the drawing ends.
        const std::string label = fitted(l.plane->name, (plot.x1 - plot.x0) / 2, s);
        const int name_w = detail::text_width(label, s);
        if (l.vertical) {
            int x = away < 0 ? p - 6 * s - name_w : p + 6 * s;
            if (x < plot.x0 || x + name_w > plot.x1) x = away < 0 ? p + 3 * s : p - 3 * s - name_w;
            draw_text(img, x, plot.y0 + s, label, s, text_colour);
        } else {
            int y = away > 0 ? p + 6 * s : p - text_h - 6 * s;
            if (y < plot.y0 || y + text_h > plot.y1) y = away > 0 ? p - text_h - 3 * s : p + 3 * s;
            draw_text(img, plot.x1 - name_w - s, y, label, s, text_colour);
        }
        ++picture.planes_drawn;
    }

    // Prescribed-velocity regions: a dashed rectangle around the nodes each holds (its mirror
    // image too), with the region's name (the scene's, or "region k") above it.
    std::map<int, std::array<double, 4>> held_boxes;  // region -> {umin, umax, vmin, vmax}
    for (const auto& d : discs) {
        if (d.region == 0) continue;
        const int key = d.u < 0.0 && mirror ? -d.region : d.region;  // a mirror image has a box of its own
        auto [it, fresh] = held_boxes.try_emplace(key, std::array<double, 4>{d.u - d.radius, d.u + d.radius, d.v - d.radius, d.v + d.radius});
        if (!fresh) {
            auto& b = it->second;
            b = {std::min(b[0], d.u - d.radius), std::max(b[1], d.u + d.radius), std::min(b[2], d.v - d.radius), std::max(b[3], d.v + d.radius)};
        }
    }
    for (const auto& [key, box] : held_boxes) {
        const auto [x0, y0] = frame.pixel(box[0], box[3]);
        const auto [x1, y1] = frame.pixel(box[1], box[2]);
        // Clamped to just outside the drawing, so that the loops below stay within the picture.
        const int l = std::clamp(pixel_index(std::floor(x0)) - 2 * s, plot.x0 - 1, plot.x1);
        const int r = std::clamp(pixel_index(std::ceil(x1)) + 2 * s, plot.x0 - 1, plot.x1);
        const int t = std::clamp(pixel_index(std::floor(y0)) - 2 * s, plot.y0 - 1, plot.y1);
        const int b = std::clamp(pixel_index(std::ceil(y1)) + 2 * s, plot.y0 - 1, plot.y1);
        const auto dash = [&](int q, int from) { return ((q - from) / (4 * s)) % 2 == 0; };
        for (int x = l; x <= r; ++x) {
            if (!dash(x, l) || x < plot.x0 || x >= plot.x1) continue;
            for (const int y : {t, b}) {
                if (y >= plot.y0 && y < plot.y1) fill_rect(img, x, y, x + 1, y + std::max(s, 1), text_colour);
            }
        }
        for (int y = t; y <= b; ++y) {
            if (!dash(y, t) || y < plot.y0 || y >= plot.y1) continue;
            for (const int x : {l, r}) {
                if (x >= plot.x0 && x < plot.x1) fill_rect(img, x, y, x + std::max(s, 1), y + 1, text_colour);
            }
        }
        const int k = std::abs(key) - 1;
        const Scene* scene = options.scene;
        const std::string name = scene && static_cast<std::size_t>(k) < scene->prescribed_velocities.size()
                                     ? scene->prescribed_velocities[static_cast<std::size_t>(k)].name
                                     : fmt::format("region {}", k);
        const std::string label = fitted(name, std::max(r - l, detail::text_width("m...", s)), s);
        draw_text(img, std::clamp(l, plot.x0, std::max(plot.x0, plot.x1 - detail::text_width(label, s))),
                  t - text_h - s >= plot.y0 ? t - text_h - s : b + 2 * s, label, s, text_colour);
        ++picture.regions_drawn;
    }

    // Text at the top: the title and mark, then the field, its unit and the time.
    std::string first = options.title;
    if (!snapshot.entry.mark.empty()) first += (first.empty() ? "" : "  ") + std::string("[") + snapshot.entry.mark + "]";
    if (first.empty()) first = snapshot.entry.files.front().filename().string();
    std::string second = choice.label;
    if (!shown.unit.empty() && !picture.categorical) second += " (" + shown.unit + ")";
    second += "   t = " + format_quantity(snapshot.entry.time, "s");
    if (three_d) second += "   view " + std::string(name_of(view));
    const int text_room = width - 2 * margin;
    draw_text(img, margin, margin, fitted(first, text_room, s), s, text_colour);
    draw_text(img, margin, margin + line, fitted(second, text_room, s), s, text_colour);

    // Coordinates: ticks and labels along the bottom (horizontal axis) and left (vertical axis)
    // edges, and each axis' name with the unit.
    fill_rect(img, plot.x0, plot.y1, plot.x1, plot.y1 + std::max(s / 2, 1), text_colour);
    fill_rect(img, plot.x0 - std::max(s / 2, 1), plot.y0, plot.x0, plot.y1, text_colour);
    const double visible_w = plot_wd / frame.scale, visible_h = plot_hd / frame.scale;
    const int most_u = std::max(2, static_cast<int>(plot_wd / std::max(1, detail::text_width("-00.00", s) + 6 * s)));
    const int most_v = std::max(2, static_cast<int>(plot_hd / (3 * line)));
    for (const double u : ticks_over(frame.u_left, frame.u_left + visible_w, std::min(most_u, 10))) {
        const int x = pixel_index(std::round(frame.pixel(u, 0.0)[0]));
        fill_rect(img, x - s / 2, plot.y1, x - s / 2 + std::max(s, 1), plot.y1 + tick_len, text_colour);
        const std::string label = coordinate_text(u, horizontal);
        const int w = detail::text_width(label, s);
        draw_text(img, std::clamp(x - w / 2, 0, width - w), plot.y1 + tick_len + 2 * s, label, s, text_colour);
    }
    for (const double v : ticks_over(frame.v_top - visible_h, frame.v_top, std::min(most_v, 10))) {
        const int y = pixel_index(std::round(frame.pixel(0.0, v)[1]));
        fill_rect(img, plot.x0 - tick_len, y - s / 2, plot.x0, y - s / 2 + std::max(s, 1), text_colour);
        const std::string label = coordinate_text(v, vertical);
        draw_text(img, plot.x0 - tick_len - 2 * s - detail::text_width(label, s), y - text_h / 2 + s, label, s, text_colour);
    }
    const std::string u_name = fmt::format("{} ({})", horizontal.name, length_unit.unit);
    const std::string v_name = fmt::format("{} ({})", vertical.name, length_unit.unit);
    draw_text(img, plot.x1 - detail::text_width(u_name, s), plot.y1 + tick_len + 2 * s + line, u_name, s, text_colour);
    draw_text(img, margin, plot.y0 - line, v_name, s, text_colour);

    // The colour bar, its frame, ticks and labels; or, for categories, a swatch and name each.
    const int bar_x = width - right + margin;
    const int bar_top = plot.y0 + text_h / 2;
    if (picture.categorical) {
        for (std::size_t k = 0; k < categories.size(); ++k) {
            const int y = bar_top + static_cast<int>(k) * (line + s);
            if (y + line > height) break;
            fill_rect(img, bar_x, y, bar_x + bar_w, y + text_h, category_colour(categories[k]));
            draw_text(img, bar_x + bar_w + tick_len + 2 * s, y, fitted(tick_labels[k], label_w, s), s, text_colour);
        }
    } else {
        const int bar_h = std::max(40 * s, static_cast<int>(0.6 * (plot.y1 - plot.y0)));
        const int bar_bottom = std::min(plot.y1 - text_h / 2, bar_top + bar_h);
        const int rows = bar_bottom - bar_top;
        for (int y = bar_top; y < bar_bottom; ++y) {
            const double f = uniform ? 0.5 : 1.0 - (y - bar_top + 0.5) / rows;
            fill_rect(img, bar_x, y, bar_x + bar_w, y + 1, colour_map(f));
        }
        fill_rect(img, bar_x - 1, bar_top - 1, bar_x + bar_w + 1, bar_top, text_colour);
        fill_rect(img, bar_x - 1, bar_bottom, bar_x + bar_w + 1, bar_bottom + 1, text_colour);
        fill_rect(img, bar_x - 1, bar_top - 1, bar_x, bar_bottom + 1, text_colour);
        fill_rect(img, bar_x + bar_w, bar_top - 1, bar_x + bar_w + 1, bar_bottom + 1, text_colour);
        for (std::size_t k = 0; k < tick_labels.size(); ++k) {
            const double f = uniform ? 0.5 : tick_fractions[k];
            const int y = bar_top + static_cast<int>(std::lround((1.0 - f) * rows));
            fill_rect(img, bar_x + bar_w, y - s / 2, bar_x + bar_w + tick_len, y - s / 2 + s, text_colour);
            draw_text(img, bar_x + bar_w + tick_len + 2 * s, y - text_h / 2 + s, tick_labels[k], s, text_colour);
        }
    }

    // A note under the coordinates on what is not coloured by the field.
    std::vector<std::string> notes;
    if (picture.failed > 0) notes.push_back(fmt::format("black dot: {} failed", picture.failed));
    if (picture.not_finite_values > 0) notes.push_back(fmt::format("magenta: {} not finite", picture.not_finite_values));
    if (picture.without_field > 0) notes.push_back(fmt::format("grey: {} without {}", picture.without_field, choice.name));
    if (picture.not_finite_positions > 0) notes.push_back(fmt::format("{} left out (position not finite)", picture.not_finite_positions));
    if (picture.below_range + picture.above_range > 0) {
        notes.push_back(fmt::format("{} below, {} above the range", picture.below_range, picture.above_range));
    }
    if (!notes.empty()) {
        std::string text;
        for (const auto& n : notes) text += (text.empty() ? "" : "; ") + n;
        const int room = plot.x1 - detail::text_width(u_name, s) - 3 * margin - plot.x0;
        draw_text(img, plot.x0, plot.y1 + tick_len + 2 * s + line, fitted(text, std::max(room, 0), s), s, text_colour);
    }
    picture.image = std::move(img);
    return picture;
}

Rgb category_colour(long long k) {
    // Okabe and Ito's colours for readers with colour-blindness, less their black (the text's and
    // the failure marks' colour): orange, sky blue, bluish green, yellow, blue, vermilion, purple.
    static constexpr std::array<Rgb, 7> colours{{{230, 159, 0}, {86, 180, 233}, {0, 158, 115}, {240, 228, 66}, {0, 114, 178},
                                                 {213, 94, 0}, {204, 121, 167}}};
    const long long n = static_cast<long long>(colours.size());
    return colours[static_cast<std::size_t>(((k % n) + n) % n)];
}

std::array<double, 4> series_extent(const SnapshotIndex& series, GeometryKind geometry, const RenderOptions& options) {
    const bool three_d = geometry == GeometryKind::ThreeD;
    const ViewDirection view = options.view.value_or(ViewDirection::PlusY);
    const bool mirror = !three_d && options.mirror.value_or(geometry == GeometryKind::Axisymmetric);
    double umin = std::numeric_limits<double>::infinity(), umax = -umin, vmin = umin, vmax = -umin;
    const auto extend = [&](const ViewPoint& p, double r) {
        if (!finite(p) || !std::isfinite(r)) return;
        for (const double u : {p.u, mirror ? -p.u : p.u}) {
            umin = std::min(umin, u - r);
            umax = std::max(umax, u + r);
        }
        vmin = std::min(vmin, p.v - r);
        vmax = std::max(vmax, p.v + r);
    };
    for (std::size_t k = 0; k < series.snapshots.size(); ++k) {
        const LoadedSnapshot snapshot = load_snapshot(series, k);
        for (const auto& part : snapshot.parts) {
            const std::vector<double> raw = part.points();
            std::vector<ViewPoint> points(part.point_count());
            for (std::size_t i = 0; i < points.size(); ++i) {
                const double* p = raw.data() + 3 * i;
                points[i] = three_d ? project({p[0], p[1], p[2]}, view) : ViewPoint{p[0], p[1], 0.0};
            }
            std::vector<double> diameter;
            if (part.type() == "PolyData") {
                if (const VtkArrayInfo* d = part.find("diameter", DataLocation::Point); d && d->components == 1) {
                    diameter = part.values("diameter", DataLocation::Point);
                }
            }
            // As render_snapshot draws them: a disc of the node's diameter (or of the spacing
            // estimated from the part), an element corner as a point.
            const double spacing = part.type() == "PolyData" && diameter.empty() ? estimated_spacing(points, three_d, raw) : 0.0;
            for (std::size_t i = 0; i < points.size(); ++i) {
                const double d = diameter.empty() || !(diameter[i] > 0.0) || !std::isfinite(diameter[i]) ? spacing : diameter[i];
                extend(points[i], 0.5 * d);
            }
        }
    }
    // The planes the drawing reaches to, as render_snapshot's (nothing drawn: the error below).
    if (umin < umax && vmin < vmax) reach_to_planes(plane_lines_of(options.scene, three_d, view, mirror), umin, umax, vmin, vmax);
    if (!(umin < umax) || !(vmin < vmax)) {
        throw SnapshotError(fmt::format("{}: no snapshot has a point with a finite position to frame", series.pvd.string()));
    }
    return {umin, umax, vmin, vmax};
}

// --- PNG ---------------------------------------------------------------------------------------

std::string encode_png(const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
        throw std::invalid_argument(fmt::format("encode_png: an image of {}x{} pixels with {} bytes", image.width, image.height,
                                                image.rgb.size()));
    }
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;
    png_alloc_size_t size = 0;
    const auto row_stride = static_cast<png_int_32>(image.width * 3);
    if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.rgb.data(), row_stride, nullptr)) {
        const std::string why = png.message;
        png_image_free(&png);
        throw std::runtime_error("libpng: " + why);
    }
    std::string out(size, '\0');
    if (!png_image_write_to_memory(&png, out.data(), &size, 0, image.rgb.data(), row_stride, nullptr)) {
        const std::string why = png.message;
        png_image_free(&png);
        throw std::runtime_error("libpng: " + why);
    }
    out.resize(size);
    return out;
}

void write_png(const fs::path& file, const Image& image) {
    const std::string bytes = encode_png(image);
    write_file_atomically(file, [&](std::ofstream& out) { out.write(bytes.data(), static_cast<std::streamsize>(bytes.size())); });
}

}  // namespace gpa::io
