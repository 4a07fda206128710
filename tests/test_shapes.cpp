// Shaped bodies: the noses of cylinders (scene.hpp, NoseSpec). The nodes of a body with a cone,
// hemisphere or tangent-ogive nose hold the volume and mass of the closed forms, to within the
// lattice's resolution of the nose's surface, at three spacings and in every geometry.

#include <cmath>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/scene.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

constexpr double pi = std::numbers::pi;

// The nose's volume (3D and axisymmetric: a solid of revolution) or area (plane strain: the
// profile's slab, per unit thickness), for a cylinder of radius R.
double nose_measure(const NoseSpec& n, double R, bool plane) {
    const double L = nose_length(n, R);
    switch (n.kind) {
        case NoseKind::Cone: return plane ? R * L : pi * R * R * L / 3.0;
        case NoseKind::Hemisphere: return plane ? 0.5 * pi * R * R : 2.0 / 3.0 * pi * R * R * R;
        case NoseKind::Ogive: {
            // r(s) = sqrt(rho^2 - s^2) - a, a = rho - R, over s in [0, L] with sqrt(rho^2 - L^2) = a:
            // area 2 int r ds = rho^2 asin(L / rho) - a L; volume pi int r^2 ds = pi (rho^2 L - L^3 / 3 - a rho^2 asin(L / rho)).
            const double rho = n.calibre_radius * 2.0 * R, a = rho - R, angle = std::asin(L / rho);
            return plane ? rho * rho * angle - a * L : pi * (rho * rho * L - L * L * L / 3.0 - a * rho * rho * angle);
        }
    }
    return 0.0;
}

// The nose's section radius at distance s from its base, written from the closed forms of
// scene.hpp independently of the engine's cylinder_radius_at.
double profile(const NoseSpec& n, double R, double s) {
    const double L = nose_length(n, R);
    if (s <= 0.0) return R;
    if (s > L) return 0.0;
    switch (n.kind) {
        case NoseKind::Cone: return R * (L - s) / L;
        case NoseKind::Hemisphere: return std::sqrt(R * R - s * s);
        case NoseKind::Ogive: {
            const double rho = n.calibre_radius * 2.0 * R;
            return std::sqrt(rho * rho - s * s) - (rho - R);
        }
    }
    return 0.0;
}

double L_of(const NoseSpec& n, double R) { return nose_length(n, R); }

struct Filled {
    double volume = 0.0;  // sum of the nodes' initial volumes (area in plane strain)
    double mass = 0.0;
    std::size_t nodes = 0;
};

Filled fill(const Scene& scene) {
    validate_scene(scene);
    NodeStore nodes(scene.geometry);
    add_body_nodes(nodes, scene, 0, {});
    Filled f;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        f.volume += nodes.initial_volume[i];
        f.mass += nodes.mass[i];
    }
    f.nodes = nodes.size();
    return f;
}

// The nose lengths: a cone's as given, a hemisphere's the radius, a tangent ogive's
// sqrt(rho^2 - (rho - R)^2): 33.166 mm for R = 10 mm at 3 calibres (rho 60 mm), and still right
// for a very long one (1e6 calibres: sqrt(R (2 rho - R)), where the difference of squares loses it).
TEST(Noses, LengthsFollowFromTheirProfiles) {
    NoseSpec ogive;
    ogive.kind = NoseKind::Ogive;
    ogive.calibre_radius = 3.0;
    EXPECT_NEAR(nose_length(ogive, 10e-3), std::sqrt(60e-3 * 60e-3 - 50e-3 * 50e-3), 1e-15);
    EXPECT_NEAR(nose_length(ogive, 10e-3), 33.166247903554e-3, 1e-14);
    ogive.calibre_radius = 1e6;
    EXPECT_NEAR(nose_length(ogive, 10e-3), std::sqrt(10e-3 * (4e4 - 10e-3)), 1e-9);
    ogive.calibre_radius = 0.5;  // the hemisphere
    EXPECT_NEAR(nose_length(ogive, 10e-3), 10e-3, 1e-17);
    NoseSpec hemisphere;
    hemisphere.kind = NoseKind::Hemisphere;
    EXPECT_EQ(nose_length(hemisphere, 7e-3), 7e-3);
    NoseSpec cone;
    cone.length = 12e-3;
    EXPECT_EQ(nose_length(cone, 7e-3), 12e-3);
}

TEST(Noses, VolumeAndMassMatchTheClosedFormsAtThreeSpacings) {
    const double R = 10e-3, length = 30e-3, density = 7830.0;
    NoseSpec cone;
    cone.kind = NoseKind::Cone;
    cone.length = 12e-3;
    NoseSpec hemisphere;
    hemisphere.kind = NoseKind::Hemisphere;
    NoseSpec ogive;
    ogive.kind = NoseKind::Ogive;
    ogive.calibre_radius = 2.0;
    NoseSpec top_cone = cone;
    top_cone.end = 1;
    for (const GeometryKind g : {GeometryKind::Axisymmetric, GeometryKind::PlaneStrain, GeometryKind::ThreeD}) {
        const bool plane = g == GeometryKind::PlaneStrain;
        const int dim = dimension_of(g);
        // The mean relative error of the removed volume over the four noses, at the coarsest and
        // the finest spacing.
        double coarse = 0.0, fine = 0.0;
        for (const NoseSpec& nose : {cone, hemisphere, ogive, top_cone}) {
            for (const double divisions : dim == 3 ? std::array{4.0, 6.0, 8.0} : std::array{8.0, 16.0, 32.0}) {
                const double h = R / divisions;
                SCOPED_TRACE(fmt::format("{}, {} nose at the {}, spacing R/{}", name_of(g), name_of(nose.kind),
                                         nose.end < 0 ? "bottom" : "top", divisions));
                Scene s;
                s.geometry = g;
                s.materials.push_back(testing::elastic_material("steel", density, 77e9, 0.29));
                BodySpec b;
                b.name = "projectile";
                b.shape = ShapeKind::Cylinder;
                b.material = "steel";
                b.origin = {plane ? 4e-3 : 0.0, dim == 3 ? 1e-3 : 2e-3, 2e-3};
                b.radius = R;
                b.length = length;
                b.spacing = h;
                s.bodies.push_back(b);
                s.stop.end_time = 1e-6;
                const Filled flat = fill(s);
                s.bodies[0].nose = nose;
                const Filled shaped = fill(s);
                if (dim == 2) {
                    // The nodes are exactly the cell centres inside the profile: counted here cell by
                    // cell (a centre within 1e-9 of the profile may go either way: counted apart).
                    std::size_t inside = 0, ties = 0;
                    const auto rows = static_cast<int>(std::llround(length / h));
                    const auto columns = static_cast<int>(std::llround((plane ? 2.0 * R : R) / h));
                    for (int kz = 0; kz < rows; ++kz) {
                        const double height = (kz + 0.5) * h;
                        const double s_nose = nose.end < 0 ? L_of(nose, R) - height : height - (length - L_of(nose, R));
                        const double r = profile(nose, R, s_nose);
                        for (int kx = 0; kx < columns; ++kx) {
                            const double x = plane ? -R + (kx + 0.5) * h : (kx + 0.5) * h;
                            if (std::abs(std::abs(x) - r) < 1e-9 * R) ++ties;
                            else if (std::abs(x) < r) ++inside;
                        }
                    }
                    EXPECT_GE(shaped.nodes, inside);
                    EXPECT_LE(shaped.nodes, inside + ties);
                }
                // The nose removes the part of the end segment (length L) outside its profile. The
                // shank's cells are the same in both fills, so the difference is that removed part
                // to within the cells the nose's surface cuts: those lie within half a cell diagonal
                // (sqrt(D) h / 2) of it, so the error is at most a band of that half-width on either
                // side of the surface, whose area is at most that of the segment's boundary (the nose
                // is convex and inside the segment): 2 pi R L + pi R^2 (axisymmetric: the meridian's
                // length R + L times the largest ring circumference 2 pi R; plane strain: 2 L + 2 R).
                const double L = nose_length(nose, R);
                const double segment = plane ? 2.0 * R * L : pi * R * R * L;
                const double removed = segment - nose_measure(nose, R, plane);
                const double surface = plane ? 2.0 * L + 2.0 * R : g == GeometryKind::Axisymmetric ? 2.0 * pi * R * (L + R)
                                                                                                    : 2.0 * pi * R * L + pi * R * R;
                const double band = 2.0 * std::sqrt(static_cast<double>(dim)) / 2.0 * h * surface;
                EXPECT_NEAR(flat.volume - shaped.volume, removed, band)
                    << "removed " << flat.volume - shaped.volume << " against the closed form " << removed;
                // The whole body, and its mass, against the closed form: the flat cylinder's lattice
                // fits its length and radius exactly (axisymmetric, plane strain) or within its round
                // section's band (3D).
                const double whole = (plane ? 2.0 * R : pi * R * R) * (length - L) + nose_measure(nose, R, plane);
                const double whole_band = band + (dim == 3 ? std::sqrt(3.0) * h * 2.0 * pi * R * length : 0.0);
                EXPECT_NEAR(shaped.volume, whole, whole_band);
                EXPECT_NEAR(shaped.mass, density * shaped.volume, 1e-12 * shaped.mass);
                (divisions == (dim == 3 ? 4.0 : 8.0) ? coarse : fine) +=
                    divisions == (dim == 3 ? 6.0 : 16.0) ? 0.0 : std::abs(flat.volume - shaped.volume - removed) / removed / 4.0;
            }
        }
        // Convergence in 2D: from 8 to 32 cells across the radius the nose's volume error falls
        // (measured: 3.0 % to 0.37 % axisymmetric, 4.3 % to 0.43 % plane strain). In 3D, at 4 to 8
        // cells across, the error stays within the band above but does not yet fall steadily.
        if (dim == 2) {
            EXPECT_LT(fine, 0.5 * coarse) << name_of(g) << ": " << coarse << " at R/8, " << fine << " at R/32";
        }
    }
}

// The overlap check (validate_scene) sees the nose: a disc beside a cone's tip, inside the
// cylinder the nose was cut from, does not overlap the projectile (plane strain, where a disc may
// sit off the axis); without the nose it would, and moved next to the axis it does.
TEST(Noses, TheOverlapCheckSeesTheNose) {
    Scene s;
    s.geometry = GeometryKind::PlaneStrain;
    s.materials.push_back(testing::elastic_material("steel", 7830.0, 200e9, 0.29));
    BodySpec projectile;
    projectile.name = "projectile";
    projectile.shape = ShapeKind::Cylinder;
    projectile.material = "steel";
    projectile.origin = {0.0, 10e-3, 0.0};
    projectile.radius = 5e-3;
    projectile.length = 20e-3;
    projectile.spacing = 0.25e-3;
    NoseSpec cone;
    cone.kind = NoseKind::Cone;
    cone.length = 10e-3;
    projectile.nose = cone;
    BodySpec disc;
    disc.name = "disc";
    disc.shape = ShapeKind::Sphere;
    disc.material = "steel";
    disc.origin = {4e-3, 11e-3, 0.0};  // x 3..5 mm, z 10..12 mm; the cone's half-width there is at most 1 mm
    disc.radius = 1e-3;
    disc.spacing = 0.25e-3;
    s.bodies = {projectile, disc};
    s.stop.end_time = 1e-6;
    EXPECT_NO_THROW(validate_scene(s));
    Scene flat = s;
    flat.bodies[0].nose.reset();
    EXPECT_THROW(validate_scene(flat), InputError);
    s.bodies[1].origin = {1e-3, 11e-3, 0.0};
    EXPECT_THROW(validate_scene(s), InputError);
}

}  // namespace
}  // namespace gpa
