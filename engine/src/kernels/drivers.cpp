#include "gpa/engine/drivers.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "gpa/engine/errors.hpp"

namespace gpa {

namespace {

constexpr std::size_t no_node = std::numeric_limits<std::size_t>::max();

// Centres per task of the row sweeps that are not coloured (gradient, stress power): a centre's row
// costs some 0.1-1 us, so 64 of them are tens of microseconds against about one of task overhead,
// and a scene of 10^3 nodes still gives every thread work. (Each centre writes only its own values,
// so the split does not change any result.)
constexpr std::size_t row_grain = 64;

void record_smallest(std::atomic<std::size_t>& slot, std::size_t i) {
    std::size_t seen = slot.load(std::memory_order_relaxed);
    while (i < seen && !slot.compare_exchange_weak(seen, i, std::memory_order_relaxed)) {
    }
}

// Every entry of a small fixed-size matrix finite, tested entry by entry without a branch (Eigen's
// allFinite compares (m - m) with itself through a function call per centre).
template <class M>
bool all_finite(const M& m) {
    bool finite = true;
    for (Eigen::Index k = 0; k < m.size(); ++k) finite &= std::isfinite(m.data()[k]);
    return finite;
}

template <int D>
Vec<D> load(const std::array<const double*, D>& field, std::size_t i) {
    Vec<D> v;
    for (int c = 0; c < D; ++c) v[c] = field[c][i];
    return v;
}

template <int D>
std::string describe(const PairFields<D>& p, std::size_t i) {
    const Vec<D> x = p.x(i);
    if constexpr (D == 2) {
        return fmt::format("node {} at (x, z) = ({:.6g}, {:.6g}) m", i, x[0], x[1]);
    } else {
        return fmt::format("node {} at (x, y, z) = ({:.6g}, {:.6g}, {:.6g}) m", i, x[0], x[1], x[2]);
    }
}

// Re-examines the centre the parallel loop flagged and throws the error that says why.
template <class G, class W>
[[noreturn]] void report_gradient_failure(const CompressedRows& lists, const GradientFields<G::dim>& f,
                                          std::size_t i) {
    constexpr int D = G::dim;
    const auto row = lists.row(i);
    if (row.empty()) {
        throw InputError(fmt::format(
            "{} has an empty neighbourhood: its geometry factors (Eq. 14-15) are undefined. Give it "
            "neighbours (a node needs others within 2 h_ij, or lattice neighbours under fixed "
            "connectivity)",
            describe(f.pairs, i)));
    }
    GradientSums<D> sums;
    for (NodeIndex j : row) {
        const auto p = f.pairs.template pair<W>(i, j);
        if (!(p.r > 0.0)) {
            throw NumericalError(fmt::format("{} and node {} coincide (r_ij = {}): the unit vector "
                                             "between them is undefined",
                                             describe(f.pairs, i), j, p.r));
        }
        accumulate_gradient(p, f.size_weight[j], Vec<D>::Zero().eval(), sums);
    }
    static constexpr const char* axis2[] = {"x", "z"};
    static constexpr const char* axis3[] = {"x", "y", "z"};
    for (int b = 0; b < D; ++b) {
        if (!(sums.moment[b] > 0.0)) {
            throw InputError(fmt::format(
                "{} has {} neighbours but none that weighs along {} (sum R W l^2 = {}): the geometry "
                "factor alpha_{} (Eq. 14-15) is undefined; its neighbourhood is flat or its weights "
                "are zero",
                describe(f.pairs, i), row.size(), D == 2 ? axis2[b] : axis3[b], sums.moment[b],
                D == 2 ? axis2[b] : axis3[b]));
        }
    }
    throw NumericalError(fmt::format("{}: the velocity gradient is not finite", describe(f.pairs, i)));
}

// The paper's correction at free surfaces (its section 2.5; kernels.hpp, OneSidedMoments): a
// second pass over the row, taken only when the option is on, so that the sweep without it is
// unchanged.
template <class G, class W, bool full>
void correct_for_surface(const GradientFields<G::dim>& f, std::span<const NodeIndex> row, std::size_t i,
                         GradientSums<G::dim>& sums) {
    constexpr int D = G::dim;
    if constexpr (full) {
        Vec<D> first_moment = Vec<D>::Zero();
        for (NodeIndex j : row) {
            const auto p = f.pairs.template pair<W>(i, j);
            first_moment += (p.R * f.size_weight[j]) * p.l;
        }
        const double length = first_moment.norm();
        if (!(length > 0.0)) return;
        const Vec<D> normal = first_moment / length;
        double positive = 0.0, negative = 0.0;
        for (NodeIndex j : row) {
            const auto p = f.pairs.template pair<W>(i, j);
            const double along = p.l.dot(normal);
            const double part = p.R * f.size_weight[j] * along * along;
            if (along > 0.0) {
                positive += part;
            } else {
                negative += part;
            }
        }
        sums.moment_matrix = surface_corrected_moment_matrix<D>(sums.moment_matrix, normal, positive, negative, one_sided_threshold);
    } else {
        OneSidedMoments<D> sides;
        for (NodeIndex j : row) accumulate_one_sided_moments(f.pairs.template pair<W>(i, j), f.size_weight[j], sides);
        sums.moment = surface_corrected_moment(sums.moment, sides, one_sided_threshold);
    }
}

template <class G, class W, bool full>
void gradient_impl(const CompressedRows& lists, const GradientFields<G::dim>& f, std::size_t n) {
    constexpr int D = G::dim;
    std::atomic<std::size_t> first_bad{no_node};
    const bool keep = f.keep_weight_over_r2 != nullptr;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, row_grain), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const Vec<D> v_i = load<D>(f.velocity, i);
            GradientSums<D> sums;
            bool ok = true;
            const std::size_t first = lists.offsets[i];
            const auto row = lists.row(i);
            // The row's pair geometry a chunk at a time (PairFields::pairs, two pairs per step of
            // the divider), then summed pair by pair in the row's order.
            constexpr std::size_t chunk = 32;
            std::array<PairGeometry<D>, chunk> geometry;
            for (std::size_t start = 0; start < row.size(); start += chunk) {
                const std::size_t count = std::min(chunk, row.size() - start);
                f.pairs.template pairs<W>(i, row.data() + start, count, geometry.data());
                for (std::size_t c = 0; c < count; ++c) {
                    const std::size_t k = start + c;
                    const NodeIndex j = row[k];
                    const PairGeometry<D>& p = geometry[c];
                    ok &= p.r > 0.0;
                    if (keep) f.keep_weight_over_r2[first + k] = p.R_over_r2;
                    Vec<D> dv = load<D>(f.velocity, j) - v_i;
                    if (f.pairs.sliding(i, j)) dv = along_pair<D>(f.pairs.sliding_normal(i, j, p.l), dv);  // spec section 2
                    accumulate_gradient<D, full>(p, f.size_weight[j], dv, sums);
                }
            }
            if (f.surface_correction) correct_for_surface<G, W, full>(f, row, i, sums);
            Mat<D> normalisation;
            if constexpr (full) {
                // Spec section 7: N = M^-1. Each eigenvalue of M is held at or above
                // W_i / alpha_limit (the same bound as on alpha); with allow_degenerate a direction
                // M does not see gets no normalisation at all.
                Eigen::SelfAdjointEigenSolver<Mat<D>> eigen;
                eigen.computeDirect(sums.moment_matrix, Eigen::ComputeEigenvectors);
                Vec<D> lambda = eigen.eigenvalues();
                const double floor = f.alpha_limit > 0.0 ? f.size_weight[i] / f.alpha_limit : 0.0;
                Vec<D> inverse;
                for (int b = 0; b < D; ++b) {
                    const double l = std::max(lambda[b], floor);
                    if (l > 0.0) {
                        inverse[b] = 1.0 / l;
                    } else {
                        inverse[b] = 0.0;
                        ok &= f.allow_degenerate;
                    }
                }
                normalisation = eigen.eigenvectors() * inverse.asDiagonal() * eigen.eigenvectors().transpose();
            } else {
                // Eq. 14-15, 51-53: alpha_b = 1 / sum_j R W l_b^2.
                Vec<D> alpha;
                for (int b = 0; b < D; ++b) {
                    alpha[b] = geometry_factor(sums.moment[b]);
                    if (!(sums.moment[b] > 0.0)) ok &= f.allow_degenerate;
                }
                if (f.alpha_limit > 0.0) alpha = alpha.cwiseMin(f.alpha_limit / f.size_weight[i]);
                normalisation = alpha.asDiagonal();
            }
            if (!std::isfinite(sums.smallest_h)) {
                // No neighbours: h of the node with itself, so that Eq. 36 stays finite.
                sums.smallest_h = pair_smoothing_length(f.pairs.influence_distance, f.pairs.diameter[i], f.pairs.diameter[i]);
            }
            const Mat<D> L = velocity_gradient(sums, normalisation);
            ok &= all_finite(L);
            ok &= all_finite(normalisation);
            if (!ok) {
                record_smallest(first_bad, i);
                continue;
            }
            for (int b = 0; b < D; ++b) f.alpha[b][i] = normalisation(b, b);
            if constexpr (full) {
                if constexpr (D == 2) {
                    f.alpha_shear[0][i] = normalisation(0, 1);
                } else {
                    f.alpha_shear[0][i] = normalisation(1, 2);
                    f.alpha_shear[1][i] = normalisation(0, 2);
                    f.alpha_shear[2][i] = normalisation(0, 1);
                }
            }
            for (int a = 0; a < D; ++a) {
                for (int b = 0; b < D; ++b) f.velocity_gradient[a * D + b][i] = L(a, b);
            }
            f.volumetric_strain_rate[i] = volumetric_strain_rate<G>(L, v_i[0], f.pairs.position[0][i]);
            f.smallest_h[i] = sums.smallest_h;
            if (f.stable_length) f.stable_length[i] = stable_length(sums, normalisation);
        }
    });
    if (const std::size_t bad = first_bad.load(); bad != no_node) report_gradient_failure<G, W>(lists, f, bad);
}

// Zeroes the forces of nodes [0, node_count).
template <int D>
void zero_forces(const ForceFields<D>& f, std::size_t node_count) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, node_count, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < D; ++c) std::fill(f.force[c] + r.begin(), f.force[c] + r.end(), 0.0);
    });
}

// Calls centre(i) for every centre of `plan`, one colour after the other, the groups of a colour in
// parallel: no two centres that run at once write the same node.
template <class Centre>
void for_each_coloured_centre(const ScatterPlan& plan, Centre&& centre) {
    for (std::size_t colour = 0; colour < plan.colours(); ++colour) {
        tbb::parallel_for(
            tbb::blocked_range<std::size_t>(plan.colour_offsets[colour], plan.colour_offsets[colour + 1], 1),
            [&](const tbb::blocked_range<std::size_t>& groups) {
                for (std::size_t g = groups.begin(); g != groups.end(); ++g) {
                    for (NodeIndex i : plan.group(g)) centre(i);
                }
            });
    }
}

template <class G, class W, bool with_bond_viscosity, bool full>
void forces_impl(const CompressedRows& lists, const ScatterPlan& plan, const BondViscosityParameters& bond,
                 const ForceFields<G::dim>& f, std::size_t node_count) {
    constexpr int D = G::dim;
    zero_forces<D>(f, node_count);

    const auto centre = [&](std::size_t i) {
        const Mat<D> sigma = cauchy_stress<G>(f.deviatoric_stress, f.pressure, f.viscous_pressure, i);
        const Vec<D> alpha = load<D>(f.alpha, i);
        [[maybe_unused]] Mat<D> normalisation;
        if constexpr (full) normalisation = normalisation_of<D>(f.alpha, f.alpha_shear, i);
        const double volume = f.volume[i];
        Vec<D> on_centre = Vec<D>::Zero();
        [[maybe_unused]] Vec<D> v_i;
        [[maybe_unused]] double density = 0.0, sound_speed = 0.0, bond_power = 0.0, largest_q = 0.0;
        if constexpr (with_bond_viscosity) {
            v_i = load<D>(f.velocity, i);
            density = f.mass[i] / volume;
            sound_speed = f.sound_speed[i];
        }
        const std::size_t first = lists.offsets[i];
        const auto row = lists.row(i);
        for (std::size_t k = 0; k < row.size(); ++k) {
            const NodeIndex j = row[k];
            const auto p = f.pairs.template pair<W>(i, j, first + k);
            const bool sliding = f.pairs.sliding(i, j);  // spec section 2: one direction only
            // The contact normal, read only when sliding (a kept pair has no l: its direction made).
            [[maybe_unused]] const Vec<D> n = sliding ? f.pairs.sliding_normal(i, j, PairFields<D>::direction(p.dx)) : Vec<D>::Zero().eval();
            double q = 0.0;
            [[maybe_unused]] Vec<D> dv;
            if constexpr (with_bond_viscosity) {
                dv = load<D>(f.velocity, j) - v_i;
                if (sliding) dv = along_pair<D>(n, dv);
                const double h = pair_smoothing_length(f.pairs.influence_distance, f.pairs.diameter[i], f.pairs.diameter[j]);
                const double mu = bond_compression_rate<D>(h, p.dx, dv, bond.eps0);  // Eq. 38
                q = bond_viscosity(mu, density, sound_speed, bond.linear, bond.quadratic);  // Eq. 37
            }
            Vec<D> normalised_dx;
            if constexpr (full) {
                normalised_dx = normalisation * p.dx;  // spec section 7: M_i^-1 dx
            } else {
                normalised_dx = alpha.cwiseProduct(p.dx);  // alpha_b dx_b
            }
            Vec<D> force_on_j = pair_force(p, volume, f.size_weight[j], normalised_dx, sigma, q);  // Eq. 21-22
            if (sliding) force_on_j = along_pair<D>(n, force_on_j);
            if constexpr (with_bond_viscosity) {
                if (f.largest_bond_viscosity) largest_q = std::max(largest_q, q);
            }
            for (int c = 0; c < D; ++c) f.force[c][j] += force_on_j[c];
            on_centre -= force_on_j;  // Eq. 23-24
            if constexpr (with_bond_viscosity) {
                // The work rate of the -Q_ij part of this pair's force (spec section 5).
                bond_power += p.R_over_r2 * volume * f.size_weight[j] * q * normalised_dx.dot(dv);
            }
        }
        if constexpr (G::axisymmetric) {
            if (i < f.hoop_count) {
                on_centre[0] += hoop_force(out_of_plane_stress(f.deviatoric_stress, f.pressure, f.viscous_pressure, i),
                                           volume, f.pairs.position[0][i]);
            }
        }
        for (int c = 0; c < D; ++c) f.force[c][i] += on_centre[c];
        if constexpr (with_bond_viscosity) {
            if (f.bond_viscous_power) f.bond_viscous_power[i] = bond_power;
            if (f.largest_bond_viscosity) f.largest_bond_viscosity[i] = largest_q;
        }
    };

    for_each_coloured_centre(plan, centre);
}

// The stress-difference form (Eq. 28): each real centre gathers its own force over its row
// (kernels.hpp, stress_difference_term, OneSidedness), in the colours of `plan` because a ghost
// neighbour's term is written, reversed, on the ghost (the planes' reactions and pushes read the
// forces on ghosts). Ghost centres make no force.
template <class G, class W, bool full>
void stress_difference_impl(const CompressedRows& lists, const ScatterPlan& plan, const ForceFields<G::dim>& f,
                            std::size_t node_count) {
    constexpr int D = G::dim;
    zero_forces<D>(f, node_count);
    const std::size_t real = f.hoop_count;
    const auto centre = [&](std::size_t i) {
        if (i >= real) return;
        const Mat<D> sigma_i = cauchy_stress<G>(f.deviatoric_stress, f.pressure, f.viscous_pressure, i);
        Mat<D> normalisation;
        if constexpr (full) {
            normalisation = normalisation_of<D>(f.alpha, f.alpha_shear, i);
        } else {
            normalisation = load<D>(f.alpha, i).asDiagonal();
        }
        const double volume = f.volume[i];
        const auto row = lists.row(i);
        OneSidedness<D> sides;
        for (NodeIndex j : row) sides.add_first(f.pairs.template pair<W>(i, j), f.size_weight[j]);
        for (NodeIndex j : row) sides.add_sides(f.pairs.template pair<W>(i, j), f.size_weight[j]);
        const Mat<D> kept_sigma_i = (1.0 - sides.gain()) * sigma_i;
        Vec<D> on_centre = Vec<D>::Zero();
        for (NodeIndex j : row) {
            const auto p = f.pairs.template pair<W>(i, j);
            const Mat<D> sigma_j = cauchy_stress<G>(f.deviatoric_stress, f.pressure, f.viscous_pressure, j);
            Vec<D> term = stress_difference_term(p, volume, f.size_weight[j], Vec<D>(normalisation * p.dx), sigma_j, kept_sigma_i);
            if (f.pairs.sliding(i, j)) term = along_pair<D>(f.pairs.sliding_normal(i, j, p.l), term);  // spec section 2
            on_centre += term;
            if (j >= real) {
                for (int c = 0; c < D; ++c) f.force[c][j] -= term[c];
            }
        }
        if constexpr (G::axisymmetric) {
            const auto extra = cylindrical_divergence_terms(sigma_i(0, 0), sigma_i(0, 1),
                                                            out_of_plane_stress(f.deviatoric_stress, f.pressure, f.viscous_pressure, i),
                                                            volume, f.pairs.position[0][i]);
            on_centre[0] += extra[0];
            on_centre[1] += extra[1];
        }
        for (int c = 0; c < D; ++c) f.force[c][i] += on_centre[c];
    };
    for_each_coloured_centre(plan, centre);
}

// `CurvedDamping`: the hourglass damping's kept fits may have second derivatives (the quadratic
// fit; KeptDampingPower), chosen once for the pass; `WithBond`: StressPowerOut::bond is set.
template <class G, class W, bool CurvedDamping, bool WithBond>
void stress_power_impl(const CompressedRows& lists, const ForceFields<G::dim>& f,
                       const std::array<const double*, G::dim>& velocity, std::size_t n, const StressPowerOut& out,
                       const HourglassFields<G::dim>* hourglass, double hourglass_coefficient) {
    constexpr int D = G::dim;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, row_grain), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const Mat<D> sigma = cauchy_stress<G>(f.deviatoric_stress, f.pressure, f.viscous_pressure, i);
            const Mat<D> normalisation = f.full_normalisation ? normalisation_of<D>(f.alpha, f.alpha_shear, i)
                                                              : Mat<D>(load<D>(f.alpha, i).asDiagonal());
            const double q = f.viscous_pressure ? f.viscous_pressure[i] : 0.0;
            const double volume = f.volume[i];
            const Vec<D> v_i = load<D>(velocity, i);
            // The row's sum of velocity differences B_i (kernels.hpp, accumulate_velocity_difference):
            // power -V_i (sigma_i N_i) : B_i, divergence N_i : B_i, no pair force made.
            Mat<D> difference = Mat<D>::Zero();
            // The hourglass damping's power in the same walk of the row (hourglass.hpp,
            // KeptDampingPower): the same numbers as a walk of its own.
            KeptDampingPower<D, CurvedDamping> damping;
            if (hourglass) damping = KeptDampingPower<D, CurvedDamping>(*hourglass, i, n, hourglass_coefficient);
            double damping_power = 0.0;
            // The bond-viscous forces' power (StressPowerOut::bond), their Q_ij made from the force
            // pass's velocities with its arithmetic (forces_impl), so that the forces are the same.
            [[maybe_unused]] const BondViscosityParameters* const bond = out.bond;
            [[maybe_unused]] double bond_power = 0.0, density = 0.0, sound_speed = 0.0;
            [[maybe_unused]] Vec<D> bond_v_i;
            if constexpr (WithBond) {
                density = f.mass[i] / volume;
                sound_speed = f.sound_speed[i];
                for (int c = 0; c < D; ++c) bond_v_i[c] = out.bond_velocity[c][i];
            }
            const std::size_t first = lists.offsets[i];
            const auto row = lists.row(i);
            for (std::size_t k = 0; k < row.size(); ++k) {
                const NodeIndex j = row[k];
                const auto p = f.pairs.template pair<W>(i, j, first + k);
                Vec<D> dv = load<D>(velocity, j) - v_i;
                const bool sliding = f.pairs.sliding(i, j);
                [[maybe_unused]] Vec<D> normal;
                if (sliding) {
                    normal = f.pairs.sliding_normal(i, j, PairFields<D>::direction(p.dx));
                    dv = along_pair<D>(normal, dv);  // spec section 2
                }
                accumulate_velocity_difference<D>(p, f.size_weight[j], dv, difference);
                if (damping.active()) damping_power += damping.term(*hourglass, j, p.dx, n);
                if constexpr (WithBond) {
                    // Eq. 37-38 as forces_impl makes them, the -Q_ij part of Eq. 21-22's pair force,
                    // its power at this pass's velocities.
                    Vec<D> dv_force;
                    for (int c = 0; c < D; ++c) dv_force[c] = out.bond_velocity[c][j] - bond_v_i[c];
                    if (sliding) dv_force = along_pair<D>(normal, dv_force);
                    const double h = pair_smoothing_length(f.pairs.influence_distance, f.pairs.diameter[i], f.pairs.diameter[j]);
                    const double mu = bond_compression_rate<D>(h, p.dx, dv_force, bond->eps0);
                    const double bond_q = bond_viscosity(mu, density, sound_speed, bond->linear, bond->quadratic);
                    const Vec<D> normalised_dx = f.full_normalisation ? Vec<D>(normalisation * p.dx) : Vec<D>(normalisation.diagonal().cwiseProduct(p.dx));
                    bond_power += p.R_over_r2 * volume * f.size_weight[j] * bond_q * normalised_dx.dot(dv);
                }
            }
            double sum = -volume * (sigma * normalisation).cwiseProduct(difference).sum();  // Eq. 21-22 summed over j
            double divergence = normalisation.cwiseProduct(difference).sum();
            if constexpr (G::axisymmetric) {
                const double hoop = hoop_force(out_of_plane_stress(f.deviatoric_stress, f.pressure, f.viscous_pressure, i), volume,
                                               f.pairs.position[0][i]);
                sum += hoop * v_i[0];
                divergence += hoop_strain_rate(v_i[0], f.pairs.position[0][i]);
            }
            const double viscous = q * volume * divergence;
            if (out.internal_energy) {
                const double m = out.mass[i];
                out.internal_energy[i] -= sum * out.dt / m;
                out.viscous_work[i] -= viscous * out.dt / m;
            } else {
                out.power[i] = sum;
                out.viscous_power[i] = viscous;
            }
            if constexpr (WithBond) out.bond_power[i] = bond_power;
            if (hourglass) {
                hourglass->power[i] = damping_power;
                if (hourglass->stiffness_power) {
                    // The stiffness form's power (fixed centres, and flowing ones with a relaxing
                    // reference) in a walk of its own: coefficient 0 leaves the damping out of
                    // hourglass_centre.
                    hourglass->stiffness_power[i] =
                        hourglass->stiffness > 0.0 &&
                                (hourglass->connectivity[i] == Connectivity::Fixed || hourglass->reference_position[0] != nullptr)
                            ? hourglass_centre<D>(row, i, *hourglass, n, 0.0).stiffness
                            : 0.0;
                }
            }
        }
    });
}

}  // namespace

template <class G>
void compute_stress_power(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& f,
                          const std::array<const double*, G::dim>& velocity, std::size_t real_count, const StressPowerOut& out,
                          const HourglassFields<G::dim>* hourglass, double hourglass_coefficient) {
    if (f.full_normalisation && !f.alpha_shear[0]) throw InputError("compute_stress_power: the full normalisation needs alpha_shear");
    if (out.internal_energy ? !(out.viscous_work && out.mass) : !(out.power && out.viscous_power)) {
        throw InputError("compute_stress_power: no place for the powers (both arrays, or the energies, viscous work and masses)");
    }
    dispatch_weight(weight, [&](auto w) {
        const auto run = [&](auto curved, auto with_bond) {
            stress_power_impl<G, decltype(w), decltype(curved)::value, decltype(with_bond)::value>(lists, f, velocity, real_count, out,
                                                                                                 hourglass, hourglass_coefficient);
        };
        const bool curved = hourglass && hourglass->quadratic;
        if (out.bond) {
            curved ? run(std::true_type{}, std::true_type{}) : run(std::false_type{}, std::true_type{});
        } else {
            curved ? run(std::true_type{}, std::false_type{}) : run(std::false_type{}, std::false_type{});
        }
    });
}

template <class G>
void compute_stress_power(const CompressedRows& lists, WeightKind weight, const ForceFields<G::dim>& f,
                          const std::array<const double*, G::dim>& velocity, std::size_t real_count, double* power,
                          double* viscous_power, const HourglassFields<G::dim>* hourglass, double hourglass_coefficient) {
    StressPowerOut out;
    out.power = power;
    out.viscous_power = viscous_power;
    compute_stress_power<G>(lists, weight, f, velocity, real_count, out, hourglass, hourglass_coefficient);
}

template <class G>
void compute_velocity_gradient(const CompressedRows& lists, WeightKind weight, const GradientFields<G::dim>& f,
                               std::size_t centres) {
    const std::size_t n = std::min(centres, lists.rows());
    if (f.full_normalisation && !f.alpha_shear[0]) {
        throw InputError("compute_velocity_gradient: the full normalisation needs alpha_shear (a node store that dropped it "
                         "serves the per-direction normalisation only)");
    }
    dispatch_weight(weight, [&](auto w) {
        if (f.full_normalisation) {
            gradient_impl<G, decltype(w), true>(lists, f, n);
        } else {
            gradient_impl<G, decltype(w), false>(lists, f, n);
        }
    });
}

template <class G>
void compute_forces(const CompressedRows& lists, const ScatterPlan& plan, WeightKind weight,
                    const BondViscosityParameters* bond, const ForceFields<G::dim>& f, std::size_t node_count) {
    if (plan.centres.size() != lists.rows()) {
        throw InputError(fmt::format("compute_forces: the scatter plan covers {} centres, the lists {}",
                                     plan.centres.size(), lists.rows()));
    }
    const BondViscosityParameters none{};
    dispatch_weight(weight, [&](auto w) {
        using W = decltype(w);
        const bool full = f.full_normalisation;
        if (full && !f.alpha_shear[0]) throw InputError("compute_forces: the full normalisation needs alpha_shear");
        if (f.stress_difference) {
            if (bond) throw InputError("compute_forces: the stress-difference form takes no bond viscosity");
            if (full) {
                stress_difference_impl<G, W, true>(lists, plan, f, node_count);
            } else {
                stress_difference_impl<G, W, false>(lists, plan, f, node_count);
            }
        } else if (bond && full) {
            forces_impl<G, W, true, true>(lists, plan, *bond, f, node_count);
        } else if (bond) {
            forces_impl<G, W, true, false>(lists, plan, *bond, f, node_count);
        } else if (full) {
            forces_impl<G, W, false, true>(lists, plan, none, f, node_count);
        } else {
            forces_impl<G, W, false, false>(lists, plan, none, f, node_count);
        }
    });
}

template void compute_stress_power<PlaneStrain>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                          const std::array<const double*, 2>&, std::size_t, double*, double*,
                                          const HourglassFields<2>*, double);
template void compute_stress_power<Axisymmetric>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                          const std::array<const double*, 2>&, std::size_t, double*, double*,
                                          const HourglassFields<2>*, double);
template void compute_stress_power<ThreeD>(const CompressedRows&, WeightKind, const ForceFields<3>&,
                                          const std::array<const double*, 3>&, std::size_t, double*, double*,
                                          const HourglassFields<3>*, double);
template void compute_stress_power<PlaneStrain>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                          const std::array<const double*, 2>&, std::size_t, const StressPowerOut&,
                                          const HourglassFields<2>*, double);
template void compute_stress_power<Axisymmetric>(const CompressedRows&, WeightKind, const ForceFields<2>&,
                                          const std::array<const double*, 2>&, std::size_t, const StressPowerOut&,
                                          const HourglassFields<2>*, double);
template void compute_stress_power<ThreeD>(const CompressedRows&, WeightKind, const ForceFields<3>&,
                                          const std::array<const double*, 3>&, std::size_t, const StressPowerOut&,
                                          const HourglassFields<3>*, double);
template void compute_velocity_gradient<PlaneStrain>(const CompressedRows&, WeightKind,
                                                const GradientFields<PlaneStrain::dim>&, std::size_t);
template void compute_forces<PlaneStrain>(const CompressedRows&, const ScatterPlan&, WeightKind,
                                     const BondViscosityParameters*, const ForceFields<PlaneStrain::dim>&, std::size_t);
template void compute_velocity_gradient<Axisymmetric>(const CompressedRows&, WeightKind,
                                                const GradientFields<Axisymmetric::dim>&, std::size_t);
template void compute_forces<Axisymmetric>(const CompressedRows&, const ScatterPlan&, WeightKind,
                                     const BondViscosityParameters*, const ForceFields<Axisymmetric::dim>&, std::size_t);
template void compute_velocity_gradient<ThreeD>(const CompressedRows&, WeightKind,
                                                const GradientFields<ThreeD::dim>&, std::size_t);
template void compute_forces<ThreeD>(const CompressedRows&, const ScatterPlan&, WeightKind,
                                     const BondViscosityParameters*, const ForceFields<ThreeD::dim>&, std::size_t);

}  // namespace gpa
