// Johnson-Cook fracture strain (materials.md, "Fracture").

#include <algorithm>
#include <cmath>

#include "gpa/materials/material.hpp"

namespace gpa::materials {

// eps_f = [D1 + D2 exp(D3 sigma*)][1 + D4 ln epsdot*][1 + D5 T*], floored at min_failure_strain
// (materials.md, "Fracture"). Guards, as for the strength model: epsdot* = max(epsdot / epsdot0, 1),
// so a slow or zero rate never sends ln epsdot* to -infinity; T* clamped to [0, 1]; the exponent
// D3 sigma* capped at 700 so exp() cannot overflow (sigma* is huge only where sigma_vm is tiny).
// The floor also catches constant sets whose eps_f is <= 0 at high triaxiality (Armco iron).
double johnson_cook_failure_strain(const JohnsonCookFailure& f, double triaxiality, double strain_rate,
                                   double homologous_temperature) {
    const double t_star = std::clamp(homologous_temperature, 0.0, 1.0);
    const double rate_ratio = std::max(strain_rate / f.reference_strain_rate, 1.0);
    const double stress_term = f.d1 + f.d2 * std::exp(std::min(f.d3 * triaxiality, 700.0));
    const double eps_f = stress_term * (1.0 + f.d4 * std::log(rate_ratio)) * (1.0 + f.d5 * t_star);
    return std::max(eps_f, f.min_failure_strain);
}

}  // namespace gpa::materials
