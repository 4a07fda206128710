#include "gpa/engine/orientation.hpp"

#include <cmath>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

bool is_identity(const Rotation& r) { return r == identity_rotation; }

Rotation rotation_about(const std::array<double, 3>& axis, double angle) {
    const auto n = unit_vector(axis, 3);
    if (!n) throw InputError(fmt::format("a rotation axis [{}, {}, {}] must be a finite, non-zero vector", axis[0], axis[1], axis[2]));
    if (!std::isfinite(angle)) throw InputError(fmt::format("a rotation angle must be finite, got {}", angle));
    // Rodrigues: R = cos t I + sin t [n]x + (1 - cos t) n n^T.
    const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
    const auto& [x, y, z] = *n;
    return {c + t * x * x,     t * x * y - s * z, t * x * z + s * y,
            t * x * y + s * z, c + t * y * y,     t * y * z - s * x,
            t * x * z - s * y, t * y * z + s * x, c + t * z * z};
}

Rotation rotation_in_plane(double angle) {
    if (!std::isfinite(angle)) throw InputError(fmt::format("a rotation angle must be finite, got {}", angle));
    const double c = std::cos(angle), s = std::sin(angle);
    return {c, -s, 0, s, c, 0, 0, 0, 1};
}

Rotation compose(const Rotation& a, const Rotation& b) {
    Rotation out{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            double sum = 0.0;
            for (int k = 0; k < 3; ++k) sum += a[3 * r + k] * b[3 * k + c];
            out[3 * r + c] = sum;
        }
    }
    return out;
}

Rotation transpose(const Rotation& r) { return {r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]}; }

std::array<double, 3> turn(const Rotation& r, const std::array<double, 3>& v) {
    return {r[0] * v[0] + r[1] * v[1] + r[2] * v[2], r[3] * v[0] + r[4] * v[1] + r[5] * v[2],
            r[6] * v[0] + r[7] * v[1] + r[8] * v[2]};
}

std::array<double, 3> turn_back(const Rotation& r, const std::array<double, 3>& v) { return turn(transpose(r), v); }

std::array<double, 6> rotate_tensor(const Rotation& r, const std::array<double, 6>& s, int dim) {
    // The full 3x3 tensor in engine components (2D: components 0, 1 = x, z; the out-of-plane entry
    // stays where it is, the 2D rotation leaving that direction alone).
    double t[3][3]{};
    if (dim == 2) {
        t[0][0] = s[0], t[1][1] = s[1], t[0][1] = t[1][0] = s[2];
    } else {
        t[0][0] = s[0], t[1][1] = s[1], t[2][2] = s[2];
        t[1][2] = t[2][1] = s[3], t[0][2] = t[2][0] = s[4], t[0][1] = t[1][0] = s[5];
    }
    const int n = dim;
    double rt[3][3]{}, out[3][3]{};
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) rt[i][j] += r[3 * i + k] * t[k][j];
        }
    }
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) out[i][j] += rt[i][k] * r[3 * j + k];
        }
    }
    if (dim == 2) return {out[0][0], out[1][1], 0.5 * (out[0][1] + out[1][0]), s[3], 0.0, 0.0};
    return {out[0][0], out[1][1], out[2][2], 0.5 * (out[1][2] + out[2][1]), 0.5 * (out[0][2] + out[2][0]),
            0.5 * (out[0][1] + out[1][0])};
}

std::optional<std::string> rotation_problem(const Rotation& r, int dim) {
    for (const double v : r) {
        if (!std::isfinite(v)) return "it has a non-finite entry";
    }
    if (dim == 2 && !(r[2] == 0.0 && r[5] == 0.0 && r[6] == 0.0 && r[7] == 0.0 && r[8] == 1.0)) {
        return "a plane-strain rotation turns the (x, z) plane only";
    }
    const Rotation p = compose(r, transpose(r));
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            if (std::abs(p[3 * i + j] - (i == j ? 1.0 : 0.0)) > 1e-9) return "its rows are not orthonormal";
        }
    }
    const double det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
    if (det < 0.0) return "it is a reflection (determinant -1), not a rotation";
    return std::nullopt;
}

std::optional<std::array<double, 3>> unit_vector(const std::array<double, 3>& v, int dim) {
    double q = 0.0;
    for (int c = 0; c < dim; ++c) {
        if (!std::isfinite(v[c])) return std::nullopt;
        q += v[c] * v[c];
    }
    if (!(q > 0.0) || !std::isfinite(q)) return std::nullopt;
    const double length = std::sqrt(q);
    std::array<double, 3> out{0, 0, 0};
    for (int c = 0; c < dim; ++c) out[c] = v[c] / length;
    return out;
}

std::optional<AlignedAxis> aligned_axis(const std::array<double, 3>& n, int dim) {
    int found = -1;
    for (int c = 0; c < dim; ++c) {
        if (n[c] == 0.0) continue;
        if (found >= 0 || std::abs(n[c]) != 1.0) return std::nullopt;
        found = c;
    }
    if (found < 0) return std::nullopt;
    return AlignedAxis{found, n[found] > 0.0 ? +1 : -1};
}

}  // namespace gpa
