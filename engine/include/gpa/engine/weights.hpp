#pragma once
// Distance weights R_ij of the method (spec section 2 and 8). The normalisation by the geometry
// factors alpha removes any constant factor of R, so only R's shape matters.

#include <cmath>

namespace gpa {

// The distance weight of every pair (Eq. 1b or 62-65). Fixed-connectivity (lattice) pairs use the
// same function, at v = r/h but never beyond lattice_weight_reach_for (below), so that a lattice
// pair keeps a weight however far apart its nodes move (spec section 2, "[spec] Lattice weights"; the paper's
// Eq. 1a has R = 1).
enum class WeightKind {
    Gpa,     // R = 1 - v/2 (Eq. 1b)
    SphNsf,  // R = -r W'(r, h) of a cubic-spline kernel (Eq. 62-65)
};

// v at which a lattice pair's weight stops falling: R(1.8) = 0.1 for the GPA weight.
inline constexpr double lattice_weight_reach = 1.8;

// The v at which lattice pairs stop falling in a scene of influence distance `a` and dimension
// `dim` (PairFields::lattice_reach): lattice_weight_reach, or, where the default stencil's
// farthest pair on the undeformed lattice lies beyond it and still within the support (v < 2),
// that pair's v: in 3D at a = 1.3 the stencil of every lattice node within 2 a d0 reaches
// sqrt(6) d0, v = 1.884. Below that v every lattice pair of the undeformed lattice weighs what a
// variable pair at its distance weighs, so that forces balance across a front between fixed and
// variable nodes (docs/connectivity.md, "The front in 3D"); with the floor at 1.8 the stencil's
// outer shell weighed R(1.8), 2.8 times R(1.884) of SPH-NSF, and a uniform pressure pushed the
// nodes next to a front by 1.4 % of P d^2. The default stencil (bodies.cpp): the box of 8 / 26,
// and beyond it, for a > 1, every lattice node closer than 2 a d0 (unit spacing d0 here).
// (Made for every phase's fields: integer offsets, one square root.)
inline double lattice_weight_reach_for(double a, int dim) {
    const double support2 = 4.0 * a * a;  // v < 2: r^2 < (2 a d0)^2
    int farthest2 = 0;
    const int box = a > 1.0 ? 3 : 1;  // 2 a <= 3 (a <= max_influence_distance)
    for (int i = 0; i <= box; ++i) {
        for (int j = 0; j <= box; ++j) {
            for (int k = 0; k <= (dim == 3 ? box : 0); ++k) {
                const int r2 = i * i + j * j + k * k;
                const bool in_box = i <= 1 && j <= 1 && k <= 1;
                const bool within_reach = a > 1.0 && r2 < support2;
                if (r2 > farthest2 && (in_box || within_reach) && r2 < support2) farthest2 = r2;
            }
        }
    }
    const double farthest = std::sqrt(static_cast<double>(farthest2)) / a;
    return farthest > lattice_weight_reach ? farthest : lattice_weight_reach;
}

// The weights below take a double, or two of them at once as a GCC vector (fields.hpp,
// PairFields::two_pairs), for which the comparisons give masks and ?: picks lane by lane; each
// lane gets the same operations, so the same bits, as the double alone.

// Eq. 1b: R = 1 - v/2 for v = r/h in [0, 2), zero beyond (a neighbour at exactly 2h has weight 0).
struct GpaWeight {
    static constexpr WeightKind kind = WeightKind::Gpa;
    template <class T>
    static T value(T v) {
        return v < 2.0 ? T(1.0 - 0.5 * v) : T{};
    }
};

// Eq. 62-65: SPH with normalised smoothing functions is GPA with R = -r dW/dr. For the cubic
// spline W(q) ~ 1 - 3/2 q^2 + 3/4 q^3 (q < 1), 1/4 (2 - q)^3 (1 <= q < 2), q = r/h, this is
// R = 3 q^2 - 9/4 q^3 (q < 1) and R = 3/4 q (2 - q)^2 (1 <= q < 2), up to the kernel's constant.
struct SphNsfWeight {
    static constexpr WeightKind kind = WeightKind::SphNsf;
    template <class T>
    static T value(T q) {
        const T t = 2.0 - q;
        return q < 1.0 ? T(q * q * (3.0 - 2.25 * q)) : (q < 2.0 ? T(0.75 * q * t * t) : T{});
    }
};

// Calls f(weight tag) for a run-time weight kind, once, outside any inner loop.
template <class F>
decltype(auto) dispatch_weight(WeightKind kind, F&& f) {
    if (kind == WeightKind::SphNsf) return f(SphNsfWeight{});
    return f(GpaWeight{});
}

// The one neighbour rule used by the search, the brute-force check and every count:
// j is a neighbour of i when r_ij < 2 h_ij (spec section 2).
inline bool within_influence(double r_squared, double h) { return r_squared < 4.0 * h * h; }

// Eq. 2: h_ij = a (d_i + d_j) / 2.
// (Also on two pairs at once, T a GCC vector of diameters: fields.hpp, neighbours.cpp.)
template <class T>
inline T pair_smoothing_length(double influence_distance, T d_i, T d_j) {
    return influence_distance * 0.5 * (d_i + d_j);
}

// The range of the dimensionless influence distance a the method is defined for (spec section 2).
inline constexpr double min_influence_distance = 0.8;
inline constexpr double max_influence_distance = 1.5;

// Throws InputError when a is outside [0.8, 1.5] or not finite.
void check_influence_distance(double influence_distance);

// The influence distance a, checked once: a value of this type is within the method's range, so
// the code that is handed one every step (the field views, the neighbour search) checks nothing.
// A run makes it once from its validated scene; the overloads that take a plain double (for
// programs that call the kernels directly) make one, and so check, on every call.
class InfluenceDistance {
public:
    explicit InfluenceDistance(double a) : a_(a) { check_influence_distance(a); }
    double value() const { return a_; }

private:
    double a_;
};

}  // namespace gpa
