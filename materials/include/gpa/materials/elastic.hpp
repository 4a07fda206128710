#pragma once
// Isotropic linear-elastic constants and the wave speeds that follow from them.

namespace gpa::materials {

struct ElasticConstants {
    double bulk_modulus = 0.0;   // K, Pa
    double shear_modulus = 0.0;  // G, Pa

    // From Young's modulus E (Pa) and Poisson's ratio nu; throws InputError-like
    // std::invalid_argument for E <= 0 or nu outside (-1, 0.5).
    static ElasticConstants from_young_poisson(double young, double poisson);

    double young_modulus() const { return 9.0 * bulk_modulus * shear_modulus / (3.0 * bulk_modulus + shear_modulus); }
    double poisson_ratio() const {
        return (3.0 * bulk_modulus - 2.0 * shear_modulus) / (2.0 * (3.0 * bulk_modulus + shear_modulus));
    }
};

// Longitudinal (dilatational) wave speed sqrt((K + 4G/3) / rho), m/s.
double longitudinal_wave_speed(const ElasticConstants& e, double density);
// Bar wave speed sqrt(E / rho), m/s.
double bar_wave_speed(const ElasticConstants& e, double density);

}  // namespace gpa::materials
