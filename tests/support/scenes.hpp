#pragma once
// Scenes built in code for the engine's run tests.

#include <filesystem>
#include <string>

#include "gpa/engine/scene.hpp"
#include "gpa/engine/simulation.hpp"

namespace gpa::testing {

// A linear-elastic material: linear EOS with K, shear modulus G, no yield.
materials::Material elastic_material(const std::string& name, double density, double young, double poisson);

// An axisymmetric bar of radius R and length L standing on a rigid plane at z = 0 (lift-off
// allowed) and moving towards it at `speed`; spacing = R / radial_cells.
Scene elastic_bar_on_plane(double radius, double length, int radial_cells, double speed);

// An elastic bar at rest (axisymmetric cylinder of radius R and length L, or the plane-strain strip
// or 3D square bar of width 2R), spacing dz = R / radial_cells, no viscosity: its nodes within
// 2.25 dz of the top ("grip", two rows of particles) are pulled along z at `speed` after a linear
// ramp over `ramp`, those within 2.25 dz of the bottom ("clamp") held at v_z = 0 (x, y free).
Scene pulled_elastic_bar(GeometryKind geometry, double radius, double length, int radial_cells, double speed, double ramp,
                         double poisson);

// Every field of every node of a run (ghosts included) and the fixed lists, as bytes (the
// checkpoint encoding of NodeStore): for comparing runs bit for bit.
std::string node_bytes(const Simulation& sim);

// Writes `text` to `file` and reads it as a scene file (io::load_scene): the error's message, or
// "" when it reads.
std::string scene_file_refusal(const std::string& text, const std::filesystem::path& file);

// scenes/taylor-copper-190-3d.toml's copper bar at 190 m/s on its rigid anvil, shortened to 8 mm and
// stepped by hand (no end condition met), at `radial_cells` nodes across the radius; or, in plane
// strain, its section: a strip 2R wide. The run tests of symmetry planes and orientation use it.
Scene short_copper_bar(GeometryKind geometry, int radial_cells);

// `scene` with the symmetry planes x = 0 and y = 0 (bodies on their positive sides): a quarter model
// of a body whose axis is the z axis.
Scene with_quarter_planes(Scene scene);

// The paper's Armco-iron cylinder (L0 15.2 mm, D0 10.2 mm, 305 m/s) at `radial_cells` across
// the radius, nodal viscosity, no lift-off, with the given end time.
Scene armco_cylinder(int radial_cells, double end_time);

// `scene`'s first body at rest (with connectivity `target`), struck on its top end at 3000 m/s by
// a variable "shot" of its own shape and material, 2 spacings long and 2 in radius (or across).
Scene struck_by_a_fast_body(Scene scene, ConnectivityMode target);

}  // namespace gpa::testing
