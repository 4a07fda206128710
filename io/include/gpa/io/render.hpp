#pragma once
// Pictures of snapshots without ParaView: one snapshot of a run folder coloured by a field, as
// an RGB image written to PNG (libpng).
//
// 2D runs (stored as (x, z, 0), vtk.hpp) are drawn in the x-z plane, x to the right and z up,
// each particle node as a filled disc of its diameter; axisymmetric runs are mirrored about the
// axis by default, so the picture is the whole section through the cylinder. 3D runs are an
// orthographic projection along a coordinate axis, the discs drawn from the farthest to the
// nearest (painter's order). Element bodies (the .vtu parts of the same snapshot) are drawn as
// filled triangles, coloured by their cell field, or by their point field interpolated across
// the triangle. The picture carries a colour bar with the field's name, unit and range (a legend
// of names for body and material), the snapshot's time, coordinates along both axes, the scene's
// planes and a mark on every failed node.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/geometry.hpp"
#include "gpa/engine/scene.hpp"
#include "gpa/io/snapshot_reader.hpp"

namespace gpa::io {

struct Rgb {
    std::uint8_t r = 0, g = 0, b = 0;
    friend bool operator==(const Rgb&, const Rgb&) = default;
};

struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;  // row by row from the top, 3 bytes a pixel
    Image() = default;
    Image(int w, int h, Rgb fill);
    Rgb at(int x, int y) const;
    void set(int x, int y, Rgb c);  // ignores pixels outside the image
};

inline constexpr Rgb background_colour{255, 255, 255};
inline constexpr Rgb text_colour{32, 32, 32};
inline constexpr Rgb no_field_colour{170, 170, 170};    // a part without the field
inline constexpr Rgb not_finite_colour{255, 0, 255};    // a value that is NaN or infinite

// The colour of t in [0, 1] (clamped): a ramp of our own through dark violet, blue, teal, green
// and yellow whose lightness rises evenly from end to end (after matplotlib's viridis), so that
// equal steps of the field read as equal steps of colour, in grey print too.
Rgb colour_map(double t);

// 3D: the direction the picture looks along. +y looks from the -y side with x to the right and z
// up (the 2D pictures' orientation); the others keep a right-handed (right, up, towards the
// viewer) frame: -y: right -x, up z; +x: right -y, up z; -x: right y, up z; -z (from above):
// right x, up y; +z (from below): right -x, up y.
enum class ViewDirection { PlusX, MinusX, PlusY, MinusY, PlusZ, MinusZ };
std::optional<ViewDirection> view_direction_named(std::string_view text);  // "+y", "-z", "y" (= +y)
std::string_view name_of(ViewDirection v);

// A point in the picture plane: u to the right, v up, depth along the view direction (larger is
// farther from the viewer).
struct ViewPoint {
    double u = 0.0, v = 0.0, depth = 0.0;
};
ViewPoint project(const std::array<double, 3>& p, ViewDirection view);

// What to colour by: "pressure", "velocity" (a vector: its magnitude), "velocity:z" (a
// component: x, z in 2D, x, y, z in 3D, or "magnitude"), "stress:xz" (a component of a symmetric
// tensor: xx, yy, zz, xy, yz, xz in 3D; xx, zz, xz and hoop (axisymmetric) or yy (plane strain) in 2D).
struct FieldChoice {
    std::string name;
    std::optional<int> component;  // index into the stored components; nullopt: magnitude or scalar
    bool tensor = false;           // the component is a tensor's (xx, ...), not a vector's (x, ...)
    std::string label;             // "velocity:z", "|velocity|", "pressure"
};
// Throws InputError for an empty name or a component that is not one of the geometry's axes.
FieldChoice parse_field_choice(std::string_view text, GeometryKind geometry);

// The unit of a field gpa writes ("Pa", "m/s", "K", ...; "" for dimensionless and for fields it
// does not know).
std::string_view field_unit(std::string_view name);

struct RenderOptions {
    std::string field = "velocity";
    int width = 800;  // pixels, 200 to 8192
    int height = 0;   // 150 to 8192; 0: from the width and the scene's proportions
    // The colour range; either end left out is the field's own minimum or maximum over the
    // snapshot. The range must end above where it starts.
    std::optional<double> range_min, range_max;
    std::optional<bool> mirror;                       // 2D: mirror about x = 0; default: axisymmetric
    std::optional<ViewDirection> view;                // 3D only; default +y
    // Only this window of the picture plane, {left, right, bottom, top} in metres along the
    // picture's own axes (2D: x and z; 3D: the view's right and up); the colour range and the
    // counts then cover only what lies in it. Default: the whole snapshot.
    std::optional<std::array<double, 4>> region;
    std::string title;                                // drawn at the top (e.g. the scene's name)
    // The run's scene (its scene.toml), when known: the names in the legends of `body` and
    // `material`, and the rigid and symmetry planes, drawn as lines where they are seen edge-on.
    const Scene* scene = nullptr;
    // Failed nodes and cells (a snapshot's `failed` array) get a black dot at their centre, in
    // every field but `failed` itself.
    bool mark_failed = true;
};
inline constexpr int min_width = 200, min_height = 150, max_side = 8192;

// A snapshot's files, opened and checked.
struct LoadedSnapshot {
    std::size_t index = 0;  // in its .pvd
    SeriesSnapshot entry;
    std::vector<VtkFile> parts;
};
LoadedSnapshot load_snapshot(const SnapshotIndex& series, std::size_t index);

// The snapshot nearest to time t (the earlier of two as near).
std::size_t snapshot_nearest(const SnapshotIndex& series, double t);

// The fields a snapshot holds (point data of every part, cell data of element parts): name,
// components and which parts have it, with the range of each (magnitude of vectors, every component of tensors) over finite
// values.
struct FieldSummary {
    std::string name;
    int components = 1;
    std::string where;  // "particles", "element points", "element cells", joined by ", "
    double min = 0.0, max = 0.0;
    std::size_t values = 0;  // finite values
};
std::vector<FieldSummary> list_fields(const LoadedSnapshot& snapshot);

// Where a point of the picture plane lands in the image: pixel column and row (fractional, the
// centre of the top-left pixel is (0.5, 0.5)).
struct PictureFrame {
    double scale = 1.0;           // pixels per metre
    double u_left = 0.0, v_top = 0.0;  // the plane's point at the plot area's top-left corner
    double left = 0.0, top = 0.0;      // that corner in pixels
    std::array<double, 2> pixel(double u, double v) const {
        return {left + (u - u_left) * scale, top + (v_top - v) * scale};
    }
};

struct Picture {
    Image image;
    PictureFrame frame;
    double range_min = 0.0, range_max = 0.0;  // the colour range used
    std::string unit;
    bool mirrored = false;
    std::size_t discs = 0, triangles = 0;     // drawn (a mirrored node counts once)
    std::size_t not_finite_values = 0;        // drawn in not_finite_colour
    std::size_t not_finite_positions = 0;     // left out
    std::size_t without_field = 0;            // nodes and cells of parts without the field (grey)
    std::size_t below_range = 0, above_range = 0;
    std::size_t failed = 0;                   // nodes and cells marked failed (a mirrored node counts once)
    bool categorical = false;                 // body or material: a colour and a name per value, no colour bar
    std::size_t planes_drawn = 0;             // scene planes drawn as lines
    std::size_t regions_drawn = 0;            // prescribed-velocity regions outlined (a mirror image counts)
};

// The colour of category k (a body or material index) in pictures coloured by `body` or
// `material`: seven colours that colour-blind readers tell apart (Okabe and Ito's, less black),
// repeated.
Rgb category_colour(long long k);

// The picture-plane window {left, right, bottom, top} (m) holding every snapshot of a series as
// render_snapshot would draw it (discs with their diameters, mirrored 2D runs with their mirror
// image): passed as RenderOptions::region, it keeps one frame for every snapshot of a run, so
// that a body's motion shows. Throws SnapshotError for a file that cannot be read.
std::array<double, 4> series_extent(const SnapshotIndex& series, GeometryKind geometry, const RenderOptions& options);

// Draws the snapshot. Throws InputError for an unknown field (listing the snapshot's fields), a
// component of a scalar field, a size outside the limits above, a range with min >= max, mirror
// or view options that do not apply to the geometry.
Picture render_snapshot(const LoadedSnapshot& snapshot, GeometryKind geometry, const RenderOptions& options);

// The image as PNG bytes (8-bit RGB), and written to a file atomically (OutputError naming it).
std::string encode_png(const Image& image);
void write_png(const std::filesystem::path& file, const Image& image);

// "40 us", "1.25 GPa": a value with the SI prefix that puts it between 1 and 1000 for units that
// take prefixes (Pa, m, s, N, J/kg, kg as g), three significant digits.
std::string format_quantity(double value, std::string_view unit);

}  // namespace gpa::io
