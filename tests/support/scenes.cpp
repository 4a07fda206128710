#include "support/scenes.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include "gpa/engine/state_io.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa::testing {

materials::Material elastic_material(const std::string& name, double density, double young, double poisson) {
    materials::Material m;
    m.name = name;
    m.density = density;
    const double k = young / (3.0 * (1.0 - 2.0 * poisson));
    m.shear_modulus = young / (2.0 * (1.0 + poisson));
    m.eos = materials::LinearEos{k, false};
    m.strength = materials::ElasticStrength{};
    m.specific_heat = 450.0;
    m.source = "test material";
    return m;
}

Scene elastic_bar_on_plane(double radius, double length, int radial_cells, double speed) {
    Scene s;
    s.name = "elastic bar on a rigid plane";
    s.geometry = GeometryKind::Axisymmetric;
    s.materials.push_back(elastic_material("elastic steel", 7800.0, 200e9, 0.0));
    BodySpec bar;
    bar.name = "bar";
    bar.shape = ShapeKind::Cylinder;
    bar.radius = radius;
    bar.length = length;
    bar.spacing = radius / radial_cells;
    bar.material = "elastic steel";
    bar.velocity = {0.0, -speed, 0.0};
    s.bodies.push_back(bar);
    PlaneSpec wall;
    wall.name = "anvil";
    wall.kind = PlaneKind::Rigid;
    wall.axis = 1;
    wall.position = 0.0;
    wall.side = +1;
    wall.lift_off = true;
    s.planes.push_back(wall);
    s.solver.viscosity = ViscosityKind::None;
    s.solver.connectivity = ConnectivityMode::Variable;
    s.stop.end_time = 3.0 * length / 5000.0;
    return s;
}

Scene pulled_elastic_bar(GeometryKind geometry, double radius, double length, int radial_cells, double speed, double ramp,
                         double poisson) {
    Scene s;
    s.name = "pulled elastic bar";
    s.geometry = geometry;
    s.materials.push_back(elastic_material("elastic steel", 7800.0, 200e9, poisson));
    BodySpec bar;
    bar.name = "bar";
    bar.spacing = radius / radial_cells;
    bar.material = "elastic steel";
    const int axial = geometry == GeometryKind::ThreeD ? 2 : 1;
    if (geometry == GeometryKind::ThreeD) {
        bar.shape = ShapeKind::Box;
        bar.origin = {-radius, -radius, 0.0};
        bar.size = {2.0 * radius, 2.0 * radius, length};
    } else {
        bar.shape = ShapeKind::Cylinder;
        bar.radius = radius;
        bar.length = length;
    }
    s.bodies.push_back(bar);
    const double dz = bar.spacing;
    PrescribedVelocitySpec grip;
    grip.name = "grip";
    grip.body = "bar";
    grip.lower[axial] = length - 2.25 * dz;  // between rows: particle rows at (k + 1/2) dz, element nodes at k dz / 2
    grip.velocity[axial] = speed;
    grip.ramp = ramp;
    s.prescribed_velocities.push_back(grip);
    PrescribedVelocitySpec clamp;
    clamp.name = "clamp";
    clamp.body = "bar";
    clamp.upper[axial] = 2.25 * dz;
    clamp.velocity[axial] = 0.0;
    s.prescribed_velocities.push_back(clamp);
    s.solver.viscosity = ViscosityKind::None;
    s.stop.end_time = 3.0 * length / std::sqrt(200e9 / 7800.0);
    return s;
}

std::string node_bytes(const Simulation& sim) {
    std::ostringstream out;
    StateWriter w(out);
    sim.nodes().write_state(w);
    return out.str();
}

Scene short_copper_bar(GeometryKind geometry, int radial_cells) {
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/taylor-copper-190-3d.toml");
    s.geometry = geometry;
    auto& bar = s.bodies[0];
    bar.length = 8e-3;
    bar.spacing = bar.radius / radial_cells;
    if (geometry == GeometryKind::PlaneStrain) {
        bar.shape = ShapeKind::Rectangle;
        bar.origin = {-bar.radius, 0.0, 0.0};
        bar.size = {2.0 * bar.radius, bar.length, 0.0};
        bar.velocity = {0.0, -190.0, 0.0};
        s.planes[0].axis = 1;
    }
    s.stop.kinetic_energy_fraction = 0.0;
    s.stop.end_time = 1.0;  // stepped by hand
    return s;
}

Scene with_quarter_planes(Scene scene) {
    for (int axis : {0, 1}) {
        PlaneSpec p;
        p.name = axis == 0 ? "x = 0" : "y = 0";
        p.kind = PlaneKind::Symmetry;
        p.axis = axis;
        p.side = +1;
        scene.planes.push_back(p);
    }
    return scene;
}

Scene armco_cylinder(int radial_cells, double end_time) {
    Scene s;
    s.name = "Armco iron cylinder impact";
    s.geometry = GeometryKind::Axisymmetric;
    materials::Material iron;
    iron.name = "Armco iron";
    iron.density = 7890.0;
    iron.shear_modulus = 80e9;
    iron.specific_heat = 452.0;
    iron.room_temperature = 294.0;
    iron.melt_temperature = 1811.0;
    iron.eos = materials::PolynomialEos{165e9, 0.0, 0.0, 1.7};
    iron.strength = materials::JohnsonCookStrength{175e6, 380e6, 0.32, 0.060, 0.55, 1.0};
    iron.source = "materials.md";
    s.materials.push_back(iron);
    BodySpec bar;
    bar.name = "cylinder";
    bar.shape = ShapeKind::Cylinder;
    bar.radius = 5.1e-3;
    bar.length = 15.2e-3;
    bar.spacing = bar.radius / radial_cells;
    bar.material = "Armco iron";
    bar.velocity = {0.0, -305.0, 0.0};
    s.bodies.push_back(bar);
    PlaneSpec wall;
    wall.name = "anvil";
    wall.kind = PlaneKind::Rigid;
    wall.axis = 1;
    wall.side = +1;
    wall.lift_off = false;
    s.planes.push_back(wall);
    s.stop.end_time = end_time;
    return s;
}

Scene struck_by_a_fast_body(Scene scene, ConnectivityMode target) {
    BodySpec& bar = scene.bodies[0];
    bar.velocity = {0.0, 0.0, 0.0};
    bar.connectivity = target;
    BodySpec shot = bar;
    shot.name = "shot";
    shot.connectivity = ConnectivityMode::Variable;
    const int up = scene.geometry == GeometryKind::ThreeD ? 2 : 1;
    shot.length = 2.0 * bar.spacing;
    if (shot.shape == ShapeKind::Box) {
        shot.size = {2.0 * bar.spacing, 2.0 * bar.spacing, shot.length};
    } else {
        shot.radius = 2.0 * bar.spacing;
    }
    shot.origin[static_cast<std::size_t>(up)] = bar.origin[static_cast<std::size_t>(up)] + bar.length + 0.75 * bar.spacing;
    shot.velocity = {0.0, 0.0, 0.0};
    shot.velocity[static_cast<std::size_t>(up)] = -3000.0;
    scene.bodies.push_back(shot);
    scene.solver.switch_plastic_strain = 0.05;
    return scene;
}

std::string scene_file_refusal(const std::string& text, const std::filesystem::path& file) {
    std::ofstream(file) << text;
    try {
        (void)io::load_scene(file);
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace gpa::testing
