#pragma once
// Gauges: material points of a particle body whose fields are recorded over a run, as the
// history nodes and gauges of impact codes do (a stress or velocity history at a point, the
// free-surface velocity of a spall plate, the signal a VISAR records).
//
// A gauge is a set of nodes chosen once, by their positions at t = 0, and followed by their node
// ids (node_store.hpp) wherever the run moves or reorders them:
//
//   point         the node nearest to `at` (ties: the lowest id), which must be within a cell of
//                 it; with a radius, every node within it, its fields averaged with the nodes'
//                 masses as weights (a weighted point).
//   free surface  a spot on a body's face whose outward normal is `normal` (an axis and a sign):
//                 the nodes of the outermost row along the normal (within half a cell of the
//                 outermost node) among those whose distance from `at` across the normal is at
//                 most `radius` (0: the nodes nearest to `at` across the normal, one column, within
//                 a cell of it); `at` must lie on that face (within a cell of the nodes' outer
//                 edge), and the gauge names its body (a face may lie under another body). Its
//                 normal_velocity is the mass-weighted mean velocity along the outward normal,
//                 the free-surface velocity of a plate-impact or spall experiment.
//
// Every field of a gauge with several nodes is their mass-weighted mean. The stress is the
// material's Cauchy stress s - P I (the artificial viscosity is not part of it).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/geometry.hpp"

namespace gpa {

class NodeStore;
struct Scene;

enum class GaugeKind { Point, FreeSurface };

enum class GaugeField {
    Position,          // current position of the gauge (m), per component
    Displacement,      // position less the position at t = 0 (m), per component
    Velocity,          // m/s, per component
    NormalVelocity,    // free surface only: velocity along the outward normal (m/s)
    Pressure,          // P (Pa), positive in compression
    VonMises,          // von Mises stress of the deviator (Pa)
    Stress,            // Cauchy stress s - P I (Pa): 2D xx, zz, xz and the out-of-plane component; 3D xx, yy, zz, yz, xz, xy
    PlasticStrain,     // equivalent plastic strain
    Temperature,       // K
    Density,           // mass / volume (kg/m^3)
    InternalEnergy,    // specific internal energy (J/kg)
    Damage,            // Johnson-Cook damage D, each node's at most 1
    VolumetricStrain,  // V / V0 - 1
};

// The scene-file word of a field ("velocity", "von_mises", ...), and the field of a word.
std::string_view name_of(GaugeField f);
bool gauge_field_of(std::string_view word, GaugeField& out);
// Every field's word, in the order of the enum (for messages and docs).
std::vector<std::string_view> gauge_field_words();

struct GaugeSpec {
    std::string name;  // names the gauge's file (gauge_<name>.csv): letters, digits, '-' and '_'
    GaugeKind kind = GaugeKind::Point;
    std::array<double, 3> at{0.0, 0.0, 0.0};  // m (2D: x, z in the first two)
    std::string body;                           // a particle body's name; empty: any particle body
    double radius = 0.0;                        // m; 0: a single node (point) or one column (free surface)
    int normal_axis = -1;                       // free surface: the axis of the outward normal (0..dim-1)
    int normal_sign = +1;                       // free surface: +1 or -1
    std::vector<GaugeField> fields;             // empty: default_gauge_fields(kind)
};

// velocity, pressure, von_mises, plastic_strain, temperature (and normal_velocity first for a free
// surface).
std::vector<GaugeField> default_gauge_fields(GaugeKind kind);

// An error in one gauge of a scene (its index: which [[gauge]] table).
class GaugeError : public EntryError {
public:
    using EntryError::EntryError;
};

// The rules a gauge must follow before any node exists (validate_scene calls it): a file-safe
// name unique in the scene, a known particle body (required for a free surface), a radius >= 0 and
// finite, a normal for a free surface only, within the geometry's axes and not towards the axis of
// an axisymmetric scene, normal_velocity on free surfaces only, no field twice. Throws GaugeError naming the gauge.
void validate_gauges(const Scene& scene);

// One gauge placed on the nodes of a run: the ids of its nodes and how it reads them.
class Gauge {
public:
    // Chooses the gauge's nodes among the real nodes [0, real) by their initial positions (so that
    // placing it again on a resumed run chooses the same ones). Throws InputError naming the gauge
    // when no node qualifies (a point more than a cell from every node, no node of the body within
    // the radius, a free-surface point that is not on the body's face).
    Gauge(const GaugeSpec& spec, const Scene& scene, const NodeStore& nodes, std::size_t real);

    const GaugeSpec& spec() const { return spec_; }
    // The ids of its nodes, ascending.
    const std::vector<std::uint32_t>& node_ids() const { return ids_; }
    // Column names with units, e.g. "velocity_z_m_s", one per value read() returns.
    std::vector<std::string> columns() const;
    // The fields' current values (mass-weighted means over the gauge's nodes), in the order of
    // columns(). Finds its nodes by id among [0, real); InputError if one is gone.
    std::vector<double> read(const NodeStore& nodes, std::size_t real);

private:
    GaugeSpec spec_;
    GeometryKind geometry_;
    std::vector<std::uint32_t> ids_;
    std::vector<std::size_t> index_;  // where each id was last found (rechecked at every read)
};

}  // namespace gpa
