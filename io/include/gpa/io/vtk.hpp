#pragma once
// ParaView-readable particle snapshots: VTK XML PolyData (.vtp) with one vertex per node and
// the node fields as point data, and a .pvd time-series index over snapshots.
// 2D nodes are written in the X-Y plane as (x, z, 0), so that ParaView shows the axial
// direction upwards.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "gpa/engine/node_store.hpp"

namespace gpa::io {

// Writes nodes [0, count) with their fields to `path` (binary, appended raw data). The file is
// written under a temporary name and renamed into place, so a reader never sees half a file.
// Throws std::runtime_error naming the path when it cannot be written.
void write_vtp(const std::filesystem::path& path, const NodeStore& nodes, std::size_t count);

struct PvdEntry {
    double time;
    std::string file;  // relative to the .pvd
    std::string name = {};  // a mark such as "failed step 27" (the DataSet's name attribute); empty: none
};
void write_pvd(const std::filesystem::path& path, const std::vector<PvdEntry>& entries);

// Equivalent (von Mises) stress of node i from its deviatoric stress, sqrt(3/2 s:s), Pa.
double von_mises_stress(const NodeStore& nodes, std::size_t i);

}  // namespace gpa::io
