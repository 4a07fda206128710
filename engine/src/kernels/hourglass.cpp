#include "gpa/engine/hourglass.hpp"

#include <type_traits>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Cholesky>
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

namespace {

template <int D>
using CurvatureMatrix = Eigen::Matrix<double, D, curvature_terms<D>>;

// Lfit and Cfit of the quadratic fit (kernels.hpp, QuadraticHourglassFit) from the Cholesky factor
// of its moment. False where the pairs do not fix the second derivatives (fewer than D + D (D + 1)
// / 2 of them, or all near one line or conic: a pivot below 1e-12 of the largest): the affine fit
// then serves.
template <int D>
bool solve_quadratic_fit(const QuadraticHourglassFit<D>& fit, Mat<D>& gradient, CurvatureMatrix<D>& curvature) {
    constexpr int P = QuadraticHourglassFit<D>::terms;
    const Eigen::LLT<Eigen::Matrix<double, P, P>> factor(fit.moment);
    if (factor.info() != Eigen::Success) return false;
    const auto pivots = factor.matrixLLT().diagonal().cwiseAbs2();
    if (!(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) return false;
    const Eigen::Matrix<double, P, D> solution = factor.solve(fit.difference.transpose());
    gradient = solution.template topRows<D>().transpose();
    curvature = solution.template bottomRows<curvature_terms<D>>().transpose();
    return true;
}

// The quadratic fit's sums over a row by two matrix products, the pairs' bases phi = (r, q(r)),
// weighted bases and differences gathered first: summed pair by pair, the 9-by-9 moment of 3D
// does not fit the registers, and each of its 45 terms became a load and a store per pair. One
// per thread, reused from centre to centre (no allocation once it holds the longest row). A second
// difference per pair (add_both: the displacement since the relaxing reference) shares the basis,
// so that the damping's and the relaxed stiffness's fits take one moment and one factor.
template <int D>
class QuadraticSums {
public:
    static constexpr int P = QuadraticHourglassFit<D>::terms;
    using SecondDifference = Eigen::Matrix<double, D, P>;
    static QuadraticSums& of_this_thread() {
        thread_local QuadraticSums sums;
        return sums;
    }
    void start(std::size_t pairs) {
        if (static_cast<std::size_t>(basis_.rows()) < pairs) {
            basis_.resize(static_cast<Eigen::Index>(pairs), P);
            weighted_.resize(static_cast<Eigen::Index>(pairs), P);
            difference_.resize(static_cast<Eigen::Index>(pairs), 2 * D);
        }
        count_ = 0;
        weight_ = 0.0;
    }
    void add(const Vec<D>& r, const Vec<D>& difference, double w, double inverse_h) {
        const Eigen::Index k = count_++;
        basis_.row(k).template head<D>() = r.transpose();
        basis_.row(k).template tail<curvature_terms<D>>() = curvature_basis<D>(r, inverse_h).transpose();
        weighted_.row(k) = w * basis_.row(k);
        difference_.row(k).template head<D>() = difference.transpose();
        weight_ += w;
    }
    void add_both(const Vec<D>& r, const Vec<D>& difference, const Vec<D>& second, double w, double inverse_h) {
        difference_.row(count_).template tail<D>() = second.transpose();
        add(r, difference, w, inverse_h);
    }
    // The products as dot products of the gathered columns, the moment's upper triangle mirrored:
    // for rows of a few dozen pairs Eigen's general matrix product spent a fifth of the step
    // packing its operands.
    QuadraticHourglassFit<D> sums() const {
        QuadraticHourglassFit<D> fit;
        for (int k = 0; k < P; ++k) {
            const auto weighted = weighted_.col(k).head(count_);
            for (int l = 0; l <= k; ++l) fit.moment(l, k) = fit.moment(k, l) = basis_.col(l).head(count_).dot(weighted);
            for (int a = 0; a < D; ++a) fit.difference(a, k) = difference_.col(a).head(count_).dot(weighted);
        }
        fit.weight = weight_;
        return fit;
    }
    // The sums of the second differences (add_both), beside sums().
    SecondDifference second_sums() const {
        SecondDifference out;
        for (int k = 0; k < P; ++k) {
            const auto weighted = weighted_.col(k).head(count_);
            for (int a = 0; a < D; ++a) out(a, k) = difference_.col(D + a).head(count_).dot(weighted);
        }
        return out;
    }

private:
    Eigen::Matrix<double, Eigen::Dynamic, P> basis_, weighted_;
    Eigen::Matrix<double, Eigen::Dynamic, 2 * D> difference_;
    Eigen::Index count_ = 0;
    double weight_ = 0.0;
};

// A centre's fit, for the damping (r -> dv) and the stiffness form (dX -> dx) alike: the affine
// map, with the second derivatives where the quadratic fit was asked for and the pairs fix them.
template <int D>
struct CentreFit {
    Mat<D> map;
    CurvatureMatrix<D> curvature;  // set where curved
    double weight = 0.0;  // sum_j w_j
    double inverse_h = 0.0;
    bool curved = false;
    bool found = false;  // false: no fit (too few pairs, or all on a line)

    // The part of a pair's difference the fit does not follow (kernels.hpp, e_ij), with the second
    // derivatives or without: the callers choose once per centre, so that the affine loop carries
    // neither a branch per pair nor the curvature's registers.
    template <bool Curved>
    Vec<D> error(const Vec<D>& offset, const Vec<D>& difference) const {
        if constexpr (Curved) {
            return difference - quadratic_fitted_velocity<D>(map, curvature, offset, inverse_h);
        } else {
            return hourglass_velocity_error<D>(map, offset, difference);
        }
    }
};

// Runs `walk` with the fit's curvature on or off as a constant; always off in the affine control
// (General false: see centre_control).
template <bool General, int D, class Walk>
void with_fit_kind(const CentreFit<D>& fit, Walk&& walk) {
    if constexpr (General) {
        if (fit.curved) {
            walk(std::true_type{});
            return;
        }
    }
    walk(std::false_type{});
}

// The affine fit from the sums of pass 1; `invert` as in centre_control.
template <int D, class Invert>
CentreFit<D> affine_centre_fit(const HourglassFit<D>& affine, const Invert& invert) {
    CentreFit<D> fit;
    Mat<D> inverse;
    fit.found = invert(affine, inverse);
    if (fit.found) fit.map = affine.difference * inverse;
    fit.weight = affine.weight;
    return fit;
}

// The quadratic fit from its sums where the pairs fix the second derivatives, else the affine fit
// from the same sums' affine part.
template <int D, class Invert>
CentreFit<D> quadratic_centre_fit(const QuadraticHourglassFit<D>& sums, double inverse_h, const Invert& invert) {
    CentreFit<D> fit;
    fit.curved = solve_quadratic_fit(sums, fit.map, fit.curvature);
    if (!fit.curved) return affine_centre_fit<D>(sums.affine_part(), invert);
    fit.inverse_h = inverse_h;
    fit.weight = sums.weight;
    fit.found = fit.weight > 0.0;
    return fit;
}

// Both fits of one basis (QuadraticSums::add_both): the quadratic ones from one factor of the
// moment where the pairs fix the second derivatives, else the affine ones from its affine part.
template <int D, class Invert>
std::array<CentreFit<D>, 2> quadratic_centre_fits(const QuadraticHourglassFit<D>& sums,
                                                  const typename QuadraticSums<D>::SecondDifference& second, double inverse_h,
                                                  const Invert& invert) {
    constexpr int P = QuadraticHourglassFit<D>::terms;
    QuadraticHourglassFit<D> other = sums;
    other.difference = second;
    std::array<CentreFit<D>, 2> fits;
    const Eigen::LLT<Eigen::Matrix<double, P, P>> factor(sums.moment);
    const auto pivots = factor.matrixLLT().diagonal().cwiseAbs2();
    if (factor.info() != Eigen::Success || !(pivots.minCoeff() > 1e-12 * pivots.maxCoeff())) {
        fits[0] = affine_centre_fit<D>(sums.affine_part(), invert);
        fits[1] = affine_centre_fit<D>(other.affine_part(), invert);
        return fits;
    }
    Eigen::Matrix<double, P, 2 * D> right;
    right.template leftCols<D>() = sums.difference.transpose();
    right.template rightCols<D>() = second.transpose();
    const Eigen::Matrix<double, P, 2 * D> solution = factor.solve(right);
    for (int k = 0; k < 2; ++k) {
        CentreFit<D>& fit = fits[k];
        fit.map = solution.template block<D, D>(0, k * D).transpose();
        fit.curvature = solution.template block<curvature_terms<D>, D>(D, k * D).transpose();
        fit.curved = true;
        fit.inverse_h = inverse_h;
        fit.weight = sums.weight;
        fit.found = fit.weight > 0.0;
    }
    return fits;
}

// One centre of the control (hourglass.hpp, hourglass_centre). `General` false: the affine fit
// and the stiffness on fixed centres only, HourglassFields::quadratic and reference_position
// ignored; that instantiation is the control of the defaults, kept free of the options' state
// and branches, which slowed it when compiled in (docs/performance.md, "Figures that were kept in
// code comments"). `General` true: the quadratic fit when asked for, and the stiffness on flowing
// centres against their relaxing reference.
template <int D, bool General>
HourglassPower centre_control(std::span<const NodeIndex> row, std::size_t i, const HourglassFields<D>& f,
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
    // The quadratic fit's Cfit, zero where the affine fit served (KeptFit::curvature).
    const auto keep_curvature = [&](const typename HourglassFields<D>::KeptFit& kept, const CentreFit<D>& fit) {
        if (!General || !kept.curvature[0]) return;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < curvature_terms<D>; ++b) {
                kept.curvature[a * curvature_terms<D> + b][i] = fit.curved ? fit.curvature(a, b) : 0.0;
            }
        }
    };
    const auto kept_matrix = [&](const typename HourglassFields<D>::KeptFit& kept) {
        Mat<D> m;
        for (int a = 0; a < D; ++a) {
            for (int b = 0; b < D; ++b) m(a, b) = kept.matrix[a * D + b][i];
        }
        return m;
    };
    // The stiffness form: a fixed centre against the initial lattice (its lattice pairs, weights
    // 1 / |dX|^2, d0); a controlled variable centre, with a relaxing reference, against that
    // reference over all its controlled pairs (weights W_j / r^2 as the damping's).
    const bool fixed_centre = f.connectivity[i] == Connectivity::Fixed;
    const bool relaxed_centre = General && !fixed_centre && f.reference_position[0] != nullptr;
    const bool stiff_centre = f.stiffness > 0.0 && (fixed_centre || relaxed_centre);
    // A relaxed centre's displacement since its reference, relative to the centre's:
    // du_j = (x_j - x_i) - (X_j - X_i) for r = x_j - x_i.
    const Vec<D> reference_i = relaxed_centre ? load(f.reference_position, i) : Vec<D>::Zero().eval();
    const auto relaxed_displacement = [&](NodeIndex j, const Vec<D>& r) {
        return (r - (load(f.reference_position, j) - reference_i)).eval();
    };
    // The relaxed stiffness's fit when the damping's quadratic fit made it from the same moment.
    CentreFit<D> shared_stiffness_fit;
    bool stiffness_fit_shared = false;
    bool stiffness_done = false;  // its forces went with the damping's (pass 2)
    if (coefficient > 0.0 && f.use_kept_fits) {
        // The force pass's fit: its forces again, pair by pair as in pass 2 below, for their power.
        const auto kept_power = [&](auto curved) {
            const KeptDampingPower<D, decltype(curved)::value> kept(f, i, real_count, coefficient);
            if (kept.active()) {
                for (NodeIndex j : row) out.damping += kept.term(f, j, load(f.position, j) - x_i, real_count);
            }
        };
        if (General && f.quadratic) {
            kept_power(std::bool_constant<General>{});
        } else {
            kept_power(std::false_type{});
        }
    } else if (coefficient > 0.0) {
        // Pass 1: the weighted least-squares velocity gradient of the lattice pairs (with the
        // second derivatives too for the quadratic fit: kernels.hpp, QuadraticHourglassFit).
        CentreFit<D> fitted;
        count = 0;
        if (General && f.quadratic) {
            const double inverse_h = 1.0 / f.smallest_h[i];
            QuadraticSums<D>& quadratic_sums = QuadraticSums<D>::of_this_thread();
            quadratic_sums.start(row.size());
            // A relaxed stiff centre's fit has the same pairs, weights and basis (the stiffness
            // section below): its displacements go into the same sums.
            stiffness_fit_shared = relaxed_centre && stiff_centre;
            for (NodeIndex j : row) {
                if (!controlled_pair(j)) continue;
                const Vec<D> r = load(f.position, j) - x_i;
                const double w = hourglass_pair_weight(f.size_weight[j], r.squaredNorm());
                if (stiffness_fit_shared) {
                    quadratic_sums.add_both(r, load(f.velocity, j) - v_i, relaxed_displacement(j, r), w, inverse_h);
                } else {
                    quadratic_sums.add(r, load(f.velocity, j) - v_i, w, inverse_h);
                }
                pairs[count++] = {j, r, w};
            }
            if (stiffness_fit_shared) {
                const auto both =
                    quadratic_centre_fits<D>(quadratic_sums.sums(), quadratic_sums.second_sums(), inverse_h, invert);
                fitted = both[0];
                shared_stiffness_fit = both[1];
            } else {
                fitted = quadratic_centre_fit<D>(quadratic_sums.sums(), inverse_h, invert);
            }
        } else {
            HourglassFit<D> fit;
            for (NodeIndex j : row) {
                if (!controlled_pair(j)) continue;
                const Vec<D> r = load(f.position, j) - x_i;
                const double w = hourglass_pair_weight(f.size_weight[j], r.squaredNorm());
                accumulate_hourglass_fit<D>(r, load(f.velocity, j) - v_i, w, fit);
                pairs[count++] = {j, r, w};
            }
            fitted = affine_centre_fit<D>(fit, invert);
        }
        no_kept_fit(f.damping_fit);
        if (fitted.found) {
            const double kappa = hourglass_damping(coefficient, f.mass[i], f.sound_speed[i], f.smallest_h[i]) / fitted.weight;
            keep(f.damping_fit, kappa, fitted.map);
            keep_curvature(f.damping_fit, fitted);
            // The relaxed stiffness of the shared fit (its forces -k w_j e_ij of du_j) in the same walk.
            double stiffness_scale = 0.0;
            if constexpr (General) {
                if (stiffness_fit_shared && shared_stiffness_fit.found) {
                    stiffness_scale = hourglass_stiffness(f.stiffness, f.mass[i], f.sound_speed[i], f.initial_diameter[i]) /
                                      shared_stiffness_fit.weight;
                    keep(f.stiffness_fit, stiffness_scale, shared_stiffness_fit.map);
                    keep_curvature(f.stiffness_fit, shared_stiffness_fit);
                    stiffness_done = true;
                }
            }
            // Pass 2: F_j = - kappa w_j e_ij on the neighbour, the reaction on the centre.
            with_fit_kind<General>(fitted, [&](auto curved) {
                constexpr bool curved_fit = decltype(curved)::value;
                for (std::size_t k = 0; k < count; ++k) {
                    const Pair& p = pairs[k];
                    const Vec<D> dv = load(f.velocity, p.j) - v_i;
                    const Vec<D> force_on_j = (-kappa * p.weight) * fitted.template error<curved_fit>(p.offset, dv);
                    Vec<D> total = force_on_j;
                    if constexpr (General) {
                        if (stiffness_done) {
                            const Vec<D> stiffness_on_j =
                                (-stiffness_scale * p.weight) *
                                shared_stiffness_fit.template error<curved_fit>(p.offset, relaxed_displacement(p.j, p.offset));
                            out.stiffness += power_of(p.j, stiffness_on_j, dv);
                            total += stiffness_on_j;
                        }
                    }
                    if (scatter) {
                        for (int c = 0; c < D; ++c) f.force[c][p.j] += total[c];
                    }
                    on_centre -= total;
                    out.damping += power_of(p.j, force_on_j, dv);
                }
            });
        }
    }
    // The stiffness's pairs: a fixed centre's offset is its lattice pair's initial one, dX_j =
    // X0_j - X0_i, fitted to the current offset x_j - x_i (weight 1 / |dX|^2); a relaxed centre's
    // offset is the current one, r_j, fitted to its displacement since the reference du_j (weight
    // W_j / r^2, the damping's pairs and basis). False when the pair takes no part.
    const Vec<D> x0_i = stiff_centre && !relaxed_centre ? load(f.initial_position, i) : Vec<D>::Zero().eval();
    const auto stiffness_pair = [&](NodeIndex j, Vec<D>& offset, double& w) {
        if (!relaxed_centre) {
            if (!stiff_pair(j)) return false;
            offset = load(f.initial_position, j) - x0_i;
            w = hourglass_pair_weight(1.0, offset.squaredNorm());
            return true;
        }
        if (!controlled_pair(j)) return false;
        offset = load(f.position, j) - x_i;
        w = hourglass_pair_weight(f.size_weight[j], offset.squaredNorm());
        return true;
    };
    const auto stiffness_difference = [&](NodeIndex j, const Vec<D>& offset) {
        return relaxed_centre ? relaxed_displacement(j, offset) : (load(f.position, j) - x_i).eval();
    };
    // A relaxed centre with the quadratic fit: its fit takes the displacement's second derivatives
    // too (kernels.hpp, QuadraticHourglassFit, with dv = du), so that a smoothly bending flow since
    // the reference stores nothing.
    const bool stiff_quadratic = stiff_centre && relaxed_centre && f.quadratic;
    const double stiff_inverse_h = stiff_quadratic ? 1.0 / f.smallest_h[i] : 0.0;
    if (stiff_centre && f.use_kept_fits) {
        const double k = f.stiffness_fit.scale[i];
        if (k != 0.0) {
            // The force pass's fit again (an affine one that served has a zero Cfit).
            CentreFit<D> kept;
            kept.map = kept_matrix(f.stiffness_fit);
            kept.curved = stiff_quadratic;
            kept.inverse_h = stiff_inverse_h;
            if (stiff_quadratic) {
                for (int a = 0; a < D; ++a) {
                    for (int b = 0; b < curvature_terms<D>; ++b) {
                        kept.curvature(a, b) = f.stiffness_fit.curvature[a * curvature_terms<D> + b][i];
                    }
                }
            }
            with_fit_kind<General>(kept, [&](auto curved) {
                for (NodeIndex j : row) {
                    Vec<D> offset;
                    double w = 0.0;
                    if (!stiffness_pair(j, offset, w)) continue;
                    const Vec<D> force_on_j =
                        (-k * w) * kept.template error<decltype(curved)::value>(offset, stiffness_difference(j, offset));
                    out.stiffness += power_of(j, force_on_j, load(f.velocity, j) - v_i);
                }
            });
        }
    } else if (stiff_centre && stiffness_fit_shared) {
        // Fitted with the damping and its forces added in the damping's walk.
        if (!stiffness_done) no_kept_fit(f.stiffness_fit);
    } else if (stiff_centre) {
        // The stiffness form (kernels.hpp, hourglass_stiffness): the map that fits the pairs'
        // differences best, then forces against the rest.
        CentreFit<D> fitted;
        {
            HourglassFit<D> fit;
            count = 0;
            QuadraticSums<D>* quadratic_sums = General && stiff_quadratic ? &QuadraticSums<D>::of_this_thread() : nullptr;
            if (quadratic_sums) quadratic_sums->start(row.size());
            for (NodeIndex j : row) {
                Vec<D> offset;
                double w = 0.0;
                if (!stiffness_pair(j, offset, w)) continue;
                if (quadratic_sums) {
                    quadratic_sums->add(offset, stiffness_difference(j, offset), w, stiff_inverse_h);
                } else {
                    accumulate_hourglass_fit<D>(offset, stiffness_difference(j, offset), w, fit);
                }
                pairs[count++] = {j, offset, w};
            }
            fitted = quadratic_sums ? quadratic_centre_fit<D>(quadratic_sums->sums(), stiff_inverse_h, invert)
                                    : affine_centre_fit<D>(fit, invert);
        }
        no_kept_fit(f.stiffness_fit);
        if (fitted.found) {
            const double k = hourglass_stiffness(f.stiffness, f.mass[i], f.sound_speed[i], f.initial_diameter[i]) / fitted.weight;
            keep(f.stiffness_fit, k, fitted.map);
            keep_curvature(f.stiffness_fit, fitted);
            with_fit_kind<General>(fitted, [&](auto curved) {
                for (std::size_t e = 0; e < count; ++e) {
                    const Pair& p = pairs[e];
                    const Vec<D> force_on_j =
                        (-k * p.weight) *
                        fitted.template error<decltype(curved)::value>(p.offset, stiffness_difference(p.j, p.offset));
                    if (scatter) {
                        for (int c = 0; c < D; ++c) f.force[c][p.j] += force_on_j[c];
                    }
                    on_centre -= force_on_j;
                    out.stiffness += power_of(p.j, force_on_j, load(f.velocity, p.j) - v_i);
                }
            });
        }
    }
    if (scatter) {
        for (int c = 0; c < D; ++c) f.force[c][i] += on_centre[c];
    }
    return out;
}

// The control's general form is needed: the quadratic fit, or a relaxing reference.
template <int D>
bool general_control(const HourglassFields<D>& f) {
    return f.quadratic || f.reference_position[0] != nullptr;
}

template <int D, bool General>
void control_all(const CompressedRows& lists, const ScatterPlan& plan, const HourglassFields<D>& f, std::size_t real_count,
                 double coefficient) {
    const bool with_stiffness = f.stiffness > 0.0;
    for (std::size_t colour = 0; colour < plan.colours(); ++colour) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(plan.colour_offsets[colour], plan.colour_offsets[colour + 1], 1),
                          [&](const tbb::blocked_range<std::size_t>& groups) {
                              for (std::size_t g = groups.begin(); g != groups.end(); ++g) {
                                  for (NodeIndex i : plan.group(g)) {
                                      const HourglassPower p =
                                          centre_control<D, General>(lists.row(i), i, f, real_count, coefficient);
                                      f.power[i] = p.damping;
                                      if (with_stiffness) f.stiffness_power[i] = p.stiffness;
                                  }
                              }
                          });
    }
}

}  // namespace

template <int D>
HourglassPower hourglass_centre(std::span<const NodeIndex> row, std::size_t i, const HourglassFields<D>& f,
                                std::size_t real_count, double coefficient) {
    return general_control(f) ? centre_control<D, true>(row, i, f, real_count, coefficient)
                              : centre_control<D, false>(row, i, f, real_count, coefficient);
}

template <int D>
void apply_hourglass_control(const CompressedRows& lists, const ScatterPlan& plan, const HourglassFields<D>& f,
                             std::size_t real_count, double coefficient) {
    // The form chosen once for the pass (centre_control).
    if (general_control(f)) {
        control_all<D, true>(lists, plan, f, real_count, coefficient);
    } else {
        control_all<D, false>(lists, plan, f, real_count, coefficient);
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
