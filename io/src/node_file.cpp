#include "gpa/io/node_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <optional>
#include <vector>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "gpa/io/snapshot_reader.hpp"
#include "toml_reading.hpp"  // printable: a file's bytes quoted in a message stay one line

namespace gpa::io {

namespace {

std::string_view trimmed(std::string_view s) {
    const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r'; };
    while (!s.empty() && space(s.front())) s.remove_prefix(1);
    while (!s.empty() && space(s.back())) s.remove_suffix(1);
    return s;
}

// A header name as matched: trimmed, without surrounding quotes, in lower case.
std::string column_name(std::string_view s) {
    s = trimmed(s);
    if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trimmed(s.substr(1, s.size() - 2));
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

std::vector<std::string_view> split_commas(std::string_view line) {
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    while (true) {
        const std::size_t comma = line.find(',', start);
        fields.push_back(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (comma == std::string_view::npos) return fields;
        start = comma + 1;
    }
}

// A whole field as a number ("1.5", "-2e-3", "+4"; surrounding spaces and quotes allowed).
std::optional<double> number(std::string_view s) {
    s = trimmed(s);
    if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trimmed(s.substr(1, s.size() - 2));
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || end != s.data() + s.size() || s.empty()) return std::nullopt;
    return v;
}

std::string read_bytes(const std::filesystem::path& file) {
    const std::string what = file.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such node file", what));
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw InputError(fmt::format("{}: cannot be read", what));
    if (size > max_node_file_bytes) {
        throw InputError(fmt::format("{}: {} bytes, more than the {} GiB a node file may hold", what, size, max_node_file_bytes >> 30));
    }
    std::ifstream in(file, std::ios::binary);
    std::string bytes(static_cast<std::size_t>(size), '\0');
    if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) throw InputError(fmt::format("{}: cannot be read", what));
    return bytes;
}

// Refuses `nodes` nodes from a file of `file_bytes` bytes that would not fit in `memory`: the
// file, reading and checking them, and running them (limits.hpp, as check_scene_memory counts).
// `counted` says what the nodes are ("65 lines (a node each, at most)").
void check_nodes_fit(const std::string& what, double file_bytes, double nodes, const std::string& counted, int dim,
                     const MemoryLimit& memory) {
    const double run = bytes_per_node_besides_lists(dim) + list_entries_per_node(dim) * bytes_per_list_entry;
    const double need = file_bytes + nodes * (bytes_to_import_node + run);
    if (need <= static_cast<double>(limit_bytes(memory))) return;
    throw LimitError(fmt::format("{}: its {} need an estimated {} of memory to read and run ({} per node besides the "
                                 "file's {}); {}",
                                 what, counted, format_bytes(need), format_bytes(bytes_to_import_node + run), format_bytes(file_bytes),
                                 describe_limit(memory)));
}

NodeSet read_node_vtk(const std::filesystem::path& file, double unit, GeometryKind geometry, const MemoryLimit& memory) {
    const std::string what = file.string();
    const int dim = dimension_of(geometry);
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(file, ec);
    check_nodes_fit(what, static_cast<double>(bytes), 0.0, "bytes", dim, memory);
    const VtkFile vtk(file);  // SnapshotError (an InputError) naming the file for anything malformed
    const std::size_t n = vtk.point_count();
    check_nodes_fit(what, static_cast<double>(bytes), static_cast<double>(n), fmt::format("{} points", n), dim, memory);
    if (n > max_imported_nodes) {
        throw InputError(fmt::format("{}: {} points, more than the {} one body may import", what, n, max_imported_nodes));
    }
    const std::vector<double> points = vtk.points();
    NodeSet set;
    set.positions.resize(n);
    set.origins.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        for (int c = 0; c < 3; ++c) set.positions[k][static_cast<std::size_t>(c)] = points[3 * k + static_cast<std::size_t>(c)] * unit;
        set.origins[k] = fmt::format("point {}", k);
    }
    const char* measure = dim == 3 ? "volume" : "area";
    const auto one_component = [&](std::string_view name) -> const VtkArrayInfo* {
        const VtkArrayInfo* info = vtk.find(name, DataLocation::Point);
        if (info && info->components != 1) {
            throw InputError(fmt::format("{}: its point array \"{}\" has {} components; one is expected", what, name,
                                         info->components));
        }
        return info;
    };
    if (one_component(measure)) {
        set.sizes = vtk.values(measure, DataLocation::Point);
        const double scale = dim == 3 ? unit * unit * unit : unit * unit;
        for (double& v : set.sizes) v *= scale;
    } else if (one_component("mass") && one_component("density")) {
        // A gpa snapshot's nodes: their volume from mass and density (SI), a ring's in axisymmetric
        // geometry.
        const std::vector<double> mass = vtk.values("mass", DataLocation::Point);
        const std::vector<double> density = vtk.values("density", DataLocation::Point);
        set.sizes.resize(n);
        for (std::size_t k = 0; k < n; ++k) {
            double v = mass[k] / density[k];
            if (geometry == GeometryKind::Axisymmetric) v /= 2.0 * std::numbers::pi * set.positions[k][0];
            set.sizes[k] = v;
        }
    } else {
        std::vector<std::string> names;
        for (const auto& a : vtk.arrays()) {
            if (a.location == DataLocation::Point) names.push_back(fmt::format("\"{}\"", a.name));
        }
        throw InputError(fmt::format("{}: no point array \"{}\" (each node's {}), nor \"mass\" and \"density\" as a gpa snapshot "
                                     "has; its point arrays: {}",
                                     what, measure, dim == 3 ? "volume" : "cross-section area",
                                     names.empty() ? "none" : fmt::format("{}", fmt::join(names, ", "))));
    }
    check_node_set(set, dim, geometry == GeometryKind::Axisymmetric, what);
    return set;
}

}  // namespace

NodeSet parse_node_csv(std::string_view text, const std::string& name, double unit, GeometryKind geometry,
                       const MemoryLimit& memory) {
    const int dim = dimension_of(geometry);
    // At most a node per line: their memory before any is read.
    const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + (!text.empty() && text.back() != '\n');
    check_nodes_fit(name, static_cast<double>(text.size()), static_cast<double>(lines),
                    fmt::format("{} lines (a node each, at most)", lines), dim, memory);
    if (!(unit > 0.0) || !std::isfinite(unit)) throw InputError(fmt::format("{}: its unit {} m must be a positive length", name, unit));
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // a UTF-8 byte-order mark
    const std::vector<std::string> wanted = dim == 3 ? std::vector<std::string>{"x", "y", "z", "volume"}
                                                     : std::vector<std::string>{"x", "z", "area"};
    std::vector<std::size_t> column(wanted.size());
    std::size_t columns = 0;
    bool header = false;
    NodeSet set;
    std::size_t line_number = 0;
    const double scale[2] = {unit, dim == 3 ? unit * unit * unit : unit * unit};
    while (!text.empty()) {
        const std::size_t end = text.find('\n');
        const std::string_view line = text.substr(0, end);
        text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
        ++line_number;
        const std::string_view content = trimmed(line);
        if (content.empty() || content.front() == '#') continue;
        if (content.find('\0') != std::string_view::npos) {
            throw InputError(fmt::format("{}:{}: holds a zero byte: not a text (CSV) file", name, line_number));
        }
        const auto fields = split_commas(content);
        if (!header) {
            header = true;
            columns = fields.size();
            std::vector<std::string> names;
            for (const auto f : fields) names.push_back(column_name(f));
            std::vector<std::string> shown;  // as the message quotes them
            for (const auto& n : names) shown.push_back(detail::printable(n, 40));
            for (std::size_t w = 0; w < wanted.size(); ++w) {
                const auto it = std::find(names.begin(), names.end(), wanted[w]);
                if (it == names.end()) {
                    throw InputError(fmt::format("{}:{}: the header names no column \"{}\": a {} scene's nodes need the columns "
                                                 "{} (the first line that is not blank or a # comment is the header; it "
                                                 "names {})",
                                                 name, line_number, wanted[w], dim == 3 ? "3D" : "2D",
                                                 fmt::join(wanted, ", "), fmt::join(shown, ", ")));
                }
                if (std::find(it + 1, names.end(), wanted[w]) != names.end()) {
                    throw InputError(fmt::format("{}:{}: the header names column \"{}\" twice", name, line_number, wanted[w]));
                }
                column[w] = static_cast<std::size_t>(it - names.begin());
            }
            continue;
        }
        if (fields.size() != columns) {
            throw InputError(fmt::format("{}:{}: {} fields, but the header has {} columns", name, line_number, fields.size(), columns));
        }
        if (set.positions.size() >= max_imported_nodes) {
            throw InputError(fmt::format("{}:{}: more than the {} nodes one body may import", name, line_number, max_imported_nodes));
        }
        std::array<double, 3> p{0.0, 0.0, 0.0};
        double size = 0.0;
        for (std::size_t w = 0; w < wanted.size(); ++w) {
            const auto v = number(fields[column[w]]);
            if (!v) {
                throw InputError(fmt::format("{}:{}: column \"{}\": \"{}\" is not a number", name, line_number, wanted[w],
                                             detail::printable(trimmed(fields[column[w]]), 40)));
            }
            if (w + 1 < wanted.size()) {
                p[w] = *v * scale[0];
            } else {
                size = *v * scale[1];
            }
        }
        set.positions.push_back(p);
        set.sizes.push_back(size);
        set.origins.push_back(fmt::format("line {}", line_number));
    }
    if (!header) throw InputError(fmt::format("{}: holds no header line (and no node)", name));
    check_node_set(set, dim, geometry == GeometryKind::Axisymmetric, name);
    return set;
}

NodeSet read_node_file(const std::filesystem::path& file, double unit, GeometryKind geometry, const MemoryLimit& memory) {
    const std::string what = file.string();
    if (!(unit > 0.0) || !std::isfinite(unit)) throw InputError(fmt::format("{}: its unit {} m must be a positive length", what, unit));
    std::string extension = file.extension().string();
    for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    if (extension == ".csv") {
        std::error_code ec;
        if (std::filesystem::is_regular_file(file, ec)) {  // the file's own bytes first
            check_nodes_fit(what, static_cast<double>(std::filesystem::file_size(file, ec)), 0.0, "bytes", dimension_of(geometry),
                            memory);
        }
        return parse_node_csv(read_bytes(file), what, unit, geometry, memory);
    }
    if (extension == ".vtp" || extension == ".vtu") {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec)) throw InputError(fmt::format("{}: no such node file", what));
        return read_node_vtk(file, unit, geometry, memory);
    }
    throw InputError(fmt::format("{}: a node file is a CSV table (.csv) or a VTK XML point file (.vtp, .vtu); this one's "
                                 "extension is \"{}\"", what, extension));
}

}  // namespace gpa::io
