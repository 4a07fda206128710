#pragma once
// A closed triangulated surface, an STL file's solid (io/stl.hpp), whose inside a body's lattice
// fills (BodySpec::surface, docs/scene-format.md "Imported shapes"). A lattice node belongs to the
// body when its cell centre is inside, as for the other shapes.
//
// The inside test is the parity of the crossings of a ray: from the point upwards along z, a point
// is inside when the ray crosses the surface an odd number of times. It needs a closed surface,
// which check_surface makes sure of (every edge shared by exactly two triangles), and no
// orientation. A ray through an edge or a vertex shared by triangles seen from above is counted
// once by the top-left rule of rasterisers (an edge belongs to the triangle it bounds on its left
// or top side, in the triangles' projection on the xy plane, each made counter-clockwise), so that
// points on the projection of an edge are neither lost nor counted twice. Triangles seen edge-on
// (vertical in z) are not crossed.
//
// The rule needs the signs of the predicates exact: a point on the projection of an edge must
// come out on it for both triangles that share the edge, and a sliver whose corners are nearly in
// a line must not cover points far from it. So the vertices and the query point are snapped to an
// integer grid of 2^31 steps across the surface's largest extent (a step of 5e-10 of it, far below
// any lattice spacing), and the side of an edge (orient2d) and of the triangle's plane (orient3d)
// are computed exactly in 128-bit integers.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace gpa {

struct TriangleSurface {
    std::vector<std::array<double, 3>> vertices;         // m
    std::vector<std::array<std::uint32_t, 3>> triangles; // vertex indices
};

// Refuses (InputError, `what` names the surface in the message, e.g. the STL file) a surface with
// fewer than 4 triangles, a vertex that is not finite, an index out of range, a triangle with no
// area, or an edge not shared by exactly two triangles (a hole or a non-manifold seam; the message
// gives the edge's end points and how many triangles share it).
void check_surface(const TriangleSurface& surface, const std::string& what);

// The volume a closed surface encloses (divergence theorem; its sign is that of the orientation:
// positive with the normals outwards by the right-hand rule), m^3.
double enclosed_volume(const TriangleSurface& surface);

// The inside test of a checked surface, with the triangles bucketed on a grid over the xy plane so
// that a query visits only the triangles above or below the point's column.
class SurfaceInside {
public:
    explicit SurfaceInside(std::shared_ptr<const TriangleSurface> surface);
    // Strictly inside (a point on the surface may go either way).
    bool inside(const std::array<double, 3>& p) const;
    const TriangleSurface& triangles() const { return *surface_; }
    const std::array<double, 3>& lower() const { return lower_; }
    const std::array<double, 3>& upper() const { return upper_; }

private:
    using Snapped = std::array<std::int64_t, 3>;
    Snapped snap(const std::array<double, 3>& p) const;

    std::shared_ptr<const TriangleSurface> surface_;
    std::array<double, 3> lower_{}, upper_{};
    double grid_step_ = 1.0;                 // of the integer grid, m
    std::vector<Snapped> snapped_;           // the vertices on it
    std::array<std::size_t, 2> cells_{1, 1};  // the bucket grid over xy
    std::array<double, 2> cell_size_{1, 1};
    std::vector<std::size_t> offsets_;       // per bucket, its triangles in `members_`
    std::vector<std::uint32_t> members_;
};

}  // namespace gpa
