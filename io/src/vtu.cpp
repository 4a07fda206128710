// Element bodies as a VTK XML UnstructuredGrid (.vtu), the counterpart of the particles' .vtp
// (vtk.hpp): one point per element node, one triangle cell (VTK type 5) per material point.
// 2D positions are written as (x, z, 0), as for particles, so that ParaView shows z upwards.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpa/io/atomic_file.hpp"
#include "gpa/io/vtk.hpp"
#include "vtk_appended.hpp"

namespace gpa::io {

void write_vtu(const std::filesystem::path& path, const ElementMesh& mesh) {
    const ElementNodes& n = mesh.nodes;
    const ElementPoints& p = mesh.points;
    const std::size_t points = n.size(), cells = p.size();
    struct Array {
        std::string name;
        int components;
        std::function<double(std::size_t, int)> value;
    };
    const auto vector = [](const std::array<std::vector<double>, 2>& f) {
        return [&f](std::size_t i, int c) { return c < 2 ? f[static_cast<std::size_t>(c)][i] : 0.0; };
    };
    const std::vector<Array> point_arrays{
        {"velocity", 3, vector(n.velocity)},
        {"force", 3, vector(n.force)},
        {"mass", 1, [&](std::size_t i, int) { return n.mass[i]; }},
        {"body", 1, [&](std::size_t i, int) { return static_cast<double>(n.body[i]); }},
        {"contact", 1, [&](std::size_t i, int) { return static_cast<double>(n.contact[i]); }},
    };
    const std::vector<Array> cell_arrays{
        {"pressure", 1, [&](std::size_t i, int) { return p.pressure[i]; }},
        {"von_mises_stress", 1,
         [&](std::size_t i, int) {
             return von_mises_stress({p.deviatoric_stress[0][i], p.deviatoric_stress[1][i], p.deviatoric_stress[2][i],
                                      p.deviatoric_stress[3][i], 0.0, 0.0},
                                     2);
         }},
        {"plastic_strain", 1, [&](std::size_t i, int) { return p.plastic_strain[i]; }},
        {"temperature", 1, [&](std::size_t i, int) { return p.temperature[i]; }},
        {"damage", 1, [&](std::size_t i, int) { return p.damage[i]; }},
        {"density", 1, [&](std::size_t i, int) { return p.density[i]; }},
        {"internal_energy", 1, [&](std::size_t i, int) { return p.internal_energy[i]; }},
        {"viscous_pressure", 1, [&](std::size_t i, int) { return p.viscous_pressure[i]; }},
        {"failed", 1, [&](std::size_t i, int) { return static_cast<double>(p.failed[i]); }},
        {"material", 1, [&](std::size_t i, int) { return static_cast<double>(mesh.quads.material[i / 4]); }},
        {"element", 1, [&](std::size_t i, int) { return static_cast<double>(i / 4); }},
    };
    detail::AppendedBlocks data;
    std::vector<std::uint64_t> point_offsets, cell_offsets;
    for (const auto& a : point_arrays) point_offsets.push_back(data.add_float(points, a.components, a.value));
    for (const auto& a : cell_arrays) cell_offsets.push_back(data.add_float(cells, a.components, a.value));
    const std::uint64_t positions = data.add_float(points, 3, vector(n.position));
    // The node ids, as the particle snapshots write them (vtk.cpp): an element node keeps its index
    // for the whole run (the mesh is never reordered), so that index is its id.
    const std::uint64_t ids = data.add_int64(points, [](std::size_t i) { return static_cast<std::int64_t>(i); });
    // Triangle 4q + k is (centre, corner k, corner k + 1) of quadrilateral q (elements.hpp).
    const std::uint64_t connectivity = data.add_int64(3 * cells, [&](std::size_t e) {
        const std::size_t t = e / 3, q = t / 4, k = t % 4, a = e % 3;
        const std::size_t corner = a == 0 ? 4 : a == 1 ? k : (k + 1) % 4;
        return static_cast<std::int64_t>(mesh.quads.nodes[q][corner]);
    });
    const std::uint64_t ends = data.add_int64(cells, [](std::size_t t) { return static_cast<std::int64_t>(3 * (t + 1)); });
    const std::uint64_t types = data.add_uint8(cells, [](std::size_t) { return std::uint8_t{5}; });  // VTK_TRIANGLE

    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
            << "  <UnstructuredGrid>\n"
            << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points, cells);
        const auto arrays = [&](const char* tag, const std::vector<Array>& list, const std::vector<std::uint64_t>& offsets) {
            out << fmt::format("      <{}>\n", tag);
            for (std::size_t k = 0; k < list.size(); ++k) {
                out << fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" "
                                   "offset=\"{}\"/>\n",
                                   list[k].name, list[k].components, offsets[k]);
            }
            out << fmt::format("      </{}>\n", tag);
        };
        out << "      <PointData>\n";
        for (std::size_t k = 0; k < point_arrays.size(); ++k) {
            out << fmt::format("        <DataArray type=\"Float64\" Name=\"{}\" NumberOfComponents=\"{}\" format=\"appended\" "
                               "offset=\"{}\"/>\n",
                               point_arrays[k].name, point_arrays[k].components, point_offsets[k]);
        }
        out << fmt::format("        <DataArray type=\"Int64\" Name=\"id\" NumberOfComponents=\"1\" format=\"appended\" offset=\"{}\"/>\n",
                           ids);
        out << "      </PointData>\n";
        arrays("CellData", cell_arrays, cell_offsets);
        out << "      <Points>\n"
            << fmt::format("        <DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\"{}\"/>\n",
                           positions)
            << "      </Points>\n      <Cells>\n"
            << fmt::format("        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"{}\"/>\n",
                           connectivity)
            << fmt::format("        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"{}\"/>\n", ends)
            << fmt::format("        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"{}\"/>\n", types)
            << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
        data.write(out);
        out << "\n  </AppendedData>\n</VTKFile>\n";
    });
}

}  // namespace gpa::io
