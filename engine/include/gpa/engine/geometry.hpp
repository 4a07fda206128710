#pragma once
// The three geometries of the method as compile-time tags. Kernels are templates over these so
// that their inner loops carry no run-time branch on the geometry.
//
// Coordinates: in 2D, component 0 is x (radial in axisymmetric geometry) and component 1 is z
// (axial); the out-of-plane direction is theta (axisymmetric) or y (plane strain, unit
// thickness). In 3D the components are x, y, z.
//
// Stress components (symmetric tensors) are stored in this order:
//   2D: xx, zz, xz, out-of-plane (theta-theta or yy)
//   3D: xx, yy, zz, yz, xz, xy

#include <cstddef>
#include <string_view>

namespace gpa {

enum class GeometryKind { PlaneStrain, Axisymmetric, ThreeD };

struct PlaneStrain {
    static constexpr int dim = 2;
    static constexpr bool axisymmetric = false;
    static constexpr GeometryKind kind = GeometryKind::PlaneStrain;
};

struct Axisymmetric {
    static constexpr int dim = 2;
    static constexpr bool axisymmetric = true;
    static constexpr GeometryKind kind = GeometryKind::Axisymmetric;
};

struct ThreeD {
    static constexpr int dim = 3;
    static constexpr bool axisymmetric = false;
    static constexpr GeometryKind kind = GeometryKind::ThreeD;
};

constexpr int dimension_of(GeometryKind g) { return g == GeometryKind::ThreeD ? 3 : 2; }

// The letter of component `axis` in messages and file headers: x, z in 2D; x, y, z in 3D.
constexpr char axis_letter(int axis, int dim) {
    if (dim == 2) return axis == 0 ? 'x' : 'z';
    return axis == 0 ? 'x' : axis == 1 ? 'y' : 'z';
}

// Number of stored components of a symmetric stress tensor (see the order above).
constexpr int stress_components(int dim) { return dim == 3 ? 6 : 4; }

constexpr std::string_view name_of(GeometryKind g) {
    switch (g) {
        case GeometryKind::PlaneStrain: return "plane strain";
        case GeometryKind::Axisymmetric: return "axisymmetric";
        case GeometryKind::ThreeD: return "3D";
    }
    return "?";
}

// Calls f(tag) with the tag type of a run-time geometry: the one place where a run-time choice
// becomes a compile-time one.
template <class F>
decltype(auto) dispatch_geometry(GeometryKind g, F&& f) {
    switch (g) {
        case GeometryKind::PlaneStrain: return f(PlaneStrain{});
        case GeometryKind::Axisymmetric: return f(Axisymmetric{});
        case GeometryKind::ThreeD: break;
    }
    return f(ThreeD{});
}

}  // namespace gpa
