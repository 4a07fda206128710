#include "gpa/materials/elastic.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace gpa::materials {

ElasticConstants ElasticConstants::from_young_poisson(double young, double poisson) {
    if (!(young > 0.0) || !std::isfinite(young)) {
        throw std::invalid_argument(fmt::format("Young's modulus {} Pa must be positive", young));
    }
    if (!(poisson > -1.0 && poisson < 0.5)) {
        throw std::invalid_argument(fmt::format("Poisson's ratio {} must lie in (-1, 0.5)", poisson));
    }
    return {young / (3.0 * (1.0 - 2.0 * poisson)), young / (2.0 * (1.0 + poisson))};
}

double longitudinal_wave_speed(const ElasticConstants& e, double density) {
    return std::sqrt((e.bulk_modulus + 4.0 * e.shear_modulus / 3.0) / density);
}

double bar_wave_speed(const ElasticConstants& e, double density) { return std::sqrt(e.young_modulus() / density); }

}  // namespace gpa::materials
