#include "gpa/engine/snapshot_fields.hpp"

#include <algorithm>

namespace gpa {

namespace {

struct FieldName {
    SnapshotField field;
    std::string_view word;
};

constexpr FieldName field_names[] = {
    {SnapshotField::Velocity, "velocity"},
    {SnapshotField::Force, "force"},
    {SnapshotField::Alpha, "alpha"},
    {SnapshotField::Pressure, "pressure"},
    {SnapshotField::ViscousPressure, "viscous_pressure"},
    {SnapshotField::VonMisesStress, "von_mises_stress"},
    {SnapshotField::Stress, "stress"},
    {SnapshotField::PlasticStrain, "plastic_strain"},
    {SnapshotField::PlasticWork, "plastic_work"},
    {SnapshotField::Temperature, "temperature"},
    {SnapshotField::Damage, "damage"},
    {SnapshotField::Failed, "failed"},
    {SnapshotField::VolumetricStrain, "volumetric_strain"},
    {SnapshotField::Density, "density"},
    {SnapshotField::InternalEnergy, "internal_energy"},
    {SnapshotField::Displacement, "displacement"},
    {SnapshotField::InitialPosition, "initial_position"},
    {SnapshotField::Diameter, "diameter"},
    {SnapshotField::Mass, "mass"},
    {SnapshotField::Connectivity, "connectivity"},
    {SnapshotField::Body, "body"},
    {SnapshotField::Material, "material"},
    {SnapshotField::PrescribedVelocity, "prescribed_velocity"},
};

}  // namespace

std::vector<SnapshotField> all_snapshot_fields() {
    std::vector<SnapshotField> all;
    for (const auto& e : field_names) all.push_back(e.field);
    return all;
}

std::vector<SnapshotField> default_snapshot_fields() {
    std::vector<SnapshotField> fields = all_snapshot_fields();
    std::erase_if(fields, [](SnapshotField f) { return f == SnapshotField::InitialPosition || f == SnapshotField::PlasticWork; });
    return fields;
}

std::string_view name_of(SnapshotField f) {
    for (const auto& e : field_names) {
        if (e.field == f) return e.word;
    }
    return "?";
}

bool snapshot_field_of(std::string_view word, SnapshotField& out) {
    for (const auto& e : field_names) {
        if (e.word == word) {
            out = e.field;
            return true;
        }
    }
    return false;
}

}  // namespace gpa
