#pragma once
// What a snapshot holds: the node fields a scene asks for (`[output] fields`) and the width of
// its floating-point arrays (`[output] precision`). The writers are in io/ (vtk.hpp); the choice is
// part of the scene, so that a study's refined runs and a resumed run write what the first did.

#include <cstdint>
#include <string_view>
#include <vector>

namespace gpa {

enum class SnapshotField : std::uint8_t {
    Velocity,          // m/s, 3 components
    Force,             // N, 3 components (a ring's force in axisymmetric geometry)
    Alpha,             // geometry factors (Eq. 14, 15), 3 components
    Pressure,          // P from the equation of state, Pa
    ViscousPressure,   // nodal artificial viscosity Q (Eq. 36), Pa
    VonMisesStress,    // sqrt(3/2 s:s), Pa
    Stress,            // Cauchy stress s - P I, Pa, as a VTK symmetric tensor (XX, YY, ZZ, XY, YZ, XZ)
    PlasticStrain,     // equivalent plastic strain
    PlasticWork,       // accumulated specific plastic work, J/kg
    Temperature,       // K
    Damage,            // Johnson-Cook damage D, written in [0, 1]
    Failed,            // 1 once the node has failed (UInt8)
    VolumetricStrain,  // V/V0 - 1 (Eq. 13)
    Density,           // m/V, kg/m^3
    InternalEnergy,    // specific, J/kg
    Displacement,      // x - x0, m, 3 components
    InitialPosition,   // x0, m, 3 components
    Diameter,          // d (Eq. 3), m
    Mass,              // kg (a ring's mass in axisymmetric geometry)
    Connectivity,      // 1 variable, 0 fixed (UInt8)
    Body,              // index of the scene's body (Int32)
    Material,          // index of the scene's material (Int32)
    PrescribedVelocity,  // 0 free; k + 1 held by the scene's [[prescribed_velocity]] k (UInt8)
};

enum class SnapshotPrecision : std::uint8_t { Float64, Float32 };

struct SnapshotFormat {
    std::vector<SnapshotField> fields;  // in the order written; the id and the positions are always written
    SnapshotPrecision precision = SnapshotPrecision::Float64;
};

// Every field in catalogue order, and the default choice (every field but the initial position,
// which the displacement and the position give, and the plastic work).
std::vector<SnapshotField> all_snapshot_fields();
std::vector<SnapshotField> default_snapshot_fields();

// The array name in a snapshot ("von_mises_stress") and back; false for an unknown word.
std::string_view name_of(SnapshotField f);
bool snapshot_field_of(std::string_view word, SnapshotField& out);

}  // namespace gpa
