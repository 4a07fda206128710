#pragma once
// Material models (shared/spec/materials.md): equations of state, strength, adiabatic
// temperature, Johnson-Cook damage and spall, and the point update that advances one node's
// stress state over a time step (spec section 4: Jaumann rate, radial return).
//
// Materials are value types: one parameter struct per model, gathered in a std::variant that a
// caller visits once per group of nodes, not per node. Nothing here knows of nodes, neighbours,
// threads or files. Units are SI (Pa, m, s, kg, K, J).

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>

#include <Eigen/Core>

namespace gpa::materials {

// --- Equations of state: P(rho, e), all of the form P = a(rho) + b(rho) e ---------------------

// P = K mu, mu = rho/rho0 - 1; or P = K ln(rho/rho0) when logarithmic.
struct LinearEos {
    double bulk_modulus = 0.0;  // K, Pa
    bool logarithmic = false;
};

// EPIC-style polynomial: in compression P = (K1 mu + K2 mu^2 + K3 mu^3)(1 - Gamma0 mu / (2 (1 + mu)))
// + Gamma0 rho0 e; in tension P = K1 mu + Gamma0 rho0 e.
struct PolynomialEos {
    double k1 = 0.0, k2 = 0.0, k3 = 0.0;  // Pa
    double gruneisen = 0.0;               // Gamma0
};

// Mie-Grueneisen with a linear Us = c0 + s up Hugoniot (materials.md gives the formulas).
struct MieGruneisenEos {
    double sound_speed = 0.0;  // c0, m/s
    double slope = 0.0;        // s
    double gruneisen = 0.0;    // Gamma0
};

using EquationOfState = std::variant<LinearEos, PolynomialEos, MieGruneisenEos>;

struct EosResult {
    double pressure = 0.0;            // P, Pa
    double energy_coefficient = 0.0;  // b = dP/de at fixed rho (P = a + b e), kg/m^3
    double bulk_modulus = 0.0;        // isentropic K_s = rho dP/drho|_e + (P / rho) dP/de, Pa
};

// Throws std::domain_error (naming mu and the limit) when the Mie-Grueneisen Hugoniot is
// evaluated at or beyond its pole mu = 1/(s - 1) (guarded with a margin).
EosResult evaluate_eos(const EquationOfState& eos, double reference_density, double density,
                       double specific_internal_energy);

// --- Strength ----------------------------------------------------------------------------

struct ElasticStrength {};

// Von Mises with linear isotropic hardening: Y = yield_stress + hardening_modulus eps_p
// (hardening_modulus 0: perfectly plastic). hardening_modulus is the plastic modulus H = dY/d eps_p;
// a tangent modulus E_t of the uniaxial stress-strain curve converts as H = E E_t / (E - E_t).
struct VonMisesStrength {
    double yield_stress = 0.0;       // Y0, Pa
    double hardening_modulus = 0.0;  // H, Pa
};

// Y = (A + B eps_p^n)(1 + C ln(max(epsdot / epsdot0, 1)))(1 - T*^m), T* clamped to [0, 1].
struct JohnsonCookStrength {
    double a = 0.0, b = 0.0;  // Pa
    double n = 0.0, c = 0.0, m = 1.0;
    double reference_strain_rate = 1.0;  // epsdot0, 1/s
};

using Strength = std::variant<ElasticStrength, VonMisesStrength, JohnsonCookStrength>;

// The Johnson-Cook flow stress at plastic strain eps_p, strain rate (1/s) and homologous
// temperature T* (clamped to [0, 1] here; 0 at and above melt gives Y = 0).
double johnson_cook_flow_stress(const JohnsonCookStrength& jc, double plastic_strain, double strain_rate,
                                double homologous_temperature);

// --- Failure -----------------------------------------------------------------------------

// eps_f = [D1 + D2 exp(D3 sigma*)][1 + D4 ln epsdot*][1 + D5 T*], floored at min_failure_strain.
struct JohnsonCookFailure {
    double d1 = 0.0, d2 = 0.0, d3 = 0.0, d4 = 0.0, d5 = 0.0;
    double reference_strain_rate = 1.0;
    double min_failure_strain = 0.01;  // floor; some constant sets give eps_f <= 0 at high triaxiality
};

struct Failure {
    std::optional<JohnsonCookFailure> johnson_cook;
    std::optional<double> spall_pressure;  // P_spall > 0: a node fails when P < -P_spall
};

double johnson_cook_failure_strain(const JohnsonCookFailure& f, double triaxiality, double strain_rate,
                                   double homologous_temperature);

// --- A material -------------------------------------------------------------------------

struct Material {
    std::string name;
    std::string source;  // where the constants come from, and which were not checked
    std::string base;    // the material this one was derived from (a scene's `base`), empty if none; descriptive only
    double density = 0.0;           // rho0, kg/m^3: sets nodal masses and the EOS reference alike
    double shear_modulus = 0.0;     // G, Pa
    double specific_heat = 0.0;     // c_p, J/(kg K); 0 = no temperature rise
    double taylor_quinney = 0.9;    // beta, fraction of plastic work turned into heat
    double room_temperature = 294.0;                                   // K, also the initial temperature
    double melt_temperature = std::numeric_limits<double>::infinity();  // K
    EquationOfState eos = LinearEos{};
    Strength strength = ElasticStrength{};
    Failure failure;
};

// Throws std::invalid_argument naming the material and the offending field (non-positive
// density, negative moduli, Taylor-Quinney outside [0, 1], melt below room temperature, ...).
void validate(const Material& m);

// T* = (T - T_room) / (T_melt - T_room), clamped to [0, 1].
double homologous_temperature(const Material& m, double temperature);

// Longitudinal wave speed of the unstressed material, sqrt((K + 4G/3) / rho0), m/s.
double reference_wave_speed(const Material& m);

// --- The point update ------------------------------------------------------------------

// Symmetric 3x3 tensors as (xx, yy, zz, yz, xz, xy). 2D callers map their axes: axisymmetric
// (x, z, theta) and plane strain (x, z, y) both go to (xx, yy, zz) = (x, z, out-of-plane).
using Sym3 = std::array<double, 6>;

struct PointState {
    Sym3 deviatoric_stress{};             // s, Pa
    double pressure = 0.0;                // P from the EOS (without artificial viscosity), Pa
    double specific_internal_energy = 0.0;  // e, J/kg
    double plastic_strain = 0.0;          // equivalent plastic strain
    double temperature = 294.0;           // K
    double damage = 0.0;                  // Johnson-Cook D
    // d eps_p / dt of the point's last step, 1/s (0 where it stayed elastic): the Johnson-Cook
    // return starts its iteration at this rate times the new step (strength.cpp). Only the
    // iteration's path depends on it, not its answer (to the return's tolerance, 1e-13 of the
    // trial stress); a caller that does not keep it passes 0 and the iteration starts cold.
    double plastic_strain_rate = 0.0;
    bool failed = false;
};

struct PointIncrement {
    Eigen::Matrix3d velocity_gradient = Eigen::Matrix3d::Zero();  // L over the step (3D form)
    double dt = 0.0;                                                // s
    double density_old = 0.0, density_new = 0.0;                    // kg/m^3, at the start and end of the step
    double viscous_pressure_old = 0.0, viscous_pressure_new = 0.0;  // artificial viscosity Q at both ends, Pa
    bool failure_enabled = false;                                   // apply the material's failure models
    // The caller books the work of the stress itself (the engine's compatible energy update, spec
    // section 5 "[spec] Compatible energy"): the point keeps its specific internal energy and takes
    // its end pressure from the EOS at (rho_new, e); plastic work, temperature and damage as usual.
    bool energy_booked_by_caller = false;
};

// Why a point update could not advance a point (PointResult::fault). The point's state is then
// left as it was passed in, and PointModel::fault_message says what went wrong in words.
enum class PointFault : std::uint8_t {
    none,
    bad_increment,         // a density that is not positive and finite, or a negative or non-finite time step
    eos_limit,             // compression at or beyond the Mie-Grueneisen guard short of the Hugoniot pole (eos.cpp)
    energy_solve,          // one step's compression too large for the point's own energy solve (point_update.cpp)
    return_not_converged,  // the Johnson-Cook return reached johnson_cook_max_iterations (strength.cpp)
};

struct PointResult {
    PointFault fault = PointFault::none;  // none: the point advanced
    double sound_speed = 0.0;       // longitudinal, sqrt((K_s + 4 G / 3) / rho), G = 0 when failed or molten
    double plastic_work = 0.0;      // increment of specific plastic work over the step, J/kg
    double viscous_work = 0.0;      // increment of specific work done by Q over the step, J/kg (>= 0 in compression)
    double plastic_strain_rate = 0.0;  // equivalent plastic strain rate d eps_p / dt of the step, 1/s
    bool failed_now = false;        // the node failed during this step
    // Flow-stress evaluations of the Johnson-Cook return (0 for other strengths and elastic steps);
    // johnson_cook_max_iterations + 1 when the return did not converge within its cap (then the
    // fault is return_not_converged: the deviator would not lie on the yield surface).
    int return_iterations = 0;
};

// The cap on the Johnson-Cook return's iteration (materials/src/strength.cpp explains the bound).
inline constexpr int johnson_cook_max_iterations = 200;

// Advances one material point over dt (spec section 4):
//   deviator: Jaumann rate s* = s + dt (2 G D' + Omega s - s Omega), then radial return to the
//     flow stress (Johnson-Cook or von Mises; elastic: no return), giving eps_p and plastic work;
//   energy: e += dt / rho_mid * s_mid : D' - (P_mid + Q_mid) (1/rho_new - 1/rho_old), with the
//     mid-step (average of start and end) values; the end pressure comes from the EOS at
//     (rho_new, e_new), solved exactly because every EOS here is linear in e;
//   temperature: T += beta dW_p / c_p; damage: D += d eps_p / eps_f;
//   failure (if enabled): D >= 1 or P < -P_spall; a failed point keeps no deviator and no tension.
// Throws std::domain_error with PointModel::fault_message when the point cannot be advanced (the
// faults of PointFault), the state then unchanged. A convenience for single points: a loop over many
// points of one material makes a PointModel once and calls its update.
PointResult update_point(const Material& m, PointState& state, const PointIncrement& inc);

// A material with its models chosen once: the equation of state and the strength model are looked
// up when the PointModel is made, not at every point, and the constants every point needs (the
// reference bulk modulus of the sound-speed floor) are worked out then. The engine makes one per
// material group and stress update; the points of the group then run code compiled for their models,
// with no branch on the model and no exception. Refers to the material, which must outlive it and
// must not change while it is in use (make a new PointModel after changing a material's models).
class PointModel {
public:
    explicit PointModel(const Material& material);
    PointModel(Material&&) = delete;  // a temporary would not outlive it

    // The point update of update_point, without exceptions: a point that cannot be advanced comes
    // back with PointResult::fault set and its state unchanged.
    PointResult update(PointState& state, const PointIncrement& inc) const noexcept { return update_(*this, state, inc); }

    // The words for a fault that update() returned for this state (as passed in, so unchanged) and
    // increment: what went wrong, with the values that show it. Empty when result.fault is none.
    std::string fault_message(const PointState& state, const PointIncrement& inc, const PointResult& result) const;

    const Material& material() const { return *material_; }
    double reference_bulk_modulus() const { return reference_bulk_; }  // K, K1 or rho0 c0^2, Pa

private:
    using Update = PointResult (*)(const PointModel&, PointState&, const PointIncrement&) noexcept;
    const Material* material_;
    double reference_bulk_;
    Update update_;
};

}  // namespace gpa::materials
