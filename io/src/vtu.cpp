// Element bodies as a VTK XML UnstructuredGrid (.vtu), the counterpart of the particles' .vtp
// (vtk.hpp): one point per element node, one triangle cell (VTK type 5) per material point.
// 2D positions are written as (x, z, 0), as for particles, so that ParaView shows z upwards.

#include <algorithm>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "gpa/io/atomic_file.hpp"
#include "gpa/io/vtk.hpp"
#include "vtk_appended.hpp"

namespace gpa::io {

void write_vtu(const std::filesystem::path& path, const ElementMesh& mesh, const SnapshotFormat& format) {
    using detail::AppendedBlocks;
    using Declared = AppendedBlocks::Declared;
    const ElementNodes& n = mesh.nodes;
    const ElementPoints& p = mesh.points;
    const std::size_t points = n.size(), cells = p.size();
    const bool float32 = format.precision == SnapshotPrecision::Float32;
    const char* float_type = float32 ? "Float32" : "Float64";
    AppendedBlocks data;
    std::vector<Declared> point_arrays, cell_arrays;
    const auto vector = [](const std::array<std::vector<double>, 2>& f) {
        return [&f](std::size_t i, int c) { return c < 2 ? f[static_cast<std::size_t>(c)][i] : 0.0; };
    };
    const auto node_floats = [&](SnapshotField f, int components, std::function<double(std::size_t, int)> value) {
        point_arrays.push_back({std::string(name_of(f)), float_type, components, data.add_float(points, components, std::move(value), float32)});
    };
    const auto cell_floats = [&](SnapshotField f, int components, std::function<double(std::size_t, int)> value) {
        cell_arrays.push_back({std::string(name_of(f)), float_type, components, data.add_float(cells, components, std::move(value), float32)});
    };
    const auto cell_scalar = [&](SnapshotField f, const std::vector<double>& v) {
        cell_floats(f, 1, [&v](std::size_t i, int) { return v[i]; });
    };
    // The fields an element body has, in the order asked for; the others (alpha, diameter,
    // connectivity, volumetric strain, displacement, initial position) are particle fields.
    for (const SnapshotField f : format.fields) {
        switch (f) {
            case SnapshotField::Velocity: node_floats(f, 3, vector(n.velocity)); break;
            case SnapshotField::Force: node_floats(f, 3, vector(n.force)); break;
            case SnapshotField::Mass: node_floats(f, 1, [&](std::size_t i, int) { return n.mass[i]; }); break;
            case SnapshotField::Body:
                point_arrays.push_back({"body", "Int32", 1, data.add_int32(points, [&](std::size_t i) { return n.body[i]; })});
                break;
            case SnapshotField::Pressure: cell_scalar(f, p.pressure); break;
            case SnapshotField::ViscousPressure: cell_scalar(f, p.viscous_pressure); break;
            case SnapshotField::VonMisesStress:
                cell_floats(f, 1, [&](std::size_t i, int) {
                    return von_mises_stress({p.deviatoric_stress[0][i], p.deviatoric_stress[1][i], p.deviatoric_stress[2][i],
                                             p.deviatoric_stress[3][i], 0.0, 0.0},
                                            2);
                });
                break;
            case SnapshotField::Stress:
                // As the particles' (detail::vtk_stress_component).
                cell_floats(f, 6, [&](std::size_t i, int c) {
                    const std::array<double, 4> dev{p.deviatoric_stress[0][i], p.deviatoric_stress[1][i], p.deviatoric_stress[2][i],
                                                    p.deviatoric_stress[3][i]};
                    return detail::vtk_stress_component(dev.data(), p.pressure[i], 2, c);
                });
                break;
            case SnapshotField::PlasticStrain: cell_scalar(f, p.plastic_strain); break;
            case SnapshotField::PlasticWork: cell_scalar(f, p.plastic_work); break;
            case SnapshotField::Temperature: cell_scalar(f, p.temperature); break;
            case SnapshotField::Damage: cell_floats(f, 1, [&](std::size_t i, int) { return std::min(p.damage[i], 1.0); }); break;
            case SnapshotField::Failed:
                cell_arrays.push_back({"failed", "UInt8", 1, data.add_uint8(cells, [&](std::size_t i) { return static_cast<std::uint8_t>(p.failed[i] != 0); })});
                break;
            case SnapshotField::Density: cell_scalar(f, p.density); break;
            case SnapshotField::InternalEnergy: cell_scalar(f, p.internal_energy); break;
            case SnapshotField::Material:
                cell_arrays.push_back({"material", "Int32", 1, data.add_int32(cells, [&](std::size_t i) { return mesh.quads.material[i / 4]; })});
                break;
            default: break;
        }
    }
    // Always: the rigid planes each node touches (a bit per plane), the node ids, and the
    // quadrilateral of each triangle. An element node keeps its index for the whole run (the mesh
    // is never reordered), so that index is its id, as the particles' ids are theirs (vtk.cpp).
    point_arrays.push_back({"contact", "UInt8", 1, data.add_uint8(points, [&](std::size_t i) { return n.contact[i]; })});
    point_arrays.push_back({"id", "Int64", 1, data.add_int64(points, [](std::size_t i) { return static_cast<std::int64_t>(i); })});
    cell_arrays.push_back({"element", "Int64", 1, data.add_int64(cells, [](std::size_t i) { return static_cast<std::int64_t>(i / 4); })});
    const std::vector<Declared> positions{{"", float_type, 3, data.add_float(points, 3, vector(n.position), float32)}};
    // Triangle 4q + k is (centre, corner k, corner k + 1) of quadrilateral q (elements.hpp).
    const std::vector<Declared> cell_lists{
        {"connectivity", "Int64", 1, data.add_int64(3 * cells, [&](std::size_t e) {
             const std::size_t t = e / 3, q = t / 4, k = t % 4, a = e % 3;
             const std::size_t corner = a == 0 ? 4 : a == 1 ? k : (k + 1) % 4;
             return static_cast<std::int64_t>(mesh.quads.nodes[q][corner]);
         })},
        {"offsets", "Int64", 1, data.add_int64(cells, [](std::size_t t) { return static_cast<std::int64_t>(3 * (t + 1)); })},
        {"types", "UInt8", 1, data.add_uint8(cells, [](std::size_t) { return std::uint8_t{5}; })},  // VTK_TRIANGLE
    };

    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
            << "  <UnstructuredGrid>\n"
            << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n", points, cells);
        out << "      <PointData>\n";
        AppendedBlocks::write_tags(out, "        ", point_arrays);
        out << "      </PointData>\n      <CellData>\n";
        AppendedBlocks::write_tags(out, "        ", cell_arrays);
        out << "      </CellData>\n      <Points>\n";
        AppendedBlocks::write_tags(out, "        ", positions);
        out << "      </Points>\n      <Cells>\n";
        AppendedBlocks::write_tags(out, "        ", cell_lists);
        out << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n  <AppendedData encoding=\"raw\">\n   _";
        data.write(out);
        out << "\n  </AppendedData>\n</VTKFile>\n";
    });
}

}  // namespace gpa::io
