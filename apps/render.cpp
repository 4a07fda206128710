#include "render.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <regex>
#include <system_error>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "gpa/io/atomic_file.hpp"
#include "gpa/io/render.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/snapshot_reader.hpp"
#include "gpa/io/units.hpp"

namespace gpa::app {

namespace fs = std::filesystem;

namespace {

std::optional<double> plain_number(const std::string& text) {
    double v = 0.0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (ec != std::errc() || end != text.data() + text.size() || text.empty() || !std::isfinite(v)) return std::nullopt;
    return v;
}

// The dimension of a field's values, for reading a range written with units.
std::optional<io::Dimension> dimension_of_unit(std::string_view unit) {
    if (unit == "Pa") return io::Dimension::Pressure;
    if (unit == "m/s") return io::Dimension::Velocity;
    if (unit == "m") return io::Dimension::Length;
    if (unit == "K") return io::Dimension::Temperature;
    if (unit == "kg/m^3") return io::Dimension::Density;
    if (unit == "J/kg") return io::Dimension::SpecificEnergy;
    return std::nullopt;
}

// One end of --range: a plain number (SI) or a quantity in the field's dimension ("2 GPa").
double range_end(const std::string& text, const std::string& field, const std::string& whole) {
    if (const auto v = plain_number(text)) return *v;
    const auto dimension = dimension_of_unit(io::field_unit(field));
    if (!dimension) {
        throw InputError(fmt::format("--range '{}': '{}' is not a number ({} takes plain numbers{})", whole, text, field,
                                     io::field_unit(field).empty() ? "" : fmt::format(" in {}", io::field_unit(field))));
    }
    try {
        return io::parse_quantity(text, *dimension);
    } catch (const io::UnitError& e) {
        throw InputError(fmt::format("--range '{}': '{}': {}", whole, text, e.what()));
    }
}

// --region LEFT:RIGHT,BOTTOM:TOP: four lengths, each a plain number (m) or with a unit ("30 mm").
std::array<double, 4> region_named(const std::string& text) {
    const auto comma = text.find(',');
    const std::string expected = "expected LEFT:RIGHT,BOTTOM:TOP, e.g. -30mm:30mm,-10mm:20mm (plain numbers in m)";
    if (comma == std::string::npos) throw InputError(fmt::format("--region '{}': {}", text, expected));
    std::array<double, 4> out{};
    const std::array<std::string, 2> halves{text.substr(0, comma), text.substr(comma + 1)};
    for (int h = 0; h < 2; ++h) {
        const auto colon = halves[h].find(':');
        if (colon == std::string::npos) throw InputError(fmt::format("--region '{}': {}", text, expected));
        const std::array<std::string, 2> ends{halves[h].substr(0, colon), halves[h].substr(colon + 1)};
        for (int e = 0; e < 2; ++e) {
            double v = 0.0;
            if (const auto plain = plain_number(ends[e])) {
                v = *plain;
            } else {
                try {
                    v = io::parse_quantity(ends[e], io::Dimension::Length);
                } catch (const io::UnitError& err) {
                    throw InputError(fmt::format("--region '{}': '{}': {} ({})", text, ends[e], err.what(), expected));
                }
            }
            out[2 * h + e] = v;
        }
        if (!(out[2 * h] < out[2 * h + 1])) {
            throw InputError(fmt::format("--region '{}': the {} range must end above where it starts", text,
                                         h == 0 ? "horizontal (LEFT:RIGHT)" : "vertical (BOTTOM:TOP)"));
        }
    }
    return out;
}

GeometryKind geometry_named(const std::string& text) {
    if (text == "axisymmetric") return GeometryKind::Axisymmetric;
    if (text == "plane-strain") return GeometryKind::PlaneStrain;
    if (text == "3d") return GeometryKind::ThreeD;
    throw InputError(fmt::format("--geometry '{}': expected axisymmetric, plane-strain or 3d", text));
}

std::size_t choose_snapshot(const RenderCommandOptions& o, const io::SnapshotIndex& series) {
    const std::size_t count = series.snapshots.size();
    if (!o.time.empty()) {
        double t = 0.0;
        if (const auto v = plain_number(o.time)) {
            t = *v;
        } else {
            try {
                t = io::parse_quantity(o.time, io::Dimension::Time);
            } catch (const io::UnitError& e) {
                throw InputError(fmt::format("--time '{}': {} (e.g. 40 us, or 4e-5 in seconds)", o.time, e.what()));
            }
        }
        return io::snapshot_nearest(series, t);
    }
    if (o.snapshot.empty() || o.snapshot == "last") return count - 1;
    std::size_t n = 0;
    const auto [end, ec] = std::from_chars(o.snapshot.data(), o.snapshot.data() + o.snapshot.size(), n);
    if (ec != std::errc() || end != o.snapshot.data() + o.snapshot.size()) {
        throw InputError(fmt::format("--snapshot '{}': expected a snapshot number (0 to {}) or last", o.snapshot, count - 1));
    }
    if (n >= count) {
        throw InputError(fmt::format("--snapshot {}: {} lists {} snapshots, 0 to {}", n, series.pvd.string(), count, count - 1));
    }
    return n;
}

// "00012" of particles_00012.vtp, "failed_step00027" of particles_failed_step00027.vtp.
std::string snapshot_label(const io::LoadedSnapshot& s) {
    const std::string stem = s.entry.files.front().stem().string();
    const auto underscore = stem.find('_');
    return underscore == std::string::npos ? fmt::format("{:05d}", s.index) : stem.substr(underscore + 1);
}

std::string file_safe(std::string text) {
    std::string out;
    for (char c : text) {
        if (c == '|') continue;
        out += (c == ':' || c == '/' || c == ' ') ? '-' : c;
    }
    return out;
}

void print_listing(const io::SnapshotIndex& series, const io::LoadedSnapshot& chosen, const std::string& geometry_text) {
    fmt::print("{}: {} snapshots; geometry {}\n", series.pvd.string(), series.snapshots.size(), geometry_text);
    fmt::print("  {:>5}  {:>12}  files\n", "index", "time");
    for (std::size_t k = 0; k < series.snapshots.size(); ++k) {
        const auto& s = series.snapshots[k];
        std::string files;
        for (const auto& f : s.files) files += (files.empty() ? "" : ", ") + f.filename().string();
        fmt::print("  {:>5}  {:>12}  {}{}\n", k, io::format_quantity(s.time, "s"), files, s.mark.empty() ? "" : "  [" + s.mark + "]");
    }
    fmt::print("fields of snapshot {} (t = {}):\n", chosen.index, io::format_quantity(chosen.entry.time, "s"));
    fmt::print("  {:<20} {:>10}  {:<36} {:>12} {:>12}\n", "name", "components", "where", "min", "max");
    for (const auto& f : io::list_fields(chosen)) {
        const std::string unit(io::field_unit(f.name));
        const std::string what = f.components == 6 ? " (every component)" : f.components > 1 ? " (magnitude)" : "";
        fmt::print("  {:<20} {:>10}  {:<36} {:>12} {:>12}{}\n", f.name, f.components, f.where, io::format_quantity(f.min, unit),
                   io::format_quantity(f.max, unit), what);
    }
}

}  // namespace

int render_run(const RenderCommandOptions& o) {
    io::RenderOptions options;
    options.field = o.field;
    if (!o.size.empty()) {
        static const std::regex pattern(R"(\s*(\d{1,6})\s*[xX]\s*(\d{1,6})\s*)");
        std::smatch m;
        if (!std::regex_match(o.size, m, pattern)) {
            throw InputError(fmt::format("--size '{}': expected WIDTHxHEIGHT in pixels, e.g. 800x600", o.size));
        }
        options.width = std::stoi(m[1].str());
        options.height = std::stoi(m[2].str());
        if (options.width < io::min_width || options.width > io::max_side || options.height < io::min_height ||
            options.height > io::max_side) {
            throw InputError(fmt::format("--size '{}': the width must be {} to {} pixels and the height {} to {}", o.size,
                                         io::min_width, io::max_side, io::min_height, io::max_side));
        }
    }
    if (o.width) {  // given, 0 included: the default width is taken only when the option is left out
        if (*o.width < io::min_width || *o.width > io::max_side) {
            throw InputError(fmt::format("--width {}: it must be {} to {} pixels", *o.width, io::min_width, io::max_side));
        }
        options.width = *o.width;
    }
    if (!o.view.empty()) {
        options.view = io::view_direction_named(o.view);
        if (!options.view) throw InputError(fmt::format("--view '{}': expected +x, -x, +y, -y, +z or -z", o.view));
    }
    if (!o.region.empty()) options.region = region_named(o.region);
    if (o.frame != "snapshot" && o.frame != "run") {
        throw InputError(fmt::format("--frame '{}': expected snapshot (fitted to the snapshot) or run (one frame for every snapshot)",
                                     o.frame));
    }
    options.mark_failed = !o.no_failed_marks;
    if (o.mirror) options.mirror = true;
    if (o.no_mirror) options.mirror = false;

    const fs::path pvd = io::find_pvd(o.run);
    const io::SnapshotIndex series = io::read_pvd(pvd);
    const fs::path folder = pvd.parent_path().empty() ? fs::path(".") : pvd.parent_path();
    const io::LoadedSnapshot snapshot = io::load_snapshot(series, choose_snapshot(o, series));

    GeometryKind geometry = GeometryKind::PlaneStrain;
    std::string geometry_text;
    if (!o.geometry.empty()) {
        geometry = geometry_named(o.geometry);
        geometry_text = fmt::format("{} (--geometry)", name_of(geometry));
    } else if (const auto known = io::read_run_geometry(folder)) {
        geometry = known->geometry;
        geometry_text = fmt::format("{} (from {})", name_of(geometry), known->source);
    } else {
        // Not recorded: 3D if any point leaves the plane z = 0 of the file, 2D otherwise.
        bool out_of_plane = false;
        for (const auto& part : snapshot.parts) {
            const auto p = part.points();
            for (std::size_t i = 2; i < p.size() && !out_of_plane; i += 3) out_of_plane = p[i] != 0.0;
        }
        geometry = out_of_plane ? GeometryKind::ThreeD : GeometryKind::PlaneStrain;
        geometry_text = fmt::format("{} (no scene.toml or summary.json in {}: guessed from the points; --geometry says otherwise)",
                                    out_of_plane ? "3D" : "2D, not mirrored", folder.string());
    }
    if (o.list) {
        print_listing(series, snapshot, geometry_text);
        return 0;
    }

    if (!o.range.empty()) {
        const auto colon = o.range.find(':');
        if (colon == std::string::npos) {
            throw InputError(fmt::format("--range '{}': expected MIN:MAX (either may be left out: 0: or :2e9)", o.range));
        }
        const std::string field_name = o.field.substr(0, o.field.find(':'));
        const std::string low = o.range.substr(0, colon), high = o.range.substr(colon + 1);
        if (!low.empty()) options.range_min = range_end(low, field_name, o.range);
        if (!high.empty()) options.range_max = range_end(high, field_name, o.range);
        if (low.empty() && high.empty()) throw InputError(fmt::format("--range '{}': give MIN, MAX or both", o.range));
    }
    // The run's scene, for the title, the names of bodies and materials and the planes drawn. A
    // scene.toml that does not read (another version's) costs only these: the picture is drawn.
    std::optional<Scene> scene;
    std::string scene_note;
    std::error_code scene_ec;  // a scene.toml that cannot be examined is taken as absent
    if (const fs::path file = folder / "scene.toml"; fs::is_regular_file(file, scene_ec)) {
        try {
            scene = io::parse_scene(io::read_scene_text(file), file.string());
            options.scene = &*scene;
        } catch (const InputError& e) {
            scene_note = fmt::format("note: drawn without the scene's names and planes: {}", e.what());
        }
    }
    const std::string run_name = folder.filename().string() == "." ? fs::absolute(folder).filename().string() : folder.filename().string();
    options.title = scene && !scene->name.empty()
                        ? fmt::format("{} ({})  snapshot {} of 0-{}", scene->name, run_name, snapshot.index, series.snapshots.size() - 1)
                        : fmt::format("{}  snapshot {} of 0-{}", run_name, snapshot.index, series.snapshots.size() - 1);
    if (o.frame == "run") options.region = io::series_extent(series, geometry, options);
    const io::Picture picture = io::render_snapshot(snapshot, geometry, options);

    fs::path output;
    const std::string default_name =
        fmt::format("{}-{}.png", file_safe(io::parse_field_choice(o.field, geometry).label), snapshot_label(snapshot));
    std::error_code ec;
    if (!o.output) {
        output = folder / default_name;
    } else if (fs::is_directory(*o.output, ec)) {
        output = *o.output / default_name;
    } else {
        output = *o.output;
        const fs::path parent = output.parent_path();
        if (!parent.empty() && !fs::is_directory(parent, ec)) {
            throw io::OutputError(fmt::format("-o {}: the folder {} does not exist", output.string(), parent.string()));
        }
    }
    io::write_png(output, picture.image);
    if (!o.quiet) {
        fmt::print("wrote {} ({}x{}): snapshot {} of 0-{} at t = {}, {} from {} to {}; {} nodes, {} element triangles; geometry {}{}\n",
                   output.string(), picture.image.width, picture.image.height, snapshot.index, series.snapshots.size() - 1,
                   io::format_quantity(snapshot.entry.time, "s"), io::parse_field_choice(o.field, geometry).label,
                   io::format_quantity(picture.range_min, picture.unit), io::format_quantity(picture.range_max, picture.unit),
                   picture.discs, picture.triangles, geometry_text, picture.mirrored ? ", mirrored about x = 0" : "");
        if (picture.not_finite_values) fmt::print("note: {} values not finite (drawn magenta)\n", picture.not_finite_values);
        if (picture.not_finite_positions) fmt::print("note: {} nodes or cells with positions not finite left out\n", picture.not_finite_positions);
        if (picture.without_field) fmt::print("note: {} nodes or cells of parts without the field (drawn grey)\n", picture.without_field);
        if (picture.failed) fmt::print("note: {} failed nodes or cells (marked with a black dot)\n", picture.failed);
        if (!scene_note.empty()) fmt::print("{}\n", scene_note);
        if (picture.below_range + picture.above_range) {
            fmt::print("note: {} below and {} above the colour range (drawn in its end colours)\n", picture.below_range,
                       picture.above_range);
        }
    }
    return 0;
}

}  // namespace gpa::app
