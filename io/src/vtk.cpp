#include "gpa/io/vtk.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>

#include <fmt/format.h>

#include "gpa/io/atomic_file.hpp"
#include "vtk_appended.hpp"

namespace gpa::io {

double von_mises_stress(const std::array<double, 6>& s, int dim) {
    double ss = 0.0;
    if (dim == 2) {
        ss = s[0] * s[0] + s[1] * s[1] + s[3] * s[3] + 2.0 * s[2] * s[2];
    } else {
        ss = s[0] * s[0] + s[1] * s[1] + s[2] * s[2] + 2.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]);
    }
    return std::sqrt(1.5 * ss);
}

double von_mises_stress(const NodeStore& nodes, std::size_t i) {
    std::array<double, 6> s{};
    for (int c = 0; c < stress_components(nodes.dim()); ++c) s[c] = nodes.deviatoric_stress[c][i];
    return von_mises_stress(s, nodes.dim());
}

namespace {

struct Array {
    std::string name;
    int components;
    std::function<double(std::size_t, int)> value;
};

// Maps a node vector field to three VTK components: 2D (x, z) -> (x, z, 0).
std::function<double(std::size_t, int)> vector_field(const NodeStore& nodes, const std::array<std::vector<double>, 3>& f) {
    const int dim = nodes.dim();
    return [&f, dim](std::size_t i, int c) { return c < dim ? f[c][i] : 0.0; };
}

}  // namespace

void write_vtp(const std::filesystem::path& path, const NodeStore& nodes, std::size_t count) {
    if (count > nodes.size()) throw std::invalid_argument(fmt::format("write_vtp: {} of {} nodes", count, nodes.size()));
    std::vector<Array> arrays{
        {"velocity", 3, vector_field(nodes, nodes.velocity)},
        {"force", 3, vector_field(nodes, nodes.force)},
        {"alpha", 3, vector_field(nodes, nodes.alpha)},
        {"pressure", 1, [&](std::size_t i, int) { return nodes.pressure[i]; }},
        {"von_mises_stress", 1, [&](std::size_t i, int) { return von_mises_stress(nodes, i); }},
        {"plastic_strain", 1, [&](std::size_t i, int) { return nodes.plastic_strain[i]; }},
        {"temperature", 1, [&](std::size_t i, int) { return nodes.temperature[i]; }},
        // Johnson-Cook damage D in [0, 1]: the model sums it past 1 after failure (1.4 in a spall run),
        // which would only stretch a colour scale; `failed` below says which nodes have failed.
        {"damage", 1, [&](std::size_t i, int) { return std::min(nodes.damage[i], 1.0); }},
        {"volumetric_strain", 1, [&](std::size_t i, int) { return nodes.volumetric_strain[i]; }},
        {"diameter", 1, [&](std::size_t i, int) { return nodes.diameter[i]; }},
        {"mass", 1, [&](std::size_t i, int) { return nodes.mass[i]; }},
        {"connectivity", 1, [&](std::size_t i, int) { return nodes.connectivity[i] == Connectivity::Variable ? 1.0 : 0.0; }},
        {"body", 1, [&](std::size_t i, int) { return static_cast<double>(nodes.body[i]); }},
        {"material", 1, [&](std::size_t i, int) { return static_cast<double>(nodes.material[i]); }},
    };
    const auto positions = vector_field(nodes, nodes.position);

    detail::AppendedBlocks data;
    std::vector<std::uint64_t> offsets;
    for (const auto& a : arrays) offsets.push_back(data.add_float(count, a.components, a.value));
    const std::uint64_t points = data.add_float(count, 3, positions);
    // The node ids (node_store.hpp): the same node in every snapshot, whatever the run's reordering.
    const std::uint64_t ids = data.add_int64(count, [&](std::size_t i) { return static_cast<std::int64_t>(nodes.id[i]); });
    // 1 where the node has failed (no deviator, no tension), 0 elsewhere.
    const std::uint64_t failed = data.add_int64(count, [&](std::size_t i) { return static_cast<std::int64_t>(nodes.failed[i] != 0); });
    const std::uint64_t connectivity = data.add_int64(count, [](std::size_t i) { return static_cast<std::int64_t>(i); });
    const std::uint64_t vertex_ends = data.add_int64(count, [](std::size_t i) { return static_cast<std::int64_t>(i + 1); });

    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
            << "  <PolyData>\n"
            << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\">\n", count, count);
        out << "      <PointData>\n";
        for (std::size_t k = 0; k < arrays.size(); ++k) {
            out << fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n",
                               arrays[k].name, arrays[k].components, offsets[k]);
        }
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"id\" NumberOfComponents=\"1\" format=\"appended\" offset=\"{}\"/>\n",
                           ids);
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"failed\" NumberOfComponents=\"1\" format=\"appended\" offset=\"{}\"/>\n",
                           failed);
        out << "      </PointData>\n      <Points>\n";
        out << fmt::format("        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{}\"/>\n", points);
        out << "      </Points>\n      <Verts>\n";
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n", connectivity);
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n", vertex_ends);
        out << "      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";
        data.write(out);
        out << "\n  </AppendedData>\n</VTKFile>\n";
    });
}

void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries) {
    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n";
        for (const auto& e : entries) {
            if (e.name.empty()) {
                out << fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"{}\" file=\"{}\"/>\n", e.time, e.part, e.file);
            } else {
                out << fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"{}\" file=\"{}\" name=\"{}\"/>\n", e.time, e.part,
                                   e.file, e.name);
            }
        }
        out << "  </Collection>\n</VTKFile>\n";
    });
}

}  // namespace gpa::io
