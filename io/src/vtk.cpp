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

using detail::AppendedBlocks;
using Declared = AppendedBlocks::Declared;

// Maps a node vector field to three VTK components: 2D (x, z) -> (x, z, 0).
std::function<double(std::size_t, int)> vector_field(const NodeStore& nodes, const std::array<std::vector<double>, 3>& f) {
    const int dim = nodes.dim();
    return [&f, dim](std::size_t i, int c) { return c < dim ? f[c][i] : 0.0; };
}

// The Cauchy stress of node i as a VTK symmetric tensor (detail::vtk_stress_component).
double vtk_stress(const NodeStore& nodes, std::size_t i, int c) {
    std::array<double, 6> s{};
    for (int k = 0; k < stress_components(nodes.dim()); ++k) s[static_cast<std::size_t>(k)] = nodes.deviatoric_stress[k][i];
    return detail::vtk_stress_component(s.data(), nodes.pressure[i], nodes.dim(), c);
}

}  // namespace

void write_vtp(const std::filesystem::path& path, const NodeStore& nodes, std::size_t count, const SnapshotFormat& format) {
    if (count > nodes.size()) throw std::invalid_argument(fmt::format("write_vtp: {} of {} nodes", count, nodes.size()));
    const bool float32 = format.precision == SnapshotPrecision::Float32;
    const char* float_type = float32 ? "Float32" : "Float64";
    AppendedBlocks data;
    std::vector<Declared> arrays;
    const auto floats = [&](SnapshotField f, int components, std::function<double(std::size_t, int)> value) {
        arrays.push_back({std::string(name_of(f)), float_type, components, data.add_float(count, components, std::move(value), float32)});
    };
    const auto scalar = [&](SnapshotField f, const std::vector<double>& v) {
        floats(f, 1, [&v](std::size_t i, int) { return v[i]; });
    };
    for (const SnapshotField f : format.fields) {
        switch (f) {
            case SnapshotField::Velocity: floats(f, 3, vector_field(nodes, nodes.velocity)); break;
            case SnapshotField::Force: floats(f, 3, vector_field(nodes, nodes.force)); break;
            case SnapshotField::Alpha: floats(f, 3, vector_field(nodes, nodes.alpha)); break;
            case SnapshotField::Pressure: scalar(f, nodes.pressure); break;
            case SnapshotField::ViscousPressure: scalar(f, nodes.viscous_pressure); break;
            case SnapshotField::VonMisesStress: floats(f, 1, [&](std::size_t i, int) { return von_mises_stress(nodes, i); }); break;
            case SnapshotField::Stress: floats(f, 6, [&](std::size_t i, int c) { return vtk_stress(nodes, i, c); }); break;
            case SnapshotField::PlasticStrain: scalar(f, nodes.plastic_strain); break;
            case SnapshotField::PlasticWork: scalar(f, nodes.plastic_work); break;
            case SnapshotField::Temperature: scalar(f, nodes.temperature); break;
            // Johnson-Cook damage D in [0, 1]: the model sums it past 1 after failure (1.4 in a spall
            // run), which would only stretch a colour scale; `failed` says which nodes have failed.
            case SnapshotField::Damage: floats(f, 1, [&](std::size_t i, int) { return std::min(nodes.damage[i], 1.0); }); break;
            case SnapshotField::Failed:
                arrays.push_back({"failed", "UInt8", 1,
                                  data.add_uint8(count, [&](std::size_t i) { return static_cast<std::uint8_t>(nodes.failed[i] != 0); })});
                break;
            case SnapshotField::VolumetricStrain: scalar(f, nodes.volumetric_strain); break;
            case SnapshotField::Density: floats(f, 1, [&](std::size_t i, int) { return nodes.mass[i] / nodes.volume[i]; }); break;
            case SnapshotField::InternalEnergy: scalar(f, nodes.internal_energy); break;
            case SnapshotField::Displacement:
                floats(f, 3, [&](std::size_t i, int c) {
                    return c < nodes.dim() ? nodes.position[c][i] - nodes.initial_position[c][i] : 0.0;
                });
                break;
            case SnapshotField::InitialPosition: floats(f, 3, vector_field(nodes, nodes.initial_position)); break;
            case SnapshotField::Diameter: scalar(f, nodes.diameter); break;
            case SnapshotField::Mass: scalar(f, nodes.mass); break;
            case SnapshotField::Connectivity:
                arrays.push_back({"connectivity", "UInt8", 1, data.add_uint8(count, [&](std::size_t i) {
                                      return static_cast<std::uint8_t>(nodes.connectivity[i] == Connectivity::Variable);
                                  })});
                break;
            case SnapshotField::Body:
                arrays.push_back({"body", "Int32", 1, data.add_int32(count, [&](std::size_t i) { return nodes.body[i]; })});
                break;
            case SnapshotField::Material:
                arrays.push_back({"material", "Int32", 1, data.add_int32(count, [&](std::size_t i) { return nodes.material[i]; })});
                break;
            case SnapshotField::PrescribedVelocity:
                arrays.push_back({"prescribed_velocity", "UInt8", 1, data.add_uint8(count, [&](std::size_t i) { return nodes.velocity_region[i]; })});
                break;
        }
    }
    // The node ids (node_store.hpp): the same node in every snapshot, whatever the run's reordering.
    arrays.push_back({"id", "Int64", 1, data.add_int64(count, [&](std::size_t i) { return static_cast<std::int64_t>(nodes.id[i]); })});
    const std::vector<Declared> points{{"", float_type, 3, data.add_float(count, 3, vector_field(nodes, nodes.position), float32)}};
    const std::vector<Declared> verts{
        {"connectivity", "Int64", 1, data.add_int64(count, [](std::size_t i) { return static_cast<std::int64_t>(i); })},
        {"offsets", "Int64", 1, data.add_int64(count, [](std::size_t i) { return static_cast<std::int64_t>(i + 1); })}};

    write_file_atomically(path, [&](std::ofstream& out) {
        out << "<?xml version=\"1.0\"?>\n"
            << "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
            << "  <PolyData>\n"
            << fmt::format("    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\">\n", count, count);
        out << "      <PointData>\n";
        AppendedBlocks::write_tags(out, "        ", arrays);
        out << "      </PointData>\n      <Points>\n";
        AppendedBlocks::write_tags(out, "        ", points);
        out << "      </Points>\n      <Verts>\n";
        AppendedBlocks::write_tags(out, "        ", verts);
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
