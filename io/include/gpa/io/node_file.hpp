#pragma once
// Node files: the positions and sizes of a body's nodes made by another tool, read into a NodeSet
// (engine/node_set.hpp) for a body of shape "nodes" (docs/scene-format.md, "Imported nodes").
//
// Two forms, told apart by the file's extension:
//   .csv  a table: a header line naming the columns, then one line per node. 3D takes columns x,
//         y, z and volume; 2D x, z and area (the node's cross-section). Other columns (an id, a
//         material number) are ignored; names are matched without regard to letter case or
//         surrounding spaces and quotes; blank lines and lines starting with # are skipped.
//   .vtp  a VTK XML point file (PolyData, or an UnstructuredGrid .vtu), uncompressed, as gpa's
//   .vtu  snapshots and ParaView write them (snapshot_reader.hpp): its points, and a point array
//         "volume" (3D) or "area" (2D); or else the arrays "mass" and "density" of a gpa snapshot
//         (SI whatever `unit` is: volume = mass / density, in axisymmetric geometry a ring's, so
//         the area is volume / (2 pi x)). In 2D the points are (x, z, 0).
// Positions are in `unit` metres (1e-3 for millimetres), volumes in unit^3, areas in unit^2.
//
// Errors are InputError naming the file and the line (CSV) or point (VTK). The set returned is
// checked (check_node_set). Before its nodes are read, their memory (the file's bytes, about
// bytes_to_import_node per node to read and check them, and what a run needs per node, limits.hpp)
// is checked against `memory`: LimitError, naming the file, when it would not fit.

#include <filesystem>
#include <string>
#include <string_view>

#include "gpa/engine/geometry.hpp"
#include "gpa/engine/limits.hpp"
#include "gpa/engine/node_set.hpp"

namespace gpa::io {

NodeSet read_node_file(const std::filesystem::path& file, double unit, GeometryKind geometry, const MemoryLimit& memory = {});

// Memory per node while a node file is read and checked: the NodeSet (position, size, the name of
// its line, with the vectors' growth) and the NodeSetShape's diameters and bucket grid.
inline constexpr double bytes_to_import_node = 300.0;

// The CSV form from bytes held in memory; `name` stands for the file in messages.
NodeSet parse_node_csv(std::string_view text, const std::string& name, double unit, GeometryKind geometry,
                       const MemoryLimit& memory = {});

// The largest node file read, in bytes (a CSV line is about 60 bytes: some 70 million nodes).
inline constexpr std::uintmax_t max_node_file_bytes = std::uintmax_t{4} << 30;

}  // namespace gpa::io
