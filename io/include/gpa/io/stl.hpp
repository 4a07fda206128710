#pragma once
// STL files (the triangulated surfaces CAD programs export), read into a TriangleSurface
// (engine/surface.hpp) for a body of shape "surface" (docs/scene-format.md, "Imported shapes").
//
// Both forms are read: binary (an 80-byte header, a triangle count, 50 bytes per triangle: the
// count must match the file's length) and ASCII ("solid ... facet normal ... outer loop, vertex
// x y z three times, endloop, endfacet ... endsolid"). The facets' normals are ignored (the inside
// test needs none). Corners with the same three coordinates are one vertex, so that the surface's
// edges are shared as check_surface expects. STL has no unit: `unit` is the length of one of the
// file's units in metres (1e-3 for a file in millimetres).

#include <filesystem>
#include <string>
#include <string_view>

#include "gpa/engine/limits.hpp"
#include "gpa/engine/surface.hpp"

namespace gpa::io {

// Throws InputError naming the file and, for ASCII, the line: a file that cannot be read, one that
// is neither form, a binary file whose count does not match its length, a number that is not one,
// a facet without three vertices, more than max_stl_triangles triangles. The surface is checked
// (check_surface) before it is returned, which includes its width in metres along each axis: its
// inside test needs it finite and, unless 0, no less than the smallest normal double. Reads the
// file and hands its bytes to parse_stl. Before it reads, the memory the file may take (its bytes
// and bytes_per_stl_triangle for each of the file's bytes / 50 triangles at most: a binary
// triangle takes 50 bytes, an ASCII one more) is checked against `memory`: LimitError naming the
// file when it would not fit.
TriangleSurface read_stl(const std::filesystem::path& file, double unit, const MemoryLimit& memory = {});

// The same from the file's bytes, `name` standing for the file in the messages (the fuzz target
// tests/fuzz/fuzz_shape_files.cpp reads through here, and so does read_stl).
TriangleSurface parse_stl(std::string_view bytes, const std::string& name, double unit);

inline constexpr std::size_t max_stl_triangles = 20'000'000;

// Memory per triangle while a surface is read and made ready for its inside test: the map that
// merges corners (half a vertex per triangle), the vertices and triangles with the vectors'
// growth, the snapped vertices and the bucket grid (at most 32 entries of 4 bytes per triangle).
inline constexpr double bytes_per_stl_triangle = 256.0;

}  // namespace gpa::io
