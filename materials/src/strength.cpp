// Strength models and the radial return (materials.md, "Strength"; gpa-method.md section 4).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "internal.hpp"

namespace gpa::materials {
namespace detail {

namespace {

// The thermal factor 1 - T*^m for T* in [0, 1). pow(0, m) = 0: the call is skipped there (room
// temperature, most points of most steps).
double johnson_cook_thermal(const JohnsonCookStrength& jc, double t_star) {
    return t_star > 0.0 ? 1.0 - std::pow(t_star, jc.m) : 1.0;
}

// The rate factor 1 + C ln(epsdot / epsdot0), the ratio floored at 1 (ln(1) = 0: no call there).
double johnson_cook_rate(const JohnsonCookStrength& jc, double strain_rate) {
    const double rate_ratio = strain_rate / jc.reference_strain_rate;
    return rate_ratio > 1.0 ? 1.0 + jc.c * std::log(rate_ratio) : 1.0;
}

// eps_p^n of the strain term, 0 where it has none (B = 0, n = 0) or at eps_p <= 0.
double strain_power_of(const JohnsonCookStrength& jc, double plastic_strain) {
    return jc.b != 0.0 && jc.n > 0.0 && plastic_strain > 0.0 ? std::pow(plastic_strain, jc.n) : 0.0;
}

// The strain term A + B eps_p^n from eps_p^n (strain_power_of, or the return's series). n = 0: a
// step at eps_p = 0 (validate() only allows it with B = 0).
double strain_hardening(const JohnsonCookStrength& jc, double plastic_strain, double strain_power) {
    if (jc.b != 0.0 && jc.n > 0.0) return jc.a + jc.b * strain_power;
    return jc.b != 0.0 && plastic_strain > 0.0 ? jc.a + jc.b : jc.a;
}

// Y and dY/d eps_p from the strain term and the two factors above.
FlowStress johnson_cook_hardening(const JohnsonCookStrength& jc, double plastic_strain, double rate, double thermal) {
    const double eps_n = strain_power_of(jc, plastic_strain);
    const double hardening = strain_hardening(jc, plastic_strain, eps_n);
    double slope = 0.0;
    if (jc.b != 0.0 && jc.n > 0.0) {
        slope = plastic_strain > 0.0 ? jc.b * jc.n * eps_n / plastic_strain
                                     : (jc.n < 1.0 ? std::numeric_limits<double>::infinity() : (jc.n == 1.0 ? jc.b : 0.0));
    }
    return {hardening * rate * thermal, slope * rate * thermal};
}

}  // namespace

// Johnson-Cook flow stress and hardening slope (materials.md, "Strength"):
//   Y = (A + B eps_p^n)(1 + C ln(max(epsdot / epsdot0, 1)))(1 - T*^m),
// with the edges guarded: eps_p^n = 0 at eps_p <= 0; the rate ratio floored at 1 so the rate term
// never weakens the material; T* clamped to [0, 1]; Y = 0 at and above melt (T* >= 1).
// dY/d eps_p = B n eps_p^(n - 1) (rate and thermal factors), infinite at eps_p = 0 when n < 1.
FlowStress johnson_cook_flow(const JohnsonCookStrength& jc, double plastic_strain, double strain_rate,
                             double homologous_temperature) {
    const double t_star = std::clamp(homologous_temperature, 0.0, 1.0);
    if (t_star >= 1.0) {
        return {0.0, 0.0};
    }
    return johnson_cook_hardening(jc, plastic_strain, johnson_cook_rate(jc, strain_rate), johnson_cook_thermal(jc, t_star));
}

namespace {

// Scale the trial deviator back to the flow stress: s = s* Y / sigma_eq* (radial return).
ReturnResult project(const Eigen::Matrix3d& trial, double trial_equivalent, double flow_stress,
                     double plastic_increment) {
    ReturnResult r;
    r.deviator = trial * (flow_stress / trial_equivalent);
    r.plastic_strain_increment = plastic_increment;
    r.flow_stress = flow_stress;
    r.plastic = true;
    r.trial_equivalent = trial_equivalent;
    return r;
}

// Johnson-Cook radial return with hardening and rate hardening: solve
//   f(x) = sigma_eq* - 3 G x - Y(eps_p + x, x / dt) = 0,   x = d eps_p,
// by Newton's method safeguarded with bisection. The rate is the equivalent plastic strain rate
// of the step, as Johnson and Cook (1983) define epsdot*: it depends on the unknown x, and Y does
// not fall with x (strain hardening and the rate term, floored at epsdot0, both rise), so f falls
// from f(0) > 0 and the perfectly plastic estimate x_hi = (sigma_eq* - Y(eps_p, 0)) / (3 G), at
// which f <= 0, brackets the root. Stop when |f| <= 1e-13 sigma_eq* or the bracket has shrunk to
// round-off; the deviator is then scaled to Y(eps_p + x, x / dt) itself, so it lies on the yield
// surface to round-off.
// The Newton step: x (1 + s) with s = f / (x (3 G + dY/dx)), the step in x; where that would
// shrink x by more than half, x e^s, the step in ln x, which never reaches 0. f is convex in x
// (Y is concave: C ln(x / dt) and eps_p^n with n <= 1), so from x_hi, to the right of the root,
// the step in x overshoots to the left, often below 0, where the iteration fell back to halving
// (28 evaluations at most, 8 on average in the README's main job); in ln x the rate term's
// logarithm is a straight line, and the overshoot is mild.
// Iteration bound: each step takes the Newton point when it lies inside the bracket, else halves
// the bracket; bisection alone would be done after 51 halvings (from x_hi down to 4 eps x_hi).
// Measured over the library's Johnson-Cook constants, plastic strains 0-5, temperatures to just
// below melt, steps of 0.1 ns to 1 us and trial stresses up to 1000 times yield: at most 16
// flow-stress evaluations from eps_p > 0 and 11 at first yield, where dY/dx is infinite at x = 0
// (tests/materials/test_strength.cpp, RadialReturn.JohnsonCookIterationBound, asserts the 52 of
// bisection); 6.5 on average in the main job from x_hi.
// The warm start: a point that flowed in its last step starts at start = (its rate then) x dt
// (PointState::plastic_strain_rate) when that lies inside the bracket (0, x_hi); a point's rate
// changes little from step to step, so the first evaluation lands near the root. Only the path
// changes, not the bracket or the stopping rule: 3.8 evaluations on average in the main job and
// 18 at most there (counted over its 2.33 M returns); 2251 against 3414 cold over five sets of 120 steps in
// RadialReturn.JohnsonCookWarmStartGivesTheColdAnswerInFewerEvaluations.
// The loop is capped at johnson_cook_max_iterations (material.hpp);
// a return that reaches the cap is a fault of the point update (PointFault::return_not_converged),
// which stops the run: it is never used silently.
ReturnResult johnson_cook_return(const JohnsonCookStrength& jc, const Eigen::Matrix3d& trial, double trial_equivalent,
                                 double shear_modulus, double plastic_strain, double strain_power, double dt, bool molten,
                                 double thermal, double initial_flow_stress, double start) {
    const double three_g = 3.0 * shear_modulus;
    // x -> epsdot / epsdot0 = x / (dt epsdot0) as one product: the rate ratio of every evaluation.
    const double ratio_per_increment = dt > 0.0 ? 1.0 / (dt * jc.reference_strain_rate) : 0.0;
    const double bn = jc.n > 0.0 ? jc.b * jc.n : 0.0;
    // e^n = eps_p^n (1 + u)^n, u = x / eps_p, by the binomial series where u <= 2^-7:
    //   (1 + u)^n = sum_k C(n, k) u^k,  C(n, k) = f_1 ... f_k,  f_k = (n - k + 1) / k,
    // to k = 8, which leaves out at most |C(n, 9)| u^9 < 0.014 x 2^-63 = 1.5e-21 (0 < n <= 4), far
    // below a double's round-off, for a few products where std::pow took about as long as the rest
    // of an evaluation. Summed in Estrin's pairs (u, u^2, u^4), whose chain of dependent operations
    // is a third of Horner's. At first yield
    // (eps_p = 0), for larger u or n: std::pow.
    const bool series = strain_power > 0.0 && jc.n <= 4.0;
    const double inverse_strain = series ? 1.0 / plastic_strain : 0.0;
    // C(n, k) = f_1 ... f_k, the f_k independent of each other (no chain of divisions), their
    // products as a tree (short chains); only where the series serves.
    std::array<double, 9> binomial{};
    if (series) {
        static constexpr std::array<double, 9> inverse_k{0.0, 1.0, 1.0 / 2, 1.0 / 3, 1.0 / 4, 1.0 / 5, 1.0 / 6, 1.0 / 7, 1.0 / 8};
        std::array<double, 9> f{};
        for (int k = 1; k < 9; ++k) f[k] = (jc.n - (k - 1)) * inverse_k[k];
        binomial[1] = f[1];
        binomial[2] = f[1] * f[2];
        binomial[3] = binomial[2] * f[3];
        binomial[4] = binomial[2] * (f[3] * f[4]);
        binomial[5] = binomial[4] * f[5];
        binomial[6] = binomial[4] * (f[5] * f[6]);
        binomial[7] = binomial[6] * f[7];
        binomial[8] = binomial[4] * ((f[5] * f[6]) * (f[7] * f[8]));
    }
    // One evaluation at x > 0: Y(eps_p + x, x / dt) (johnson_cook_flow, the thermal factor taken
    // once by the caller) and the Newton step's fraction. With e = eps_p + x, H = A + B e^n and
    // the rate factor R = 1 + C ln(x / (dt epsdot0)) (1 below epsdot0),
    //   dY/dx = T (R B n e^n / e + H C / x)      (the second term only above epsdot0),
    // and the step in x of the iteration below, f / (x (3 G + dY/dx)), is f e / denominator with
    //   denominator = 3 G e x + T (R B n e^n x + H C e):
    // one division per evaluation, all its terms positive. Molten: Y = 0, the step f / (3 G x).
    struct Evaluation {
        double stress = 0.0;  // Y, Pa
        double e = 1.0;       // the step is f * e / denominator
        double denominator = 0.0;
    };
    const auto evaluate = [&](double x) {
        Evaluation y;
        if (molten) {
            y.denominator = three_g * x;
            return y;
        }
        const double ratio = x * ratio_per_increment;
        const bool rate_hardens = ratio > 1.0;
        const double rate = rate_hardens ? 1.0 + jc.c * std::log(ratio) : 1.0;
        const double e = plastic_strain + x;
        double e_n = 0.0;  // e^n where the strain term has one
        if (jc.b != 0.0 && jc.n > 0.0) {
            const double u = x * inverse_strain;
            if (series && u <= 0x1p-7) {
                const double u2 = u * u, u4 = u2 * u2;
                const double low = (1.0 + binomial[1] * u) + u2 * (binomial[2] + binomial[3] * u);
                const double high = (binomial[4] + binomial[5] * u) + u2 * (binomial[6] + binomial[7] * u);
                e_n = strain_power * (low + u4 * (high + u4 * binomial[8]));
            } else {
                e_n = std::pow(e, jc.n);
            }
        }
        const double hardening = strain_hardening(jc, e, e_n);
        const double bn_en = bn * e_n;  // B n e^n
        y.stress = hardening * rate * thermal;
        y.e = e;
        y.denominator = three_g * e * x + thermal * (rate * bn_en * x + (rate_hardens ? hardening * jc.c * e : 0.0));
        return y;
    };
    double lo = 0.0;
    double hi = (trial_equivalent - initial_flow_stress) / three_g;
    // The warm start: the last step's rate carried over, where it lies inside the bracket.
    double x = (start > 0.0 && start < hi) ? start : hi;
    const double tolerance = 1e-13 * trial_equivalent;
    Evaluation y = evaluate(x);
    int evaluations = 1;
    bool converged = false;
    for (int iteration = 0; iteration < johnson_cook_max_iterations; ++iteration) {
        const double f = trial_equivalent - three_g * x - y.stress;
        if (std::abs(f) <= tolerance) {
            converged = true;
            break;
        }
        if (f > 0.0) {
            lo = x;
        } else {
            hi = x;
        }
        if (hi - lo <= 4.0 * std::numeric_limits<double>::epsilon() * hi) {
            converged = true;
            break;
        }
        const double step = f * y.e / y.denominator;  // f / (x (3 G + dY/dx)), f' = -(3 G + dY/dx); x > 0 here
        const double newton = step > -0.5 ? x * (1.0 + step) : x * std::exp(step);
        x = (newton > lo && newton < hi) ? newton : 0.5 * (lo + hi);
        y = evaluate(x);
        ++evaluations;
    }
    ReturnResult r = project(trial, trial_equivalent, y.stress, x);
    r.iterations = converged ? evaluations : johnson_cook_max_iterations + 1;
    return r;
}

}  // namespace

// Radial return (gpa-method.md section 4): if sigma_eq(s*) exceeds the flow stress, scale s* back
// along itself onto the yield surface; the plastic strain increment satisfies
// sigma_eq* - 3 G d eps_p = Y(eps_p + d eps_p). Y = 0 at and above melt for both plastic models
// (materials.md). With G = 0 no elastic strain exists to turn plastic: the deviator is only
// scaled back and d eps_p = 0. One overload per strength model.

// An elastic material: no return.
ReturnResult model_return(const ElasticStrength&, const Eigen::Matrix3d& trial, double, double, double, double, double) {
    ReturnResult elastic;
    elastic.deviator = trial;
    return elastic;
}

// Linear hardening Y(eps_p) = Y0 + H eps_p: the consistency condition
// sigma_eq* - 3 G x = Y0 + H (eps_p + x) is linear in x = d eps_p, so
// x = (sigma_eq* - Y(eps_p)) / (3 G + H) exactly (H = 0: perfect plasticity).
ReturnResult model_return(const VonMisesStrength& vm, const Eigen::Matrix3d& trial, double shear_modulus,
                          double plastic_strain, double, double homologous_temperature, double) {
    ReturnResult elastic;
    elastic.deviator = trial;
    const double t_star = std::clamp(homologous_temperature, 0.0, 1.0);
    const double trial_equivalent = von_mises(trial);
    const double h = vm.hardening_modulus;
    const double y = t_star >= 1.0 ? 0.0 : vm.yield_stress + h * plastic_strain;
    elastic.flow_stress = y;
    if (!(trial_equivalent > y)) {
        return elastic;
    }
    if (!(shear_modulus > 0.0)) return project(trial, trial_equivalent, y, 0.0);
    // Molten (Y = 0 whatever eps_p): the whole trial deviator returns, without hardening.
    const double slope = t_star >= 1.0 ? 0.0 : h;
    const double increment = (trial_equivalent - y) / (3.0 * shear_modulus + slope);
    return project(trial, trial_equivalent, y + slope * increment, increment);
}

// Johnson-Cook: the iteration of johnson_cook_return from the flow stress at the start of the step
// (johnson_cook_flow at zero rate, its thermal factor taken once for both).
ReturnResult model_return(const JohnsonCookStrength& jc, const Eigen::Matrix3d& trial, double shear_modulus,
                          double plastic_strain, double dt, double homologous_temperature, double previous_rate) {
    ReturnResult elastic;
    elastic.deviator = trial;
    const double t_star = std::clamp(homologous_temperature, 0.0, 1.0);
    const double trial_equivalent = von_mises(trial);
    const bool molten = t_star >= 1.0;
    const double thermal = molten ? 0.0 : johnson_cook_thermal(jc, t_star);
    // No plastic flow yet: no rate term (its factor is 1). eps_p^n, kept for the return's series.
    const double strain_power = strain_power_of(jc, plastic_strain);
    const double y0 = molten ? 0.0 : strain_hardening(jc, plastic_strain, strain_power) * thermal;
    elastic.flow_stress = y0;
    if (!(trial_equivalent > y0)) {
        return elastic;
    }
    if (!(shear_modulus > 0.0)) {
        return project(trial, trial_equivalent, y0, 0.0);
    }
    return johnson_cook_return(jc, trial, trial_equivalent, shear_modulus, plastic_strain, strain_power, dt, molten,
                               thermal, y0, previous_rate * dt);
}

}  // namespace detail

// Public Johnson-Cook flow stress (materials.md, "Strength"); see detail::johnson_cook_flow.
double johnson_cook_flow_stress(const JohnsonCookStrength& jc, double plastic_strain, double strain_rate,
                                double homologous_temperature) {
    return detail::johnson_cook_flow(jc, plastic_strain, strain_rate, homologous_temperature).stress;
}

}  // namespace gpa::materials
