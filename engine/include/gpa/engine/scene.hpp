#pragma once
// A scene: everything a run needs, as a plain C++ value. io/ turns scene files into one; an
// embedding program can build one in code. All quantities SI.
//
// Coordinates follow the engine: in 2D, component 0 is x (radial in axisymmetric geometry) and
// component 1 is z (axial); in 3D, (x, y, z). Arrays of 3 use the first dim entries.

#include <array>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/gauges.hpp"
#include "gpa/engine/geometry.hpp"
#include "gpa/engine/node_set.hpp"
#include "gpa/engine/orientation.hpp"
#include "gpa/engine/snapshot_fields.hpp"
#include "gpa/engine/surface.hpp"
#include "gpa/engine/weights.hpp"
#include "gpa/materials/material.hpp"

namespace gpa {

enum class ConnectivityMode {
    Fixed,      // lattice neighbours for the whole run
    Variable,   // all nodes within 2 h_ij, re-found every step
    Automatic,  // start fixed, switch a node to variable when its plastic strain exceeds a threshold
};

enum class ViscosityKind { None, Nodal, Bond };

enum class Normalisation {
    PerDirection,  // the paper's geometry factors alpha_b = 1 / sum_j R W l_b^2 (Eq. 14-15, 51-53)
    MomentMatrix,  // the inverse of the full moment matrix (spec section 7): exact for every affine field
};

enum class SmoothingMode {
    Off,
    Everywhere,  // every node is a smoothing centre
    Tension,     // only nodes with negative pressure (paper section 7)
};

enum class ShapeKind {
    Cylinder,   // axis along z. Axisymmetric: on the axis, x in (0, radius). Plane strain: x in
                // (x0 - radius, x0 + radius). 3D: a circular cylinder around (x0, y0).
    Plate,      // the same as a cylinder (a short, wide one); kept as its own word for scenes
    Rectangle,  // 2D: x in (x0, x0 + size_x), z in (z0, z0 + size_z)
    Box,        // 3D: a box from origin to origin + size
    Sphere,     // centre `origin`, `radius` (a disc in plane strain; a sphere on the axis in axisymmetric)
    Surface,    // 3D: the inside of a closed triangulated surface (BodySpec::surface), moved by `origin`
    Nodes,      // nodes imported with their positions and sizes (BodySpec::node_set), moved by `origin`
};

// The scene-file word of a shape ("cylinder", ...), and whether it is round (has a radius).
std::string_view name_of(ShapeKind s);
bool is_round(ShapeKind s);

// How a body is discretised: a lattice of GPA particles, or explicit Lagrangian finite elements
// (quadrilaterals of four crossed triangles with mean dilatation, 2D only; docs/elements.md),
// meshed from the same shape at the same spacing.
enum class Discretisation { Particles, Elements };

std::string_view name_of(Discretisation d);

// How a lattice fills a shape's boundary cells (docs/scene-format.md, `fill`): `Centres` keeps the
// cells whose centre lies inside (the staircase of the paper's lattices); `Trimmed` makes every
// cell the shape covers in part a node of that part (its centroid, its volume), slivers merged
// into a neighbour (LatticeBlock::trim): the body's outline and mass are the shape's. `Rings`
// (3D cylinders and plates, variable connectivity) has no cubic lattice: layers along the axis,
// each of concentric rings of nodes about it (bodies.hpp, ring_fill), so that the body has no
// lattice directions across its section, as the 2D axisymmetric discretisation has none.
enum class CellFill { Centres, Trimmed, Rings };

// The shaped end of a cylinder: a projectile's nose (Borvik et al. fired blunt, hemispherical and
// conical ones; tangent ogives are the usual long-rod and bullet shape). The nose is part of the
// cylinder's `length`, at its lower z end (end = -1, a projectile flying towards -z) or its upper.
// Its cross-section's radius at distance s from the nose's base, R the cylinder's radius and L the
// nose length:
//   cone        r = R (1 - s / L)
//   hemisphere  r = sqrt(R^2 - s^2),                   L = R
//   ogive       r = sqrt(rho^2 - s^2) - (rho - R),     L = sqrt(rho^2 - (rho - R)^2)
// the ogive tangent to the shank, of arc radius rho = calibre_radius * 2 R (its "calibre radius
// head", CRH; >= 0.5, where 0.5 is the hemisphere). In plane strain the same profile bounds a slab
// (a wedge, a half disc).
enum class NoseKind { Cone, Hemisphere, Ogive };

struct NoseSpec {
    NoseKind kind = NoseKind::Cone;
    double length = 0.0;          // cone: given (m); hemisphere and ogive: 0 (nose_length gives it)
    double calibre_radius = 0.0;  // ogive only: rho / (2 R)
    int end = -1;                 // -1: at the lower z end, +1: at the upper
};

std::string_view name_of(NoseKind k);

// The nose's length along z (NoseSpec), for a cylinder of radius `radius`.
double nose_length(const NoseSpec& nose, double radius);

struct BodySpec {
    std::string name;
    Discretisation discretisation = Discretisation::Particles;
    ShapeKind shape = ShapeKind::Cylinder;
    // Cylinder/plate: origin is the centre of the base (lower z end); Rectangle/box: lower
    // corner; Sphere: centre. Axisymmetric cylinders, plates and spheres must have origin x = 0.
    std::array<double, 3> origin{0, 0, 0};

    std::array<double, 3> size{0, 0, 0};  // rectangle/box
    double radius = 0.0;                  // cylinder/plate/sphere
    // Sphere only: the radius of a hollow core, 0 = solid. A hollow sphere in 3D and in axisymmetric
    // geometry, an annulus (a ring) in plane strain.
    double inner_radius = 0.0;
    double length = 0.0;                  // cylinder/plate, along z (a nose included)
    std::optional<NoseSpec> nose;         // cylinder only: its shaped end; none = flat ends
    // Surface only: the file it was read from, as the scene names it (io::resolve_scene_files reads
    // it, relative to the scene file's folder), the length unit of the file's numbers in metres,
    // and the surface with its inside test, in metres before the body's origin is added (null until
    // it is read).
    std::string surface_file;
    double surface_unit = 1.0;
    std::shared_ptr<const SurfaceInside> surface;
    // Nodes only: the nodes, in metres before the origin is added (null until read). The file and
    // its unit are surface_file and surface_unit, as for a surface. Such a body has no lattice:
    // `spacing` is not used (nominal_spacing gives the nodes' median diameter), its nodes have
    // variable connectivity, and it is discretised with particles.
    std::shared_ptr<const NodeSetShape> node_set;
    double spacing = 0.0;                 // lattice spacing dx (and dy, dz in 3D)
    double spacing_z = 0.0;               // 2D: dz; 0 = equal to dx
    std::string material;                 // a name in Scene::materials
    std::array<double, 3> velocity{0, 0, 0};
    // Initial Cauchy stress in NodeStore order (2D: xx, zz, xz, out-of-plane; 3D: xx, yy, zz, yz,
    // xz, xy). Its deviator becomes s; its mean stress becomes an initial compression through the EOS.
    std::array<double, 6> initial_stress{0, 0, 0, 0, 0, 0};
    // The body turned about its origin (orientation.hpp): the point x of the shape as described
    // above lies at origin + R (x - origin); its lattice, nose and imported nodes turn with it, so
    // that a cylinder's axis is R e_z. `velocity` and `initial_stress` are in the scene's axes.
    // Particles in plane strain and 3D only (the identity elsewhere).
    Rotation rotation = identity_rotation;
    std::optional<ConnectivityMode> connectivity;  // overrides SolverOptions::connectivity (particles only)
    int lattice_neighbours = 0;                    // fixed lists: 4/8 (2D), 6/18/26 (3D); 0 = 8 or 26 (particles only)
    std::optional<CellFill> fill;                  // lattice bodies of particles; unset: cell_fill's default
};

// The fill of body b's lattice in a scene of geometry g: b.fill when given; otherwise `Trimmed` for
// a 3D cylinder, plate or sphere (whose cubic staircase measurably widens a Taylor bar's footprint,
// docs/validation.md) and `Centres` for the rest.
CellFill cell_fill(const BodySpec& b, GeometryKind g);

// The radius of cylinder (or plate) b's cross-section at `height` above its base (z minus the
// origin's z): b.radius along the shank, the nose's profile (NoseSpec) over the nose, 0 outside
// [0, length]. A lattice node belongs to the body when its cell centre lies within it
// (docs/scene-format.md).
double cylinder_radius_at(const BodySpec& b, double height);

// A body's node size as given: its lattice spacing dx (`spacing`), or for imported nodes their
// median diameter (0 before they are read).
double nominal_spacing(const BodySpec& b);

enum class PlaneKind {
    Rigid,     // a rigid wall; pushes only unless lift_off is false; frictionless unless given friction
    Symmetry,  // a mirror plane; ghost pairs always act
};

// A plane with ghost (mirror) nodes (spec section 7). The axis of an axisymmetric scene is a
// symmetry plane of its own and is not listed. Its normal is a coordinate axis (`axis`) or, in
// plane strain and 3D, any direction (`axis` = -1 and `normal`; plane_normal gives either).
struct PlaneSpec {
    std::string name;
    PlaneKind kind = PlaneKind::Rigid;
    int axis = 1;           // normal direction: 0 = x, 1 = z in 2D; 0, 1, 2 = x, y, z in 3D; -1: `normal`
    std::array<double, 3> normal{0, 0, 0};  // axis = -1 only: the unit normal (first dim components)
    double position = 0.0;  // coordinate of the plane along `axis`; for axis = -1, n . x of its points
    int side = +1;          // the bodies lie where the coordinate (n . x) is above (+1) or below (-1) the plane
    bool lift_off = true;   // rigid only: false = the paper's no-lift-off (nodes on it may not leave)
    // Rigid only: Coulomb friction (RigidPlanes::apply_friction). A node the plane pushes with N
    // sticks while the tangential force that would stop it is at most friction_static N, and
    // slides against a force friction_dynamic N otherwise; 0 and 0: frictionless.
    double friction_static = 0.0;
    double friction_dynamic = 0.0;
};

// The unit normal of a plane: e_axis, or `normal` for axis = -1 (as given; validate_scene checks it
// is a unit vector).
std::array<double, 3> plane_normal(const PlaneSpec& p);

// Nodes of one body held at a prescribed velocity (a grip, a clamp, a piston): every node of
// `body` inside the region at t = 0 keeps, in each prescribed component, the velocity
//   v(t) = value * min(t / ramp, 1)   (ramp > 0: a linear ramp from 0, then constant)
//   v(t) = value                      (ramp = 0)
// from t = 0 on; the other components move freely. The region is the nodes whose initial
// position p has lower[c] <= p[c] <= upper[c] on every axis and a distance from the body's axis
// within [radius_min, radius_max]. The body's axis is the line along z through the centre of its
// extent across z (for cylinders, plates and spheres their own axis; in axisymmetric geometry
// x = 0, so the distance is x). The force the nodes need to follow the motion is the region's
// reaction; its work is booked as boundary work (simulation.hpp, Totals::regions).
struct PrescribedVelocitySpec {
    std::string name;
    std::string body;  // a name in Scene::bodies
    std::array<double, 3> lower{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
    std::array<double, 3> upper{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
                                std::numeric_limits<double>::infinity()};
    double radius_min = 0.0;
    double radius_max = std::numeric_limits<double>::infinity();
    std::array<std::optional<double>, 3> velocity;  // m/s per component (first dim entries); empty = free
    double ramp = 0.0;                              // s
};

// Which form of the momentum equation gives the stress forces (spec section 5, docs/surfaces.md).
enum class ForceForm {
    Pairwise,          // Eq. 21-24 (the paper's Eq. 29): equal and opposite pair forces from each centre's stress
    StressDifference,  // Eq. 28: F_i = V_i div(sigma) at i, gathered from sigma_j - sigma_i over i's row
};

// How the internal energy follows the stress (spec section 5, "[spec] Compatible energy").
enum class EnergyUpdate {
    Compatible,  // the work of each node's stress forces at the mean velocities of the velocity update
    Point,       // the point update's own mid-step energy equation (materials.md; not exactly conservative)
};

// How a particle node's diameter d (the length of Eq. 2's h_ij = a (d_i + d_j) / 2) follows the
// deformation (spec section 2; docs/validation.md, "Local fields at the impact face").
enum class NodeDiameter {
    // d = d0 sqrt(V / V0) in 2D, d0 (V / V0)^(1/3) in 3D: the node's volume alone ([spec] entry of
    // issue 13). In axisymmetric geometry this leaves out Eq. 3's factor x0 / x.
    Volume,
    // Eq. 3 as printed: d = d0 sqrt((1 + eps_v) x0 / x) in axisymmetric geometry (the ring's
    // section), the same as Volume otherwise.
    Section,
    // d = d0 sqrt((1 + eps_v) max(x / x0, x0 / x)) in axisymmetric geometry: the hoop stretch
    // lambda = x / x0 enlarges the support whichever way it goes; the same as Volume otherwise.
    Hoop,
    // 3D: d = d0 (V / V0)^(1/3) lambda, lambda the largest principal stretch of the node's
    // volume-preserving deformation (kernels.hpp, largest_isochoric_stretch), so that the support
    // reaches the neighbours of the most stretched direction as it did on the initial lattice; a
    // failed node's follows its volume alone. In 2D the same as Hoop (the hoop stretch is the one
    // an axisymmetric node carries). The default.
    Stretch,
};

// The hourglass control's fit around a centre (SolverOptions::hourglass_fit): affine, or with the
// second derivatives too.
enum class HourglassFitOrder { Linear, Quadratic };

// Which nodes the hourglass damping (hourglass_coefficient) acts on (docs/validation.md, "The face
// pairs in the hoop direction").
enum class HourglassNodes {
    // Every node in 3D, the lattice regime in 2D (hourglass_damps_every_node): the face's pairing
    // needs a discretised hoop direction, which axisymmetric bodies do not have. The default.
    Automatic,
    // The lattice regime: fixed nodes, and variable nodes whose plastic strain is below
    // switch_plastic_strain.
    Lattice,
    // Every node that has not failed (its pairs with its own body), however far it has flowed: in
    // 3D it holds the pairing of an impact face's nodes under hoop tension, which the lattice regime
    // leaves alone.
    All,
};

struct SolverOptions {
    ConnectivityMode connectivity = ConnectivityMode::Variable;
    double switch_plastic_strain = 0.1;  // Automatic: switch at this equivalent plastic strain
    double influence_distance = 1.0;     // a, 0.8-1.5 (Eq. 2)
    NodeDiameter node_diameter = NodeDiameter::Stretch;
    WeightKind weight = WeightKind::Gpa;
    Normalisation normalisation = Normalisation::PerDirection;
    // The paper's correction at free surfaces and interfaces (its section 2.5): the geometry factor
    // normal to a one-sided neighbourhood halved (kernels.hpp, OneSidedMoments; docs/surfaces.md).
    bool surface_correction = false;
    // Eq. 29 (pairwise) or Eq. 28 (stress differences; no equal and opposite forces, so momentum is
    // not conserved; no bond viscosity; the internal energy follows the point update's energy
    // equation whatever energy_update says, there being no pair forces whose power the compatible
    // update could book). Unstable in every impact measured: a mode grows from the free surfaces
    // within microseconds (docs/surfaces.md); for study, not for results.
    ForceForm force_form = ForceForm::Pairwise;
    ViscosityKind viscosity = ViscosityKind::Nodal;
    double viscosity_linear = 0.2;     // C_L (Eq. 36, 37)
    double viscosity_quadratic = 4.0;  // C_Q
    double bond_viscosity_eps0 = 0.01; // Eq. 38
    // C_hg of the zero-energy-mode control (hourglass.hpp, spec section 2): 0 = off. It acts on the
    // nodes of hourglass_nodes.
    double hourglass_coefficient = 0.1;
    HourglassNodes hourglass_nodes = HourglassNodes::Automatic;
    // The damping's fit: the affine velocity field around the centre (linear), or one with its
    // second derivatives too (quadratic), which leaves smooth curved flow alone.
    HourglassFitOrder hourglass_fit = HourglassFitOrder::Linear;
    // C_hs of the stiffness form of the control (kernels.hpp, hourglass_stiffness): on fixed nodes,
    // forces against the non-affine part of the lattice pairs' displacement since t = 0, which the
    // damping alone cannot hold under tension (docs/tension.md). 0 = off.
    double hourglass_stiffness = 0.0;
    // The stiffness form on the flowing nodes the damping controls (hourglass_nodes), against a
    // reference that relaxes towards the current positions with this time constant, s (kernels.hpp,
    // hourglass_stiffness). 0: the stiffness acts on fixed nodes only.
    double hourglass_stiffness_relaxation = 0.0;
    SmoothingMode smoothing = SmoothingMode::Off;
    double smoothing_coefficient = 0.1;  // C_cs (Eq. 67)
    // C_cfl of the stable time step (spec section 11). The largest value found stable: 0.6 (the
    // paper's Armco cylinder at 8 and 20 nodes across the radius, OFHC copper at 190 m/s); 0.7 fails.
    double cfl = 0.4;
    // Upper bound on the geometry factors, alpha_b <= alpha_limit / W_i (0 = none, the paper's
    // method). A node whose neighbours along one axis have all drifted to the edge of its radius
    // of influence gets an unbounded alpha and explodes; on a regular lattice alpha W is 0.63 in
    // the interior, 1.26 at a flat surface and 1.55 at a corner, so the default 3 leaves those alone.
    double alpha_limit = 3.0;
    double max_time_step = std::numeric_limits<double>::infinity();  // s
    double time_step_growth = 1.1;       // largest ratio of one step to the previous
    // Largest fraction by which one step may change a node's volume, dt <= this / |eps_v_dot|
    // (compression always, expansion while the pressure is positive; spec section 11): a node
    // squeezed by a large fraction in one step gets its pressure a step late, and the work booked
    // on the way in falls short of the work given back on the way out (0 = no limit).
    double max_volume_change = 0.1;
    bool failure = false;                // apply the materials' failure models (J-C damage, spall)
    // With failure: a pair with a failed node may open like a pair between bodies (separation.hpp),
    // so that a crack has free faces; false keeps such pairs like any other.
    bool separate_failed = true;
    // Closed separable pairs (contacts between bodies, cracks) carry only normal velocity
    // differences and forces: frictionless sliding (spec section 2, "[spec] Sliding contact";
    // docs/contact.md). false: they act like any other pair, shear included (the surfaces stick).
    bool sliding_contact = true;
    EnergyUpdate energy_update = EnergyUpdate::Compatible;
    ScatterScheme scatter = ScatterScheme::Slabs;
    std::size_t reorder_interval = 200;  // steps between locality reorderings (0 = never)
    // Neighbour lists with a skin (Verlet lists): the search keeps every pair within
    // 2 h_ij + skin, skin = neighbour_skin times the largest interaction radius, and is repeated
    // only when nodes have moved (or grown) enough that a pair could have closed by the skin; in
    // between, each step cuts the candidates to r_ij < 2 h_ij. 0 = a full search every step. The
    // lists are the same either way; only the order of a row's entries may differ.
    double neighbour_skin = 0.25;
    // For tests: after every step's cut of the candidates, search all pairs afresh and throw
    // NumericalError if the lists differ as sets (slow; not read from scene files).
    bool check_neighbour_lists = false;

    // Member by member, for tests that a scene file and a study variant give the same options.
    bool operator==(const SolverOptions&) const = default;
};

struct StopCriteria {
    double end_time = 0.0;                 // s; 0 = no time limit
    double kinetic_energy_fraction = 0.0;  // stop when KE < fraction * initial KE; 0 = off
    std::size_t max_steps = 0;             // 0 = no limit
    // The energy guard: a run whose energy error |KE + IE + boundary work - E0| / E0 exceeds this
    // stops as a numerical failure (an unstable run). The scenes of scenes/ end at 0.1-0.6 % at
    // the default C_cfl (docs/cfl-range.md); a sphere through a plate was reported at 1.8 % (issue 14). 0 = no guard.
    double energy_error = 0.03;
};

struct OutputOptions {
    std::size_t snapshots = 20;      // ParaView snapshots over the run, first and last included (0 or 1: those two only)
    double snapshot_interval = 0.0;  // s; > 0 overrides `snapshots`
    std::size_t history_every = 10;  // steps between history rows (the last step is always written)
    // Checkpoints of a run (gpa run --resume): every this many steps, or every this much wall-clock
    // time (s); 0 = never (a run still writes one when it is interrupted).
    std::size_t checkpoint_every_steps = 0;
    double checkpoint_every_seconds = 600.0;
    // Radius of the neighbourhood over which local peaks (plastic strain, temperature) are averaged
    // (measure.hpp), m; 0 = twice the first body's spacing. The scene reader fixes it from the scene
    // as written, so that a study's refined runs keep one radius.
    double peak_radius = 0.0;
    // The arrays of every snapshot and the width of their floats (snapshot_fields.hpp).
    SnapshotFormat snapshot_format{default_snapshot_fields(), SnapshotPrecision::Float64};
};

struct Scene {
    std::string name;
    std::string description;
    GeometryKind geometry = GeometryKind::Axisymmetric;
    std::vector<materials::Material> materials;
    std::vector<BodySpec> bodies;
    std::vector<PlaneSpec> planes;
    std::vector<PrescribedVelocitySpec> prescribed_velocities;
    // Material points recorded over the run (gauges.hpp); the run loop places and writes them.
    std::vector<GaugeSpec> gauges;
    SolverOptions solver;
    StopCriteria stop;
    OutputOptions output;
    // Known answers the scene states, reported beside the run's own values, e.g.
    // "final_length" and "footprint_diameter" (m) of a Taylor test. Keys are free-form words.
    std::map<std::string, double> reference;
    std::string reference_source;
    // [reference] elements: the file of the scene's element reference (gpa study --reference), as
    // written; relative paths are taken from the scene file's folder (io::load_scene resolves them).
    std::string element_reference;
};

// The stiffness form acts on flowing nodes too, against a relaxing reference
// (SolverOptions::hourglass_stiffness_relaxation).
inline bool relaxing_stiffness(const SolverOptions& solver) {
    return solver.hourglass_stiffness > 0.0 && solver.hourglass_stiffness_relaxation > 0.0;
}

// Whether the hourglass damping acts on every node (SolverOptions::hourglass_nodes), the automatic
// choice resolved by the scene's geometry.
inline bool hourglass_damps_every_node(const SolverOptions& solver, GeometryKind geometry) {
    if (solver.hourglass_nodes == HourglassNodes::Automatic) return geometry == GeometryKind::ThreeD;
    return solver.hourglass_nodes == HourglassNodes::All;
}

// Throws InputError naming the body, plane or option when the scene is impossible (no bodies,
// a body with a non-positive size or spacing, an unknown material name, a plane on a body's
// wrong side, an option out of its range, a missing end condition, ...).
// The checks of one prescribed-velocity region fail with this error (its index says which entry, so
// that a scene reader can name the line): an unknown body, no component, a negative ramp, a region
// outside the body or holding none of its nodes, two regions sharing a node, a region that would
// move nodes through a plane they touch.
class PrescribedVelocityError : public EntryError {
public:
    using EntryError::EntryError;
};

void validate_scene(const Scene& scene);

// The scene turned by `rotation` about the origin (orientation.hpp; plane strain and 3D): every
// body's origin, rotation, velocity and initial stress, every plane's normal (its position, n . x,
// is unchanged) and every point gauge. The run of the rotated scene is the run of the scene seen
// in turned axes, up to what the method takes in the global frame (the per-direction
// normalisation). Throws InputError for an axisymmetric scene, a rotation that is not one
// (rotation_problem), prescribed-velocity regions (boxes in the scene's axes) and free-surface
// gauges (an axis-aligned normal), which do not turn.
Scene rotated_scene(const Scene& scene, const Rotation& rotation);

// Whether scene.planes[plane] is a symmetry plane that passes through scene.bodies[body] (the
// body's shape reaches beyond it on both sides; touching is not cutting). Such a body is filled on
// the plane's side only and the plane's ghosts continue it across: a half model, or a quarter one
// with two such planes (docs/scene-format.md). False for a plane that is not valid.
bool symmetry_plane_cuts(const Scene& scene, std::size_t body, std::size_t plane);

// Whether body `body` reaches symmetry plane `plane`: the plane cuts it or the body touches it. The
// model is then half of a body mirrored across the plane, and the body's widths are measured with
// its mirror image (measure.hpp).
bool reaches_symmetry_plane(const Scene& scene, std::size_t body, std::size_t plane);

// How many copies of body `body` the symmetry planes it reaches make of the whole: 2 to the number
// of such planes with distinct normals (1 without any, 2 a half model, 4 a quarter). The model's
// masses, energies and momenta are those of one copy; its widths are measured on the whole.
int symmetry_copies(const Scene& scene, std::size_t body);

// Values a valid scene may hold but an impact simulation hardly ever does, most often a unit
// slip ("190 km/s" for 190 m/s, "10 m" for 10 mm): a body faster than 20 km/s (light-gas guns
// reach about 10 km/s, orbital debris 15 km/s), a body smaller than 10 um or larger than 10 m
// across, an end time beyond 0.1 s (impacts last micro- to milliseconds). One message per finding,
// naming the body or key, its value and what to check; empty when nothing is odd. They are
// warnings (gpa check and gpa run print them), never refusals: such a scene may be meant. Also
// one combination of options that works but less well than another: an oblique plane under the
// per-direction normalisation (docs/orientation.md).
std::vector<std::string> scene_warnings(const Scene& scene);

}  // namespace gpa
