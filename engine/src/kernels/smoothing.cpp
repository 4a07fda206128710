#include "gpa/engine/smoothing.hpp"

#include "gpa/engine/kernels.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace gpa {

namespace {

template <class G, class W>
double smooth_impl(const CompressedRows& lists, const ScatterPlan& plan, const PairFields<G::dim>& pairs,
                   std::size_t n, const SmoothingOptions& options, std::array<double*, G::dim> v, const double* mass,
                   const double* pressure, double* internal_energy, SmoothingScratch& scratch) {
    constexpr int D = G::dim;
    scratch.centre_change.assign(D * n, 0.0);
    scratch.share.assign(n, 0.0);
    scratch.total_change.assign(D * n, 0.0);
    // Eq. 66-67: dv_i = C (vbar_i - v_i), vbar_i = sum R_ij v_j / sum R_ij over real neighbours.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            if (options.tension_only && !(pressure[i] < 0.0)) continue;
            double weight_sum = 0.0, weighted_mass = 0.0;
            Vec<D> weighted_v = Vec<D>::Zero();
            const std::size_t first = lists.offsets[i];
            const auto row = lists.row(i);
            for (std::size_t k = 0; k < row.size(); ++k) {
                const NodeIndex j = row[k];
                // Ghosts take no part, nor do contacts and cracks (spec section 2, "[spec] Sliding
                // contact": averaging velocities across them would be friction).
                if (j >= n || pairs.sliding(i, j)) continue;
                const double R = pairs.template weight<W>(i, j, first + k);
                weight_sum += R;
                weighted_mass += R * mass[j];
                for (int c = 0; c < D; ++c) weighted_v[c] += R * v[c][j];
            }
            if (!(weight_sum > 0.0) || !(weighted_mass > 0.0)) continue;
            for (int c = 0; c < D; ++c) {
                scratch.centre_change[D * i + c] = smoothing_change(options.coefficient, weighted_v[c], weight_sum, v[c][i]);
            }
            scratch.share[i] = smoothing_share(mass[i], weighted_mass);
        }
    });
    // Scatter the neighbours' shares by colours (each node receives its changes in plan order).
    for (std::size_t colour = 0; colour < plan.colours(); ++colour) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(plan.colour_offsets[colour], plan.colour_offsets[colour + 1], 1),
                          [&](const tbb::blocked_range<std::size_t>& groups) {
                              for (std::size_t g = groups.begin(); g != groups.end(); ++g) {
                                  for (NodeIndex i : plan.group(g)) {
                                      if (i >= n || scratch.share[i] == 0.0) continue;
                                      const double* dv = &scratch.centre_change[D * i];
                                      for (int c = 0; c < D; ++c) scratch.total_change[D * i + c] += dv[c];
                                      const std::size_t first = lists.offsets[i];
                                      const auto row = lists.row(i);
                                      for (std::size_t k = 0; k < row.size(); ++k) {
                                          const NodeIndex j = row[k];
                                          if (j >= n || pairs.sliding(i, j)) continue;
                                          const double f = -scratch.share[i] * pairs.template weight<W>(i, j, first + k);
                                          for (int c = 0; c < D; ++c) scratch.total_change[D * j + c] += f * dv[c];
                                      }
                                  }
                              }
                          });
    }
    // Eq. 73: the kinetic energy a node loses becomes its internal energy.
    return tbb::parallel_deterministic_reduce(
        tbb::blocked_range<std::size_t>(0, n, 4096), 0.0,
        [&](const tbb::blocked_range<std::size_t>& r, double moved) {
            for (std::size_t i = r.begin(); i != r.end(); ++i) {
                double before = 0.0, after = 0.0;
                const unsigned held = options.held ? options.held[i] : 0u;
                for (int c = 0; c < D; ++c) {
                    const double old_v = v[c][i];
                    const double new_v = (held >> c) & 1u ? old_v : old_v + scratch.total_change[D * i + c];
                    before += old_v * old_v;
                    after += new_v * new_v;
                    v[c][i] = new_v;
                }
                const double dE = smoothing_heat(mass[i], before, after);
                internal_energy[i] += dE / mass[i];
                moved += dE;
            }
            return moved;
        },
        [](double a, double b) { return a + b; });
}

}  // namespace

template <class G>
double smooth_velocities(const CompressedRows& lists, const ScatterPlan& plan, WeightKind weight,
                         const PairFields<G::dim>& pairs, std::size_t real_count, const SmoothingOptions& options,
                         std::array<double*, G::dim> velocity, const double* mass, const double* pressure,
                         double* internal_energy, SmoothingScratch& scratch) {
    return dispatch_weight(weight, [&](auto w) {
        return smooth_impl<G, decltype(w)>(lists, plan, pairs, real_count, options, velocity, mass, pressure,
                                           internal_energy, scratch);
    });
}

template double smooth_velocities<PlaneStrain>(const CompressedRows&, const ScatterPlan&, WeightKind, const PairFields<2>&,
                                               std::size_t, const SmoothingOptions&, std::array<double*, 2>,
                                               const double*, const double*, double*, SmoothingScratch&);
template double smooth_velocities<Axisymmetric>(const CompressedRows&, const ScatterPlan&, WeightKind, const PairFields<2>&,
                                                std::size_t, const SmoothingOptions&, std::array<double*, 2>,
                                                const double*, const double*, double*, SmoothingScratch&);
template double smooth_velocities<ThreeD>(const CompressedRows&, const ScatterPlan&, WeightKind, const PairFields<3>&,
                                          std::size_t, const SmoothingOptions&, std::array<double*, 3>, const double*,
                                          const double*, double*, SmoothingScratch&);

}  // namespace gpa
