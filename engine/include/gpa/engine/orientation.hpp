#pragma once
// Orientation: rotations of bodies and of whole scenes, and the normals of planes in any direction
// (docs/scene-format.md, "Orientation").
//
// A rotation acts on engine components (geometry.hpp): in 3D on (x, y, z); in plane strain on
// (x, z) through its top-left 2x2 block, the rest of the matrix being the identity. Axisymmetric
// scenes have no rotations (their axis is fixed).

#include <array>
#include <optional>
#include <string>

namespace gpa {

// A proper rotation matrix, row-major: v' = R v, v'_r = sum_c R[3 r + c] v_c.
using Rotation = std::array<double, 9>;

inline constexpr Rotation identity_rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};

// Exactly the identity (bit for bit): the un-rotated path of every caller, which keeps the
// coordinates of axis-aligned scenes free of any rounding a product with R would add.
bool is_identity(const Rotation& r);

// The rotation by `angle` (radians, right-handed) about `axis` (3D; any non-zero length;
// Rodrigues' formula). Throws InputError for a zero or non-finite axis or angle.
Rotation rotation_about(const std::array<double, 3>& axis, double angle);

// The plane-strain rotation by `angle` (radians) in the (x, z) plane, from x towards z.
Rotation rotation_in_plane(double angle);

Rotation compose(const Rotation& outer, const Rotation& inner);  // outer * inner
// R v, and R^T v (the inverse turn).
Rotation transpose(const Rotation& r);
std::array<double, 3> turn(const Rotation& r, const std::array<double, 3>& v);
std::array<double, 3> turn_back(const Rotation& r, const std::array<double, 3>& v);

// R S R^T of a symmetric tensor in NodeStore order (2D: xx, zz, xz, out-of-plane, the last one
// unchanged; 3D: xx, yy, zz, yz, xz, xy).
std::array<double, 6> rotate_tensor(const Rotation& r, const std::array<double, 6>& s, int dim);

// Why `r` is not a proper rotation of a dim-D scene (not orthonormal to 1e-9, a reflection, a 2D
// matrix that moves the out-of-plane direction, a non-finite entry); nothing when it is one.
std::optional<std::string> rotation_problem(const Rotation& r, int dim);

// The unit vector along v (the first dim components); nothing for a zero or non-finite one.
std::optional<std::array<double, 3>> unit_vector(const std::array<double, 3>& v, int dim);

// The coordinate axis a unit normal lies along, exactly (one component +-1, the others 0), with
// its sign; nothing for an oblique normal.
struct AlignedAxis {
    int axis;
    int sign;
};
std::optional<AlignedAxis> aligned_axis(const std::array<double, 3>& normal, int dim);

}  // namespace gpa
