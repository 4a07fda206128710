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

#include "gpa/engine/surface.hpp"

namespace gpa::io {

// Throws InputError naming the file and, for ASCII, the line: a file that cannot be read, one that
// is neither form, a binary file whose count does not match its length, a number that is not one,
// a facet without three vertices, more than max_stl_triangles triangles. The surface is checked
// (check_surface) before it is returned, and so is its width in metres along each axis, which its
// inside test needs finite and, unless 0, no less than the smallest normal double (surface.hpp
// does not refuse those). Reads the file and hands its bytes to parse_stl.
TriangleSurface read_stl(const std::filesystem::path& file, double unit);

// The same from the file's bytes, `name` standing for the file in the messages (the fuzz target
// tests/fuzz/fuzz_stl.cpp reads through here, and so does read_stl).
TriangleSurface parse_stl(std::string_view bytes, const std::string& name, double unit);

inline constexpr std::size_t max_stl_triangles = 20'000'000;

}  // namespace gpa::io
