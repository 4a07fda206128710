#include "gpa/engine/simulation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <utility>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/colouring.hpp"
#include "gpa/engine/drivers.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/ghosts.hpp"
#include "gpa/engine/hourglass.hpp"
#include "gpa/engine/kernels.hpp"
#include "gpa/engine/lattice_check.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/engine/parallel.hpp"
#include "gpa/engine/prescribed.hpp"
#include "gpa/engine/separation.hpp"
#include "gpa/engine/smoothing.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/engine/stress.hpp"
#include "gpa/engine/version.hpp"
#include "step/contact.hpp"
#include "step/energy_ledger.hpp"
#include "step/external_loads.hpp"
#include "step/neighbour_lists.hpp"
#include "step/measures.hpp"
#include "step/regions.hpp"
#include "step/rigid_planes.hpp"
#include "step/run_control.hpp"
#include "step/stable_step.hpp"
#include "step/switching.hpp"
#include "reduce_grain.hpp"

namespace gpa {

namespace {


}  // namespace

struct Simulation::Impl {
    Scene scene;
    ThreadScope threads;
    NodeStore nodes;
    std::size_t real = 0;
    GhostSet ghosts;
    RigidPlanes rigid_planes;  // reactions, impulses, the penetration guard (step/rigid_planes.hpp)
    MaterialGroups material_groups;
    NeighbourLists neighbour_lists;  // lists, skin cache, scatter plan (step/neighbour_lists.hpp)
    Contact contact;                 // separation and sliding state (step/contact.hpp)
    Switching switching_part;        // connectivity modes and the switching phase (step/switching.hpp)
    Measures measures;               // sums, extents, local fields, half-step energies (step/measures.hpp)
    SmoothingScratch smoothing_scratch;
    StableStep stable_step;          // the stable time step and its bond-viscous pressures (step/stable_step.hpp)
    bool failed = false;                 // a phase threw: the state is half-updated
    std::unique_ptr<PhaseGraph> graph;
    bool particles = true;                  // the scene has particle bodies (real > 0)
    std::unique_ptr<ElementPart> elements;  // the element bodies, if any (elements.hpp)
    double element_steps = 0.0;

    double time = 0.0;
    double dt_half = 0.0;  // dt^{n+1/2}: the step from t^n to t^{n+1}
    double dt_next = 0.0;  // dt^{n+3/2}
    std::size_t steps = 0;
    double node_steps = 0.0;
    Regions regions;      // prescribed-velocity regions (step/regions.hpp)
    EnergyLedger ledger;  // every booking of work and heat (step/energy_ledger.hpp)
    ExternalLoads external;  // an embedding program's forces and velocities between steps (step/external_loads.hpp)
    Totals totals;
    std::string stop_reason;

    // --- limits, failure reports and checkpoints (the last section of this file) ---------
    RunControl run_control;  // stop criteria, limits, failure reports (step/run_control.hpp)
    void write_state(StateWriter& out) const;
    void read_state(StateReader& in);

    Impl(Scene s, int thread_count, MemoryLimit memory)
        : scene(std::move(s)),
          threads(thread_count),
          nodes(scene.geometry),
          neighbour_lists(scene.solver),
          contact(scene),
          switching_part(scene),
          stable_step(scene),
          regions(scene.prescribed_velocities),
          ledger(scene.solver),
          run_control(scene, std::move(memory)) {}

    int dim() const { return nodes.dim(); }
    // a, checked once in setup (after validate_scene, whose message names the scene's key).
    std::optional<InfluenceDistance> influence;
    InfluenceDistance a() const { return *influence; }

    template <class G>
    void setup();
    template <class G>
    void build_phase_graph();

    // --- phases ---------------------------------------------------------------------------
    void move();
    void reorder();
    template <class G>
    void geometry();
    void neighbours();
    template <class G>
    void gradient();
    template <class G>
    void stress();
    void switching();
    void refresh_ghosts_and_plan();
    const CompressedRows& lists() const { return neighbour_lists.rows(); }
    const ScatterPlan& plan() const { return neighbour_lists.plan(); }
    void time_step();
    template <class G>
    void forces();
    template <class G>
    void integrate(double dt_avg);
    void integrate_elements(double dt_avg, double dt_next);
    template <class G>
    HourglassFields<G::dim> hourglass_control_fields(double* power, double* stiffness_power);
    template <class G>
    void smoothing();
    void sum_totals();
    const GhostPlane* first_rigid_plane() const { return rigid_planes.first(ghosts); }
    void regroup_materials();
};

template <class G>
void Simulation::Impl::setup() {
    // The scene was validated by the constructor, before its sizes were checked (once).
    influence.emplace(scene.solver.influence_distance);
    // Planes with ghosts: the axis of an axisymmetric scene first, then the scene's planes.
    std::vector<GhostPlane> planes;
    std::vector<std::size_t> rigid;
    std::vector<std::array<double, 2>> friction;
    if (G::axisymmetric) planes.push_back({"axis", 0, 0.0, +1, false, false});
    for (const auto& p : scene.planes) {
        if (p.kind == PlaneKind::Rigid) {
            rigid.push_back(planes.size());
            friction.push_back({p.friction_static, p.friction_dynamic});
        }
        planes.push_back({p.name, p.axis, p.position, p.side, p.kind == PlaneKind::Rigid && p.lift_off,
                          p.kind == PlaneKind::Rigid, p.kind == PlaneKind::Symmetry, p.axis < 0 ? p.normal : std::array<double, 3>{}});
    }
    ghosts = GhostSet(planes);
    rigid_planes.assign(std::move(rigid), std::move(friction));
    const auto mirrors = ghosts.mirror_planes();
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (scene.bodies[b].discretisation == Discretisation::Particles) add_body_nodes(nodes, scene, b, mirrors);
    }
    real = nodes.size();
    particles = real > 0;
    if (relaxing_stiffness(scene.solver)) nodes.carry_reference_positions();
    if (scene.solver.normalisation != Normalisation::MomentMatrix) nodes.drop_shear_normalisation();
    if (std::any_of(scene.bodies.begin(), scene.bodies.end(),
                    [](const BodySpec& b) { return b.discretisation == Discretisation::Elements; })) {
        elements = std::make_unique<ElementPart>(scene, mesh_element_bodies(scene), element_options(scene));
    }
    validate_nodes(nodes, 0, real);
    regions.assign(scene, nodes, real, elements ? &elements->mesh().nodes : nullptr);
    switching_part.prepare_lattices(scene, nodes, real, planes.size() - scene.planes.size());
    for (const auto& m : scene.materials) materials::validate(m);
    initialise_material_state(nodes, real, scene.materials);
    measures.set_up(scene, nodes, real);
    if (particles && scene.solver.reorder_interval > 0) reorder();
    regroup_materials();
    regions.index(nodes, real);
    if (!ExternalLoads::check_ids(nodes, real)) throw NumericalError("the nodes' ids are not 0 ... n - 1, each once");
    external.forget_ids();
    contact.set_up(real);
    neighbour_lists.set_up(!contact.separation() && ghosts.empty() && !needs_search(nodes, real) &&
                           !switching_part.any_automatic());

    // Geometry, neighbours, geometry factors and forces at t = 0; then the first half step.
    if (particles) {
        geometry<G>();
        neighbours();
        gradient<G>();
        refresh_ghosts_and_plan();
    }
    // The first step: dt from the initial state, velocities advance half a step (spec section 11).
    dt_half = 0.0;
    time_step();
    sum_totals();
    const double kinetic_at_start = measures.half_step_kinetic();
    const std::vector<double> body_kinetic_at_start = measures.body_half_step_kinetic();
    totals.initial_kinetic_energy = kinetic_at_start;
    totals.initial_energy = kinetic_at_start + totals.internal_energy;
    if (particles) forces<G>();
    integrate<G>(0.5 * dt_next);
    if (elements) {
        elements->compute_forces();
        integrate_elements(0.5 * dt_next, dt_next);
    }
    sum_totals();
    totals.kinetic_energy = kinetic_at_start;  // at t = 0: the initial velocities themselves
    for (std::size_t b = 0; b < totals.bodies.size(); ++b) totals.bodies[b].kinetic_energy = body_kinetic_at_start[b];
    totals.energy_error = 0.0;
    dt_half = dt_next;
    build_phase_graph<G>();
}

void Simulation::Impl::regroup_materials() {
    material_groups = group_by_material(nodes, real, scene.materials.size());
}

void Simulation::Impl::reorder() {
    nodes.resize(real);  // ghosts are rebuilt after every move
    neighbour_lists.invalidate();  // rebuilt in the new numbering by the neighbours phase; freed first
    const double cell = bulk_interaction_radius(nodes, a().value(), real);
    nodes.permute(locality_order(nodes, cell, 0, real));
    switching_part.forget_lattice_axes();
    external.forget_ids();  // made again at the next look-up
    regroup_materials();
    regions.index(nodes, real);
}

void Simulation::Impl::move() {
    neighbour_lists.forget_kept_pairs();  // kept at the old positions
    const int d = dim();
    const double dt = dt_half;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < d; ++c) {
            double* x = nodes.position[c].data();
            const double* v = nodes.velocity[c].data();
            for (std::size_t i = r.begin(); i != r.end(); ++i) x[i] = leapfrog_position(x[i], v[i], dt);
        }
    });
    if (relaxing_stiffness(scene.solver)) {
        const double tau = scene.solver.hourglass_stiffness_relaxation;
        // The stiffness form's reference relaxes towards the new positions, X_r += (x - X_r)(1 - e^(-dt / tau)),
        // one rate for every node so that an affine motion leaves the reference's offsets an affine image.
        const double share = -std::expm1(-dt / tau);
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real, 4096), [&](const tbb::blocked_range<std::size_t>& r) {
            for (int c = 0; c < d; ++c) {
                const double* x = nodes.position[c].data();
                double* ref = nodes.reference_position[c].data();
                for (std::size_t i = r.begin(); i != r.end(); ++i) ref[i] += (x[i] - ref[i]) * share;
            }
        });
    }
    regions.advance_displacements(dim(), dt);
    time += dt;
    rigid_planes.guard_penetration(ghosts, nodes, real, ledger);  // spec section 7
}

template <class G>
void Simulation::Impl::geometry() {
    // Node diameters (Eq. 3, or the rule of the solver's node_diameter: kernels.hpp) and size weights
    // (Eq. 4) at the new positions, with the volumes of the previous stress update; the gradient
    // and the next forces both use these.
    const NodeDiameter rule = scene.solver.node_diameter;
    const int diameter_rule = rule == NodeDiameter::Section ? 0 : rule == NodeDiameter::Volume ? 1 : rule == NodeDiameter::Hoop ? 2 : 3;
    const bool stretch = G::dim == 3 && rule == NodeDiameter::Stretch;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real, costly_node_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            double lambda = 1.0;
            if (stretch && !nodes.failed[i]) {  // a failed node is debris: its support follows its volume
                std::array<double, 6> b;
                for (int c = 0; c < 6; ++c) b[c] = nodes.left_cauchy_green[c][i];
                lambda = largest_isochoric_stretch(b);
            }
            nodes.diameter[i] = node_diameter<G>(nodes.initial_diameter[i], nodes.volumetric_strain[i],
                                                 nodes.initial_position[0][i], nodes.position[0][i], diameter_rule, lambda);
        }
        update_size_weights(nodes, r.begin(), r.end());
    });
    neighbour_lists.place_ghosts(nodes, real, ghosts, a(), steps == 0 && time == 0.0);
}

void Simulation::Impl::neighbours() {
    neighbour_lists.update(nodes, real, ghosts, a(), switching_part.any_automatic(), contact, steps);
}

template <class G>
void Simulation::Impl::gradient() {
    auto f = gradient_fields<G::dim>(nodes, a());
    f.pairs = contact.fields(f.pairs, nodes);
    f.alpha_limit = scene.solver.alpha_limit;
    f.full_normalisation = scene.solver.normalisation == Normalisation::MomentMatrix;
    f.surface_correction = scene.solver.surface_correction;
    f.allow_degenerate = true;  // a fragment that has lost its neighbours flies on (see fields.hpp)
    f.keep_weight_over_r2 = neighbour_lists.keep_pairs(real);  // for the sweeps after this one
    compute_velocity_gradient<G>(lists(), scene.solver.weight, f, real);
    neighbour_lists.pairs_kept(std::min(real, lists().rows()));
}

template <class G>
void Simulation::Impl::stress() {
    StressPhaseOptions o;
    o.nodal_viscosity = scene.solver.viscosity == ViscosityKind::Nodal;
    o.viscosity_linear = scene.solver.viscosity_linear;
    o.viscosity_quadratic = scene.solver.viscosity_quadratic;
    o.failure = scene.solver.failure;
    o.energy_booked_by_forces = ledger.compatible();
    o.left_cauchy_green = G::dim == 3 && scene.solver.node_diameter == NodeDiameter::Stretch;
    update_stresses<G>(nodes, real, scene.materials, material_groups, dt_half, o);
}

void Simulation::Impl::switching() {
    const Switching::Report report = switching_part.switch_nodes(scene, nodes, real);
    totals.collapse_switches = report.collapse_switches;
    totals.first_collapse_switch = report.first_collapse_switch;
}

void Simulation::Impl::refresh_ghosts_and_plan() {
    if (!ghosts.empty()) ghosts.refresh(nodes, real);
    neighbour_lists.refresh_plan(nodes);
}

void Simulation::Impl::time_step() {
    const double element_limit = elements ? elements->stable_time_step() : std::numeric_limits<double>::infinity();
    dt_next = stable_step.next(nodes, real, contact.closing_speed(), element_limit, time, dt_half);
}

template <class G>
void Simulation::Impl::forces() {
    auto f = force_fields<G::dim>(nodes, a());
    f.pairs = neighbour_lists.with_kept_pairs(contact.fields(f.pairs, nodes));
    f.hoop_count = real;
    f.full_normalisation = scene.solver.normalisation == Normalisation::MomentMatrix;
    f.stress_difference = scene.solver.force_form == ForceForm::StressDifference;
    BondViscosityParameters bond{scene.solver.viscosity_linear, scene.solver.viscosity_quadratic, scene.solver.bond_viscosity_eps0};
    const bool with_bond = scene.solver.viscosity == ViscosityKind::Bond;
    if (with_bond) {
        f.viscous_pressure = nullptr;
        f.bond_viscous_power = ledger.bond_power(nodes.size());
        f.largest_bond_viscosity = stable_step.bond_viscosity(nodes.size());
    }
    compute_forces<G>(lists(), plan(), scene.solver.weight, with_bond ? &bond : nullptr, f, nodes.size());
    if (ledger.hourglass()) {
        auto control = hourglass_control_fields<G>(ledger.hourglass_power(nodes.size()), ledger.stiffness_power(nodes.size()));
        ledger.keep_hourglass_fits<G::dim>(control, real);
        if (control.ghost_continues) ghosts.save_forces(nodes, real);
        apply_hourglass_control<G::dim>(lists(), plan(), control, real, scene.solver.hourglass_coefficient);
        if (control.ghost_continues) ghosts.fold_forces(nodes, real);  // a half or quarter model (ghosts.hpp)
    }
    rigid_planes.take_reactions(ghosts, nodes, real);
}

template <class G>
HourglassFields<G::dim> Simulation::Impl::hourglass_control_fields(double* power, double* stiffness_power) {
    // The hourglass control's fields (hourglass.hpp), its powers per centre into `power` and
    // `stiffness_power`.
    // The damping's regime: below the switching strain, or every node (an infinite bound) but the
    // failed ones, which are debris without a continuum to fit.
    const bool every_node = hourglass_damps_every_node(scene.solver, scene.geometry);
    const double lattice_plastic_strain =
        every_node ? std::numeric_limits<double>::infinity() : scene.solver.switch_plastic_strain;
    auto h = hourglass_fields<G::dim>(nodes, lattice_plastic_strain, power, scene.solver.hourglass_stiffness, stiffness_power);
    h.quadratic = scene.solver.hourglass_fit == HourglassFitOrder::Quadratic;
    if (relaxing_stiffness(scene.solver)) {
        for (int c = 0; c < G::dim; ++c) h.reference_position[c] = nodes.reference_position[c].data();
    }
    if (every_node || (contact.sliding() && contact.failed_pairs_separate())) h.failed = nodes.failed.data();
    h.ghost_continues = ghosts.continuing_flags();
    return h;
}

template <class G>
void Simulation::Impl::integrate(double dt_avg) {
    // v^{n+3/2} = v^{n+1/2} + dt_avg F^{n+1} / M (spec section 11), then the prescribed components
    // of held nodes (prescribed.hpp): after the update, which they replace, and before smoothing,
    // which leaves them alone, so that the nodes move with the prescribed velocity. Then the
    // ledger books the step's work and heat.
    const int d = dim();
    const std::array<double*, 3> velocity{nodes.velocity[0].data(), nodes.velocity[1].data(),
                                          d == 3 ? nodes.velocity[2].data() : nullptr};
    HeldNodes& held = regions.particles();
    if (!held.empty()) held.capture({velocity[0], velocity[1], velocity[2]}, d);
    ledger.keep_half_step_velocities(nodes);
    if (external.forces_pending()) external.add_to_forces(nodes, real);  // a program's loads join the forces
    rigid_planes.apply_friction(ghosts, nodes, real, dt_avg);  // Coulomb friction joins the forces
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, real, costly_node_grain), [&](const tbb::blocked_range<std::size_t>& r) {
        for (int c = 0; c < d; ++c) {
            double* v = nodes.velocity[c].data();
            const double* f = nodes.force[c].data();
            for (std::size_t i = r.begin(); i != r.end(); ++i) v[i] = leapfrog_velocity(v[i], f[i], nodes.mass[i], dt_avg);
        }
    });
    if (!held.empty()) {
        regions.book(held.impose(scene.prescribed_velocities, d, time + 0.5 * dt_next, dt_avg, velocity, nodes.mass.data()), dt_avg);
    }
    external.book(nodes, dt_avg);  // (also when none waited: the last update's work is then 0)
    rigid_planes.add_impulses(dt_avg);
    rigid_planes.book_friction(nodes, dt_avg);  // its work becomes heat of the nodes it acted on
    if (ledger.compatible() && particles) {
        auto f = force_fields<G::dim>(nodes, a());
        f.pairs = neighbour_lists.with_kept_pairs(contact.fields(f.pairs, nodes));
        f.full_normalisation = scene.solver.normalisation == Normalisation::MomentMatrix;
        if (scene.solver.viscosity != ViscosityKind::Nodal) f.viscous_pressure = nullptr;  // as in forces()
        std::optional<HourglassFields<G::dim>> control;
        if (ledger.hourglass()) control = hourglass_control_fields<G>(nullptr, nullptr);  // the ledger sets the outputs
        ledger.compatible_powers<G>(lists(), scene.solver.weight, f, control, scene.solver.hourglass_coefficient, nodes, real,
                                    dt_avg, held, scene.prescribed_velocities, ghosts);
    }
    ledger.book(nodes, real, dt_avg);
}

void Simulation::Impl::integrate_elements(double dt_avg, double dt_next_step) {
    // As for particles: the element nodes' update with their own constraints (axis, planes,
    // contact), then the prescribed components.
    ElementNodes& n = elements->mesh().nodes;
    const std::array<double*, 3> velocity{n.velocity[0].data(), n.velocity[1].data(), nullptr};
    HeldNodes& held = regions.elements();
    if (!held.empty()) held.capture({velocity[0], velocity[1], nullptr}, 2);
    elements->integrate(dt_avg, dt_next_step);
    if (!held.empty()) {
        regions.book(held.impose(scene.prescribed_velocities, 2, time + 0.5 * dt_next_step, dt_avg, velocity, n.mass.data()), dt_avg);
    }
}

template <class G>
void Simulation::Impl::smoothing() {
    SmoothingOptions o{scene.solver.smoothing_coefficient, scene.solver.smoothing == SmoothingMode::Tension};
    o.held = regions.held_bits();
    std::array<double*, G::dim> v{};
    for (int c = 0; c < G::dim; ++c) v[c] = nodes.velocity[c].data();
    smooth_velocities<G>(lists(), plan(), scene.solver.weight, neighbour_lists.with_kept_pairs(contact.fields(pair_fields<G::dim>(nodes, a()), nodes)), real, o, v,
                         nodes.mass.data(), nodes.pressure.data(), nodes.internal_energy.data(), smoothing_scratch);
    regions.book_smoothing(G::dim, nodes.mass.data(), smoothing_scratch.total_change);
}

void Simulation::Impl::sum_totals() {
    const GhostPlane* plane = first_rigid_plane();
    const bool axisymmetric = scene.geometry == GeometryKind::Axisymmetric;
    const NodeSums s = measures.node_sums(nodes, real, plane, axisymmetric);
    NodeSums all = s;
    double element_boundary_work = 0.0;
    if (elements) {
        const ElementPart::Sums e = elements->sums();
        all.kinetic += e.kinetic;
        all.internal += e.internal;
        all.plastic += e.plastic;
        all.viscous += e.viscous;
        for (int c = 0; c < 2; ++c) all.momentum[c] += e.momentum[c];
        element_boundary_work = elements->boundary_work();
        if (plane) all.extent += Measures::element_extent(elements->mesh(), *plane, axisymmetric);
    }
    // Kinetic energy at an integer time: the mean of the half steps around it (spec section 11).
    totals.kinetic_energy = measures.advance_kinetic(all.kinetic);
    totals.internal_energy = all.internal;
    totals.plastic_work = all.plastic;
    totals.viscous_work = all.viscous;
    totals.hourglass_work = ledger.hourglass_work();
    totals.hourglass_energy = ledger.hourglass_energy();
    // The regions' work, taken at the instant of the energy balance's kinetic energy. With the
    // compatible energy update (particle bodies) that is the half step ahead, v^{n+3/2}: the work of
    // every velocity update so far, like the impulse. Otherwise the balance takes the kinetic energy
    // at t^{n+1}, the mean of the half steps around it: a constraint's impulse acts from t^{n+1/2} to
    // t^{n+3/2}, so half of the last update's work is done by then (and none at t = 0). Either way
    // a rigid motion's energy books close to round-off.
    const bool balance_at_half_step = ledger.compatible() && !elements;
    const double region_work_now = regions.report(time, balance_at_half_step, steps == 0 && time == 0.0, totals.regions);
    const double external_work_now = external.work(balance_at_half_step);
    totals.external_work = external_work_now;
    totals.boundary_work = ledger.boundary_work() + element_boundary_work - region_work_now - external_work_now;
    totals.momentum = all.momentum;
    totals.time = time;
    totals.time_step = dt_half;
    totals.step = steps;
    // The base the body is measured from (measure.hpp): the plane while it stands on it, which the
    // pass above measured; otherwise its own underside, measured in a second pass.
    measure::Extent shape = all.extent;
    totals.base_height = 0.0;
    if (plane && shape.seen() && !shape.standing()) {
        totals.base_height = shape.lowest;
        shape = measures.particle_extent(nodes, real, *plane, axisymmetric, totals.base_height);
        if (elements) shape += Measures::element_extent(elements->mesh(), *plane, axisymmetric, totals.base_height);
    }
    totals.length = plane ? shape.length() : 0.0;
    totals.footprint_diameter = plane ? shape.footprint() : 0.0;
    totals.footprint_narrowest = plane ? shape.footprint_narrowest() : 0.0;
    totals.footprint_widest = plane ? shape.footprint_widest() : 0.0;
    totals.real_nodes = real;
    totals.element_nodes = elements ? elements->mesh().nodes.size() : 0;
    totals.elements = elements ? elements->mesh().quads.size() : 0;
    totals.ghost_nodes = nodes.size() - real;
    totals.variable_nodes = s.variable;
    totals.failed_nodes = s.failed;
    totals.pairs = lists().entries();
    totals.neighbour_searches = neighbour_lists.searches();
    totals.row_searches = neighbour_lists.row_searches();
    totals.rows_searched = neighbour_lists.rows_searched();
    rigid_planes.report(ghosts, elements ? &elements->reactions() : nullptr, elements ? &elements->impulses() : nullptr,
                        totals.planes);
    measures.body_totals(scene, nodes, real, true, &s, totals.bodies);
    totals.energy_given = totals.initial_energy + std::max(0.0, region_work_now + external_work_now);
    if (totals.energy_given != 0.0) {
        // With the compatible energy update the internal energy has been booked up to the velocities
        // of this half step, so the balance takes their kinetic energy (docs/energy.md); the mean of
        // the two half steps, reported as the kinetic energy at t^n, would add an oscillation of half
        // a step's kinetic-energy change.
        const double kinetic = ledger.compatible() && !elements ? all.kinetic : totals.kinetic_energy;
        totals.energy_error = (kinetic + totals.internal_energy + totals.boundary_work - totals.initial_energy) /
                              totals.energy_given;
    }
}

template <class G>
void Simulation::Impl::build_phase_graph() {
    graph = std::make_unique<PhaseGraph>();
    // The step, as drawn in simulation.hpp; bracketed phases only where the scene needs them, the
    // particle phases only with particle bodies and the element phases only with element bodies.
    if (particles) graph->add("move", [this] { move(); });
    if (elements) {
        graph->add("element move", [this] {
            elements->move(dt_half);
            if (!particles) {
                regions.advance_displacements(2, dt_half);
                time += dt_half;
            }
        });
    }
    if (particles) {
        if (scene.solver.reorder_interval > 0) {
            graph->add("reorder", [this] {
                if (steps % scene.solver.reorder_interval == 0 && steps > 0) reorder();
            });
        }
        graph->add("geometry", [this] { geometry<G>(); });
        graph->add("neighbours", [this] { neighbours(); });
        graph->add("gradient", [this] { gradient<G>(); });
        graph->add("stress", [this] { stress<G>(); });
    }
    if (elements) graph->add("element stress", [this] { elements->update_stress(dt_half, steps + 1, time); });
    if (particles) graph->add("plan", [this] { refresh_ghosts_and_plan(); });
    graph->add("time step", [this] { time_step(); });
    if (particles) graph->add("forces", [this] { forces<G>(); });
    if (elements) graph->add("element forces", [this] { elements->compute_forces(); });
    if (particles) graph->add("integrate", [this] { integrate<G>(0.5 * (dt_half + dt_next)); });
    if (elements) graph->add("element integrate", [this] { integrate_elements(0.5 * (dt_half + dt_next), dt_next); });
    if (particles && scene.solver.smoothing != SmoothingMode::Off && scene.solver.smoothing_coefficient > 0.0) {
        graph->add("smoothing", [this] { smoothing<G>(); });
    }
    // Switching last: a node that switches takes its new rule from the next geometry on, so that
    // its strain rates and forces always use one rule (spec section 2).
    // (Fixed bodies need it too: it checks their lattice cells.)
    if (particles && switching_part.any_lattice()) {
        graph->add("switching", [this] { switching(); });
    }
    graph->add("totals", [this] {
        ++steps;
        node_steps += static_cast<double>(real);
        if (elements) {
            node_steps += static_cast<double>(elements->mesh().nodes.size());
            element_steps += static_cast<double>(elements->mesh().quads.size());
        }
        sum_totals();
        dt_half = dt_next;
    });
}

Simulation::Simulation(Scene scene, int threads, MemoryLimit memory)
    : impl_(std::make_unique<Impl>(std::move(scene), threads, memory)) {
    // Sizes from the input, checked before they are allocated: the nodes here, the neighbour
    // lists before every search.
    validate_scene(impl_->scene);
    check_scene_memory(impl_->scene, memory);
    impl_->neighbour_lists.set_entry_check(
        [im = impl_.get()](std::size_t entries) { return im->run_control.check_list_memory(im->nodes, im->real, entries); });
    impl_->threads.run([this] {
        dispatch_geometry(impl_->scene.geometry, [this](auto g) { impl_->setup<decltype(g)>(); });
    });
}

Simulation::~Simulation() = default;

void Simulation::step() {
    if (impl_->failed) {
        throw NumericalError("Simulation::step: an earlier step failed and left the state half-updated");
    }
    if (finished()) return;
    const double time_before = impl_->time;
    try {
        impl_->threads.run([this] { impl_->graph->run(); });
    } catch (const std::exception& e) {
        impl_->failed = true;
        throw impl_->run_control.step_failure(e, impl_->graph->failed_phase(), impl_->steps, impl_->time, impl_->nodes,
                                              impl_->real);
    } catch (...) {
        impl_->failed = true;
        throw;
    }
    try {
        impl_->run_control.check_step(time_before, impl_->time, impl_->dt_half, impl_->steps, impl_->totals, impl_->nodes,
                                      impl_->real);
    } catch (...) {
        impl_->failed = true;
        throw;
    }
}

bool Simulation::finished() const {
    return impl_->run_control.finished(impl_->time, impl_->steps, impl_->totals, impl_->stop_reason);
}

std::string Simulation::stop_reason() const {
    (void)finished();
    return impl_->stop_reason;
}

const Scene& Simulation::scene() const { return impl_->scene; }
const NodeStore& Simulation::nodes() const { return impl_->nodes; }
std::size_t Simulation::real_count() const { return impl_->real; }
const Totals& Simulation::totals() const { return impl_->totals; }
void Simulation::measure_bodies() {
    Impl& im = *impl_;
    im.measures.local_fields(im.scene, im.nodes, im.real, im.first_rigid_plane(), im.elements.get(), im.totals.base_height,
                             im.totals.local);
    if (!im.particles) return;
    gpa::measure_bodies(im.nodes, im.real, im.lists(), im.measures.impact(), im.totals.bodies);
}

double Simulation::time() const { return impl_->time; }
std::size_t Simulation::steps() const { return impl_->steps; }
double Simulation::next_time_step() const { return impl_->dt_half; }
int Simulation::threads() const { return impl_->threads.threads(); }
std::vector<PhaseTime> Simulation::phase_times() const { return impl_->graph->times(); }
std::vector<std::string> Simulation::phases() const { return impl_->graph->names(); }
double Simulation::node_steps() const { return impl_->node_steps; }
double Simulation::element_steps() const { return impl_->element_steps; }
const ElementPart* Simulation::elements() const { return impl_->elements.get(); }
const CompressedRows& Simulation::neighbour_lists() const { return impl_->lists(); }

// --- between steps ------------------------------------------------------------------------

namespace {

// A vector argument of the calls below: finite, and 0 beyond the scene's dimension.
void check_vector(const std::array<double, 3>& v, int dim, const char* call, const char* what) {
    for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(v[c])) throw InputError(fmt::format("Simulation::{}: its {} has a component that is not finite ({})", call, what, v[c]));
        if (c >= dim && v[c] != 0.0) {
            throw InputError(fmt::format("Simulation::{}: its {} has a third component ({}) in a 2D scene, whose components are "
                                         "x (the radius in axisymmetric) and z",
                                         call, what, v[c]));
        }
    }
}

}  // namespace

std::size_t Simulation::index_of(std::uint64_t id) const { return impl_->external.index_of(impl_->nodes, impl_->real, id); }

void Simulation::apply_force(std::uint64_t id, const std::array<double, 3>& force) {
    Impl& im = *impl_;
    if (im.failed) throw InputError("Simulation::apply_force: an earlier step failed");
    check_vector(force, im.dim(), "apply_force", "force");
    (void)im.external.index_of(im.nodes, im.real, id);
    im.external.add_force(static_cast<std::uint32_t>(id), force);
}

void Simulation::set_velocity(std::uint64_t id, const std::array<double, 3>& velocity) {
    Impl& im = *impl_;
    if (im.failed) throw InputError("Simulation::set_velocity: an earlier step failed");
    check_vector(velocity, im.dim(), "set_velocity", "velocity");
    const std::size_t i = im.external.index_of(im.nodes, im.real, id);
    // A component a region holds keeps the region's velocity (set_region_velocity changes it).
    if (const std::uint8_t region = im.nodes.velocity_region[i]; region != 0) {
        const PrescribedVelocitySpec& spec = im.scene.prescribed_velocities[region - 1u];
        for (int c = 0; c < im.dim(); ++c) {
            if (spec.velocity[c] && velocity[c] != im.nodes.velocity[c][i]) {
                throw InputError(fmt::format("Simulation::set_velocity: node id {} is held along {} by the prescribed-velocity "
                                             "region \"{}\" (set the region's velocity with set_region_velocity)",
                                             id, axis_letter(c, im.dim()), spec.name));
            }
        }
    }
    // The change of the half-step kinetic energy is work done on the bodies (external_loads.hpp);
    // the kinetic energy the next step reports is the mean of the changed half step and the next.
    double before = 0.0, after = 0.0;
    for (int c = 0; c < im.dim(); ++c) {
        before += im.nodes.velocity[c][i] * im.nodes.velocity[c][i];
        after += velocity[c] * velocity[c];
        im.nodes.velocity[c][i] = velocity[c];
    }
    const double change = 0.5 * im.nodes.mass[i] * (after - before);
    im.external.add_work(change);
    im.measures.add_to_half_step_kinetic(static_cast<std::size_t>(im.nodes.body[i]), change);
}

void Simulation::set_region_velocity(std::string_view name, const std::array<double, 3>& velocity) {
    Impl& im = *impl_;
    if (im.failed) throw InputError("Simulation::set_region_velocity: an earlier step failed");
    auto& specs = im.scene.prescribed_velocities;
    const auto it = std::find_if(specs.begin(), specs.end(), [&](const PrescribedVelocitySpec& r) { return r.name == name; });
    if (it == specs.end()) {
        std::vector<std::string> names;
        for (const auto& r : specs) names.push_back("\"" + r.name + "\"");
        throw InputError(fmt::format("Simulation::set_region_velocity: the scene has no prescribed-velocity region \"{}\" ({})", name,
                                     names.empty() ? std::string("it has none") : fmt::format("it has {}", fmt::join(names, ", "))));
    }
    check_vector(velocity, im.dim(), "set_region_velocity", "velocity");
    for (int c = 0; c < 3; ++c) {
        if (!it->velocity[c] && velocity[c] != 0.0) {
            throw InputError(fmt::format("Simulation::set_region_velocity: region \"{}\" leaves component {} free; it holds only the "
                                         "components its scene gives",
                                         name, axis_letter(c, im.dim())));
        }
    }
    // From now on: the value replaces the scene's (and its ramp, which is over).
    for (int c = 0; c < 3; ++c) {
        if (it->velocity[c]) it->velocity[c] = velocity[c];
    }
    it->ramp = 0.0;
}

MemoryUse Simulation::memory_use() const {
    const Impl& im = *impl_;
    MemoryUse out;
    im.nodes.memory_use(out);
    im.neighbour_lists.memory_use(out);
    im.ghosts.memory_use(out);
    im.contact.memory_use(out);
    im.ledger.memory_use(out);
    im.external.memory_use(out);
    im.switching_part.memory_use(out);
    im.stable_step.memory_use(out);
    const auto& s = im.smoothing_scratch;
    add_memory(out, "smoothing: scratch", allocated_bytes(s.centre_change) + allocated_bytes(s.share) + allocated_bytes(s.total_change));
    std::size_t groups = 0;
    for (const auto& g : im.material_groups.members) groups += allocated_bytes(g);
    add_memory(out, "stress: material groups", groups);
    return out;
}

// --- limits, failure reports and checkpoints ----------------------------------------------

namespace {

constexpr char checkpoint_magic[8] = {'G', 'P', 'A', 'C', 'H', 'K', 'P', 'T'};
constexpr std::uint32_t byte_order_mark = 0x01020304u;

// The header: everything up to the state, read again by checkpoint_info.
CheckpointInfo read_header(StateReader& in) {
    char magic[8];
    in.bytes(magic, sizeof magic);
    if (!std::equal(magic, magic + 8, checkpoint_magic)) in.fail("it is not a gpa checkpoint");
    CheckpointInfo info;
    info.format = in.value<std::uint32_t>();
    if (info.format != Simulation::checkpoint_format) {
        in.fail(fmt::format("it is of format {}, this build reads format {}", info.format, Simulation::checkpoint_format));
    }
    if (in.value<std::uint32_t>() != byte_order_mark) in.fail("it was written on a machine of another byte order");
    info.build = in.text();
    info.scene_fingerprint = in.text();
    info.scene_name = in.text();
    info.step = static_cast<std::size_t>(in.value<std::uint64_t>());
    info.time = in.value<double>();
    info.user_data = in.text();
    return info;
}

// The run's clock as a checkpoint keeps it, listed once for writing (IO = StateWriter, Impl const)
// and reading (StateReader).
template <class IO, class Impl>
void clock_fields(IO& io, Impl& s) {
    io.field(s.time);
    io.field(s.dt_half);
    io.field(s.dt_next);
    io.field(s.steps);
    io.field(s.node_steps);
    io.field(s.element_steps);
}

// What a checkpoint keeps of the totals, listed once for both directions (T = const Totals or
// Totals); `planes` and `regions` are the scene's counts, which a checkpoint read must hold. The
// rest of Totals (the bodies' reports, local peaks, base height) is measured again after a resume.
template <class IO, class T>
void totals_fields(IO& io, T& t, std::size_t planes, std::size_t regions) {
    for (auto* v : {&t.time, &t.time_step, &t.kinetic_energy, &t.internal_energy, &t.plastic_work, &t.viscous_work,
                    &t.boundary_work, &t.initial_kinetic_energy, &t.initial_energy, &t.energy_error, &t.momentum[0],
                    &t.momentum[1], &t.momentum[2], &t.length, &t.footprint_diameter, &t.footprint_narrowest,
                    &t.footprint_widest, &t.hourglass_work, &t.hourglass_energy, &t.energy_given, &t.external_work}) {
        io.field(*v);
    }
    for (auto* v : {&t.step, &t.real_nodes, &t.ghost_nodes, &t.variable_nodes, &t.failed_nodes, &t.pairs,
                    &t.neighbour_searches, &t.row_searches, &t.rows_searched}) {
        io.field(*v);
    }
    io.sequence(t.planes, planes, "its planes are not the scene's");
    for (auto& p : t.planes) {
        io.field(p.name);
        io.field(p.reaction);
        io.field(p.impulse);
    }
    io.sequence(t.regions, regions, "its prescribed velocities are not the scene's");
    for (auto& r : t.regions) {
        io.field(r.name);
        io.field(r.nodes);
        for (int c = 0; c < 3; ++c) {
            io.field(r.held[c]);
            for (auto* v : {&r.velocity[c], &r.displacement[c], &r.reaction[c], &r.impulse[c]}) io.field(*v);
        }
        io.field(r.work);
    }
}

// The phases' accumulated times, both directions; `phases` is this scene's phase count.
template <class IO, class Times>
void phase_time_fields(IO& io, Times& times, std::size_t phases) {
    io.sequence(times, phases, "its phase list is not this scene's");
    for (auto& p : times) {
        io.field(p.name);
        io.field(p.seconds);
        io.field(p.calls);
    }
}

// A part's section in the direction of IO: write_state(out), or read_state(in, read_args...).
template <class IO, class Part, class... ReadArgs>
void part_state(IO& io, Part& part, ReadArgs&&... read_args) {
    if constexpr (IO::reading) {
        part.read_state(io, std::forward<ReadArgs>(read_args)...);
    } else {
        part.write_state(io);
    }
}

// The checkpoint's sections in their order, listed once for writing (IO = StateWriter, Impl
// const) and reading. Returns the bodies' kinetic energies of the half step as read (the reader
// puts them into the totals once the bodies are measured again; empty when writing).
template <class IO, class Impl>
std::vector<double> state_sections(IO& io, Impl& s) {
    constexpr bool reading = IO::reading;
    io.tag("SIMU");
    part_state(io, s.nodes);
    io.expect(s.real, "its bodies hold another number of nodes than the scene's");
    const std::size_t n = s.nodes.size();
    if constexpr (reading) {
        if (n < s.real) io.fail("it holds fewer nodes than the scene's bodies (a damaged checkpoint)");
    }
    part_state(io, s.ghosts, s.real, n);
    if constexpr (reading) {
        s.neighbour_lists.read_state(io, s.dim(), n);
        s.switching_part.forget_lattice_axes();  // found again from the restored nodes
    } else {
        s.neighbour_lists.write_state(io, s.dim());
    }
    io.tag("TIME");
    part_state(io, s.stable_step);
    clock_fields(io, s);
    std::vector<double> body_kinetic;
    if constexpr (!reading) {
        for (const auto& b : s.totals.bodies) body_kinetic.push_back(b.kinetic_energy);
    }
    io.sequence(body_kinetic, s.scene.bodies.size(), "its bodies are not the scene's");
    for (double& k : body_kinetic) io.field(k);
    part_state(io, s.rigid_planes);
    part_state(io, s.measures, s.scene.bodies.size());
    part_state(io, s.ledger);
    part_state(io, s.regions);
    if constexpr (reading) {
        s.external.read_state(io, s.scene.prescribed_velocities, s.real);
    } else {
        s.external.write_state(io, s.scene.prescribed_velocities);
    }
    if (s.elements) part_state(io, *s.elements);
    io.tag("TOTL");
    totals_fields(io, s.totals, s.rigid_planes.size(), s.scene.prescribed_velocities.size());
    auto times = s.graph->times();
    phase_time_fields(io, times, times.size());
    if constexpr (reading) s.graph->restore_times(times);
    io.tag("END.");
    return body_kinetic;
}

}  // namespace

void Simulation::Impl::write_state(StateWriter& out) const { state_sections(out, *this); }

void Simulation::Impl::read_state(StateReader& in) {
    external.forget_ids();  // until the nodes are read whole: no id is found in a half-read store
    const std::vector<double> body_kinetic = state_sections(in, *this);
    regroup_materials();
    measures.body_totals(scene, nodes, real, false, nullptr, totals.bodies);
    for (std::size_t b = 0; b < body_kinetic.size(); ++b) totals.bodies[b].kinetic_energy = body_kinetic[b];
    // The held nodes in the checkpoint's numbering: the same count per region as the scene's.
    regions.check_restored(in, nodes, real);
    if (!ExternalLoads::check_ids(nodes, real)) in.fail("its node ids are not those of the scene's nodes (a damaged checkpoint)");
    external.forget_ids();
}

bool Simulation::can_checkpoint() const { return true; }

namespace {

// A checkpoint's header and sections, without the checksum that ends the file.
template <class Impl>
void write_checkpoint(StateWriter& w, const Impl& impl, std::string_view scene_fingerprint, std::string_view user_data) {
    w.bytes(checkpoint_magic, sizeof checkpoint_magic);
    w.value<std::uint32_t>(Simulation::checkpoint_format);
    w.value<std::uint32_t>(byte_order_mark);
    w.text(build_id());
    w.text(scene_fingerprint);
    w.text(impl.scene.name);
    w.value<std::uint64_t>(impl.steps);
    w.value<double>(impl.time);
    w.text(user_data);
    impl.write_state(w);
}

}  // namespace

void Simulation::save_checkpoint(std::ostream& out, std::string_view scene_fingerprint, std::string_view user_data) const {
    if (impl_->failed) throw NumericalError("Simulation::save_checkpoint: the last step failed and left the state half-updated");
    StateWriter w(out);
    write_checkpoint(w, *impl_, scene_fingerprint, user_data);
    const std::uint64_t sum = w.checksum();
    out.write(reinterpret_cast<const char*>(&sum), sizeof sum);
}

std::vector<std::uint64_t> Simulation::checkpoint_field_starts(std::string_view scene_fingerprint, std::string_view user_data) const {
    std::ostringstream discarded;
    StateWriter w(discarded);
    std::vector<std::uint64_t> starts;
    w.record_field_starts(&starts);
    write_checkpoint(w, *impl_, scene_fingerprint, user_data);
    return starts;
}

CheckpointInfo Simulation::checkpoint_info(std::istream& in, std::uint64_t size, const std::string& source) {
    StateReader r(in, size, source);
    return read_header(r);
}

std::string Simulation::restore_checkpoint(std::istream& in, std::uint64_t size, const std::string& source,
                                           std::string_view scene_fingerprint) {
    if (size < sizeof(std::uint64_t)) throw CheckpointError("checkpoint " + source + ": it is too short to be one");
    StateReader r(in, size - sizeof(std::uint64_t), source);
    const CheckpointInfo info = read_header(r);
    if (info.build != build_id()) {
        r.fail(fmt::format("it was written by {}, and this is {}: a run resumes bit-identically only with the build "
                           "that started it",
                           info.build, build_id()));
    }
    if (info.scene_fingerprint != scene_fingerprint) {
        r.fail(fmt::format("it was written for another scene (scene \"{}\", fingerprint {}; this scene's is {})",
                           info.scene_name, info.scene_fingerprint, scene_fingerprint));
    }
    impl_->failed = true;  // until the whole state has been read and checked
    impl_->read_state(r);
    if (r.left() != 0) r.fail("it holds more than a checkpoint of this scene (a damaged checkpoint)");
    const std::uint64_t computed = r.checksum();
    std::uint64_t stored = 0;
    in.read(reinterpret_cast<char*>(&stored), sizeof stored);
    if (!in || stored != computed) r.fail("its checksum does not match (a damaged checkpoint)");
    impl_->failed = false;
    return info.user_data;
}

}  // namespace gpa

