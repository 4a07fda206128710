#pragma once
// ParaView-readable snapshots: particles as VTK XML PolyData (.vtp) with one vertex per node and
// the node fields as point data, element bodies as an UnstructuredGrid (.vtu) of triangles, and
// a .pvd time-series index over snapshots (a snapshot with both kinds lists both files as parts
// of one time step).
// 2D nodes are written in the X-Y plane as (x, z, 0), so that ParaView shows the axial
// direction upwards.

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/snapshot_fields.hpp"

namespace gpa::io {

// Writes nodes [0, count) to `path` (binary, appended raw data): the fields `format` names, in its
// order and float width (snapshot_fields.hpp), then the Int64 node ids, always. Flags (failed,
// connectivity) are UInt8 and indices (body, material) Int32. The file is written under a
// temporary name and renamed into place, so a reader never sees half a file. Throws
// std::runtime_error naming the path when it cannot be written.
void write_vtp(const std::filesystem::path& path, const NodeStore& nodes, std::size_t count,
               const SnapshotFormat& format = {default_snapshot_fields(), SnapshotPrecision::Float64});

struct PvdEntry {
    double time;
    std::string file;  // relative to the .pvd
    std::string name = {};  // a mark such as "failed step 27" (the DataSet's name attribute); empty: none
    int part = 0;           // files of one time step are parts 0, 1, ...
};
void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries);

// Equivalent (von Mises) stress of node i from its deviatoric stress, sqrt(3/2 s:s), Pa.
double von_mises_stress(const NodeStore& nodes, std::size_t i);
// The same from deviator components in the order of geometry.hpp (2D: xx, zz, xz, out-of-plane).
double von_mises_stress(const std::array<double, 6>& s, int dim);

// Element bodies as a VTK XML UnstructuredGrid (.vtu): of the fields `format` names, those an
// element body has, the node fields (velocity, force, mass, body) at the points and the material
// point fields (pressure, stresses, plastic strain and work, temperature, damage, failed, density,
// internal energy, viscous pressure, material) at the triangles; always the contact bits and ids
// of the points and the quadrilateral of each triangle. Written atomically, like write_vtp.
void write_vtu(const std::filesystem::path& path, const ElementMesh& mesh,
               const SnapshotFormat& format = {default_snapshot_fields(), SnapshotPrecision::Float64});

}  // namespace gpa::io
