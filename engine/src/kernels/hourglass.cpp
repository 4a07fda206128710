#include "gpa/engine/hourglass.hpp"

#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/LU>

#include "gpa/engine/kernels.hpp"

namespace gpa {

template <int D>
HourglassFields<D> hourglass_fields(NodeStore& nodes, double lattice_plastic_strain, double* power) {
    HourglassFields<D> f;
    for (int c = 0; c < D; ++c) {
        f.position[c] = nodes.position[c].data();
        f.velocity[c] = nodes.velocity[c].data();
        f.force[c] = nodes.force[c].data();
    }
    f.size_weight = nodes.size_weight.data();
    f.mass = nodes.mass.data();
    f.sound_speed = nodes.sound_speed.data();
    f.smallest_h = nodes.smallest_h.data();
    f.connectivity = nodes.connectivity.data();
    f.body = nodes.body.data();
    f.plastic_strain = nodes.plastic_strain.data();
    f.lattice_plastic_strain = lattice_plastic_strain;
    f.power = power;
    return f;
}

template <int D>
HourglassFields<D> hourglass_fields(NodeStore& nodes, double lattice_plastic_strain, double* power, double stiffness,
                                    double* stiffness_power) {
    HourglassFields<D> f = hourglass_fields<D>(nodes, lattice_plastic_strain, power);
    if (stiffness > 0.0) {
        f.stiffness = stiffness;
        for (int c = 0; c < D; ++c) f.initial_position[c] = nodes.initial_position[c].data();
        f.initial_diameter = nodes.initial_diameter.data();
        f.stiffness_power = stiffness_power;
    }
    return f;
}

template <int D>
HourglassPower hourglass_centre(std::span<const NodeIndex> row, std::size_t i, const HourglassFields<D>& f,
                                std::size_t real_count, double coefficient) {
    const auto load = [](const std::array<const double*, D>& field, std::size_t k) {
        Vec<D> v;
        for (int c = 0; c < D; ++c) v[c] = field[c][k];
        return v;
    };
    HourglassPower out;
    if (i >= real_count) return out;
    // The kept fits say 0 for a centre without control (see KeptFit), so that the booking pass
    // needs no array cleared every step.
    const auto no_kept_fit = [&](const typename HourglassFields<D>::KeptFit& kept) {
        if (kept.scale && !f.use_kept_fits) kept.scale[i] = 0.0;
    };
    if (f.connectivity[i] != Connectivity::Fixed && !(f.plastic_strain[i] < f.lattice_plastic_strain)) {
        no_kept_fit(f.damping_fit);
        no_kept_fit(f.stiffness_fit);
        return out;
    }
    const auto controlled_pair = [&](NodeIndex j) { return controlled_hourglass_pair(f, i, j, real_count); };
    // The stiffness form acts on pairs of two fixed nodes: the lattice pairs, whose initial offsets
    // are the lattice's.
    const auto stiff_pair = [&](NodeIndex j) { return controlled_pair(j) && f.connectivity[j] == Connectivity::Fixed; };
    const Vec<D> x_i = load(f.position, i), v_i = load(f.velocity, i);
    const bool other_velocity = f.power_velocity[0] != nullptr;
    const bool scatter = f.force[0] != nullptr;
    const Vec<D> w_i = other_velocity ? load(f.power_velocity, i) : Vec<D>::Zero().eval();
    const auto power_of = [&](NodeIndex j, const Vec<D>& force_on_j, const Vec<D>& dv) {
        return force_on_j.dot(other_velocity ? (load(f.power_velocity, j) - w_i).eval() : dv);
    };
    Vec<D> on_centre = Vec<D>::Zero();
    // A neighbourhood that gives no fit in some direction (a single row or column of nodes)
    // has no affine reference to measure against: no control there.
    const auto invert = [](const HourglassFit<D>& fit, Mat<D>& inverse) {
        bool invertible = false;
        double determinant = 0.0;
        // The determinant's scale, trace^D, multiplied out: std::pow(trace, 3) is a call to libm's
        // pow at every centre of a 3D step.
        const double trace = fit.moment.trace();
        double scale = trace;
        for (int k = 1; k < D; ++k) scale *= trace;
        fit.moment.computeInverseAndDetWithCheck(inverse, determinant, invertible, 1e-12 * scale);
        return invertible && fit.weight > 0.0;
    };
    // The controlled pairs of the row with their offsets and weights, found once for the fit and
    // used again for the forces: a buffer per thread, reused from centre to centre and sized for
    // the row before the fit's loop, which then calls nothing (a push_back's possible reallocation
    // made the compiler keep the fit's sums in memory, a store and a load per sum and pair).
    struct Pair {
        NodeIndex j;
        Vec<D> offset;  // r = x_j - x_i (damping) or dX = X_j - X_i (stiffness)
        double weight;  // w = W_j / r^2 (damping) or 1 / |dX|^2 (stiffness)
    };
    thread_local std::vector<Pair> buffer;
    if (buffer.size() < row.size()) buffer.resize(row.size());
    Pair* const pairs = buffer.data();
    std::size_t count = 0;
    const auto keep = [&](const typename HourglassFields<D>::KeptFit& kept, double scale, const Mat<D>& matrix) {
        if (!kept.scale) return;
        kept.scale[i] = scale;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < D; ++b) kept.matrix[a * D + b][i] = matrix(a, b);
        }
    };
    const auto kept_matrix = [&](const typename HourglassFields<D>::KeptFit& kept) {
        Mat<D> m;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < D; ++b) m(a, b) = kept.matrix[a * D + b][i];
        }
        return m;
    };
    if (coefficient > 0.0 && f.use_kept_fits) {
        // The force pass's fit: its forces again, pair by pair as in pass 2 below, for their power.
        const KeptDampingPower<D> kept(f, i, real_count, coefficient);
        if (kept.active()) {
            for (NodeIndex j : row) out.damping += kept.term(f, j, load(f.position, j) - x_i, real_count);
        }
    } else if (coefficient > 0.0) {
        // Pass 1: the weighted least-squares velocity gradient of the lattice pairs.
        HourglassFit<D> fit;
        count = 0;
        for (NodeIndex j : row) {
            if (!controlled_pair(j)) continue;
            const Vec<D> r = load(f.position, j) - x_i;
            const double w = hourglass_pair_weight(f.size_weight[j], r.squaredNorm());
            accumulate_hourglass_fit<D>(r, load(f.velocity, j) - v_i, w, fit);
            pairs[count++] = {j, r, w};
        }
        Mat<D> inverse;
        no_kept_fit(f.damping_fit);
        if (invert(fit, inverse)) {
            const Mat<D> fitted_gradient = fit.difference * inverse;
            const double kappa = hourglass_damping(coefficient, f.mass[i], f.sound_speed[i], f.smallest_h[i]) / fit.weight;
            keep(f.damping_fit, kappa, fitted_gradient);
            // Pass 2: F_j = - kappa w_j e_ij on the neighbour, the reaction on the centre.
            for (std::size_t k = 0; k < count; ++k) {
                const Pair& p = pairs[k];
                const Vec<D> dv = load(f.velocity, p.j) - v_i;
                const Vec<D> force_on_j = (-kappa * p.weight) * hourglass_velocity_error<D>(fitted_gradient, p.offset, dv);
                if (scatter) {
                    for (int c = 0; c < D; ++c) f.force[c][p.j] += force_on_j[c];
                }
                on_centre -= force_on_j;
                out.damping += power_of(p.j, force_on_j, dv);
            }
        }
    }
    if (f.stiffness > 0.0 && f.connectivity[i] == Connectivity::Fixed && f.use_kept_fits) {
        const double k = f.stiffness_fit.scale[i];
        if (k != 0.0) {
            const Vec<D> x0_i = load(f.initial_position, i);
            const Mat<D> fitted_map = kept_matrix(f.stiffness_fit);
            for (NodeIndex j : row) {
                if (!stiff_pair(j)) continue;
                const Vec<D> initial = load(f.initial_position, j) - x0_i;
                const double w = hourglass_pair_weight(1.0, initial.squaredNorm());
                const Vec<D> force_on_j = (-k * w) * hourglass_displacement_error<D>(fitted_map, initial, load(f.position, j) - x_i);
                out.stiffness += power_of(j, force_on_j, load(f.velocity, j) - v_i);
            }
        }
    } else if (f.stiffness > 0.0 && f.connectivity[i] == Connectivity::Fixed) {
        // The stiffness form (kernels.hpp, hourglass_stiffness): the affine map of the initial
        // lattice pairs that fits their current offsets best, then forces against the rest.
        const Vec<D> x0_i = load(f.initial_position, i);
        HourglassFit<D> fit;
        count = 0;
        for (NodeIndex j : row) {
            if (!stiff_pair(j)) continue;
            const Vec<D> initial = load(f.initial_position, j) - x0_i;
            const double w = hourglass_pair_weight(1.0, initial.squaredNorm());
            accumulate_hourglass_fit<D>(initial, load(f.position, j) - x_i, w, fit);
            pairs[count++] = {j, initial, w};
        }
        Mat<D> inverse;
        no_kept_fit(f.stiffness_fit);
        if (invert(fit, inverse)) {
            const Mat<D> fitted_map = fit.difference * inverse;
            const double k = hourglass_stiffness(f.stiffness, f.mass[i], f.sound_speed[i], f.initial_diameter[i]) / fit.weight;
            keep(f.stiffness_fit, k, fitted_map);
            for (std::size_t e = 0; e < count; ++e) {
                const Pair& p = pairs[e];
                const Vec<D> force_on_j = (-k * p.weight) *
                                          hourglass_displacement_error<D>(fitted_map, p.offset, load(f.position, p.j) - x_i);
                if (scatter) {
                    for (int c = 0; c < D; ++c) f.force[c][p.j] += force_on_j[c];
                }
                on_centre -= force_on_j;
                out.stiffness += power_of(p.j, force_on_j, load(f.velocity, p.j) - v_i);
            }
        }
    }
    if (scatter) {
        for (int c = 0; c < D; ++c) f.force[c][i] += on_centre[c];
    }
    return out;
}

template <int D>
void apply_hourglass_control(const CompressedRows& lists, const ScatterPlan& plan, const HourglassFields<D>& f,
                             std::size_t real_count, double coefficient) {
    const bool with_stiffness = f.stiffness > 0.0;
    for (std::size_t colour = 0; colour < plan.colours(); ++colour) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(plan.colour_offsets[colour], plan.colour_offsets[colour + 1], 1),
                          [&](const tbb::blocked_range<std::size_t>& groups) {
                              for (std::size_t g = groups.begin(); g != groups.end(); ++g) {
                                  for (NodeIndex i : plan.group(g)) {
                                      const HourglassPower p = hourglass_centre<D>(lists.row(i), i, f, real_count, coefficient);
                                      f.power[i] = p.damping;
                                      if (with_stiffness) f.stiffness_power[i] = p.stiffness;
                                  }
                              }
                          });
    }
}

template HourglassFields<2> hourglass_fields<2>(NodeStore&, double, double*);
template HourglassFields<3> hourglass_fields<3>(NodeStore&, double, double*);
template HourglassFields<2> hourglass_fields<2>(NodeStore&, double, double*, double, double*);
template HourglassFields<3> hourglass_fields<3>(NodeStore&, double, double*, double, double*);
template void apply_hourglass_control<2>(const CompressedRows&, const ScatterPlan&, const HourglassFields<2>&, std::size_t, double);
template void apply_hourglass_control<3>(const CompressedRows&, const ScatterPlan&, const HourglassFields<3>&, std::size_t, double);
template HourglassPower hourglass_centre<2>(std::span<const NodeIndex>, std::size_t, const HourglassFields<2>&, std::size_t, double);
template HourglassPower hourglass_centre<3>(std::span<const NodeIndex>, std::size_t, const HourglassFields<3>&, std::size_t, double);

}  // namespace gpa
