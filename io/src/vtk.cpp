#include "gpa/io/vtk.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <stdexcept>

#include <fmt/format.h>

#include "gpa/io/atomic_file.hpp"

namespace gpa::io {

double von_mises_stress(const NodeStore& nodes, std::size_t i) {
    const auto& s = nodes.deviatoric_stress;
    double ss = 0.0;
    if (nodes.dim() == 2) {
        ss = s[0][i] * s[0][i] + s[1][i] * s[1][i] + s[3][i] * s[3][i] + 2.0 * s[2][i] * s[2][i];
    } else {
        ss = s[0][i] * s[0][i] + s[1][i] * s[1][i] + s[2][i] * s[2][i] +
             2.0 * (s[3][i] * s[3][i] + s[4][i] * s[4][i] + s[5][i] * s[5][i]);
    }
    return std::sqrt(1.5 * ss);
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
        {"damage", 1, [&](std::size_t i, int) { return nodes.damage[i]; }},
        {"volumetric_strain", 1, [&](std::size_t i, int) { return nodes.volumetric_strain[i]; }},
        {"diameter", 1, [&](std::size_t i, int) { return nodes.diameter[i]; }},
        {"mass", 1, [&](std::size_t i, int) { return nodes.mass[i]; }},
        {"connectivity", 1, [&](std::size_t i, int) { return nodes.connectivity[i] == Connectivity::Variable ? 1.0 : 0.0; }},
        {"body", 1, [&](std::size_t i, int) { return static_cast<double>(nodes.body[i]); }},
        {"material", 1, [&](std::size_t i, int) { return static_cast<double>(nodes.material[i]); }},
    };
    const auto positions = vector_field(nodes, nodes.position);

    write_file_atomically(path, [&](std::ofstream& out) {
        std::uint64_t offset = 0;
        const auto block_bytes = [&](int components) { return 8 + 8 * static_cast<std::uint64_t>(components) * count; };
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
            << "  <PolyData>\n"
            << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\">\n", count, count);
        out << "      <PointData>\n";
        for (const auto& a : arrays) {
            out << fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" offset=\"{}\"/>\n",
                               a.name, a.components, offset);
            offset += block_bytes(a.components);
        }
        out << "      </PointData>\n      <Points>\n";
        out << fmt::format("        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{}\"/>\n", offset);
        offset += block_bytes(3);
        out << "      </Points>\n      <Verts>\n";
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n", offset);
        offset += 8 + 8 * static_cast<std::uint64_t>(count);
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n", offset);
        out << "      </Verts>\n    </Piece>\n  </PolyData>\n  <AppendedData encoding=\"raw\">\n   _";

        std::vector<char> buffer;
        const auto put = [&](const void* p, std::size_t n) {
            const auto* c = static_cast<const char*>(p);
            buffer.insert(buffer.end(), c, c + n);
        };
        const auto flush = [&] {
            out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
            buffer.clear();
        };
        const auto put_block = [&](int components, const std::function<double(std::size_t, int)>& value) {
            const std::uint64_t bytes = 8 * static_cast<std::uint64_t>(components) * count;
            put(&bytes, 8);
            for (std::size_t i = 0; i < count; ++i) {
                for (int c = 0; c < components; ++c) {
                    const double v = value(i, c);
                    put(&v, 8);
                }
                if (buffer.size() >= (std::size_t{1} << 20)) flush();  // a bounded buffer: no copy of a whole field
            }
            flush();
        };
        for (const auto& a : arrays) put_block(a.components, a.value);
        put_block(3, positions);
        for (int pass = 0; pass < 2; ++pass) {
            const std::uint64_t bytes = 8 * static_cast<std::uint64_t>(count);
            put(&bytes, 8);
            for (std::size_t i = 0; i < count; ++i) {
                const std::int64_t v = static_cast<std::int64_t>(pass == 0 ? i : i + 1);
                put(&v, 8);
                if (buffer.size() >= (std::size_t{1} << 20)) flush();
            }
            flush();
        }
        out << "\n  </AppendedData>\n</VTKFile>\n";
    });
}

void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries) {
    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n  <Collection>\n";
        for (const auto& e : entries) {
            if (e.name.empty()) {
                out << fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\"/>\n", e.time, e.file);
            } else {
                out << fmt::format("    <DataSet timestep=\"{:.9g}\" part=\"0\" file=\"{}\" name=\"{}\"/>\n", e.time, e.file,
                                   e.name);
            }
        }
        out << "  </Collection>\n</VTKFile>\n";
    });
}

}  // namespace gpa::io
