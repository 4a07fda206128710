// Bodies filled from a closed triangulated surface (surface.hpp; shape "surface"): the inside test
// against an independent one (the planes of a convex polyhedron) at every lattice point of a
// geodesic sphere, and at points on its edges and vertices; a cube's surface fills exactly the
// nodes of the box of the same size, moved by its origin; the triangles' orientation does not
// matter; open, self-meeting and degenerate surfaces are refused with their reason; a surface body
// runs.

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/surface.hpp"
#include "support/scenes.hpp"

namespace gpa {
namespace {

using Point = std::array<double, 3>;

// The 12 triangles of the box [0, a] x [0, b] x [0, c], outward.
TriangleSurface box_surface(double a, double b, double c) {
    TriangleSurface s;
    for (int k = 0; k < 8; ++k) s.vertices.push_back({(k & 1) * a, ((k >> 1) & 1) * b, ((k >> 2) & 1) * c});
    // Each face as two triangles (corner indices: bit 0 x, bit 1 y, bit 2 z).
    const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
        s.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[1]), std::uint32_t(f[2])});
        s.triangles.push_back({std::uint32_t(f[0]), std::uint32_t(f[2]), std::uint32_t(f[3])});
    }
    return s;
}
TriangleSurface cube(double a) { return box_surface(a, a, a); }

// A geodesic sphere: an icosahedron whose triangles are split `levels` times, corners pushed onto
// the sphere of radius r about c (a convex polyhedron inside it).
TriangleSurface geodesic_sphere(double r, const Point& c, int levels) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Point> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::array<std::uint32_t, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    const auto unit = [](Point p) {
        const double n = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        return Point{p[0] / n, p[1] / n, p[2] / n};
    };
    for (auto& p : v) p = unit(p);
    for (int l = 0; l < levels; ++l) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> middle;
        const auto mid = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = middle.find(key);
            if (it != middle.end()) return it->second;
            v.push_back(unit({v[a][0] + v[b][0], v[a][1] + v[b][1], v[a][2] + v[b][2]}));
            return middle[key] = static_cast<std::uint32_t>(v.size() - 1);
        };
        std::vector<std::array<std::uint32_t, 3>> next;
        for (const auto& tri : f) {
            const std::uint32_t a = mid(tri[0], tri[1]), b = mid(tri[1], tri[2]), cc = mid(tri[2], tri[0]);
            next.push_back({tri[0], a, cc});
            next.push_back({tri[1], b, a});
            next.push_back({tri[2], cc, b});
            next.push_back({a, b, cc});
        }
        f = std::move(next);
    }
    TriangleSurface s;
    for (const auto& p : v) s.vertices.push_back({c[0] + r * p[0], c[1] + r * p[1], c[2] + r * p[2]});
    s.triangles = f;
    return s;
}

// Inside a convex polyhedron: on the inner side of every triangle's plane (the centroid's side);
// `margin` > 0 reports points within it of a plane as undecided.
enum class Side { In, Out, Undecided };
Side convex_side(const TriangleSurface& s, const Point& p, double margin) {
    Point centroid{0, 0, 0};
    for (const auto& v : s.vertices) {
        for (int c = 0; c < 3; ++c) centroid[c] += v[c] / static_cast<double>(s.vertices.size());
    }
    bool near = false;
    for (const auto& tri : s.triangles) {
        const Point& a = s.vertices[tri[0]];
        const Point& b = s.vertices[tri[1]];
        const Point& c = s.vertices[tri[2]];
        const Point u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, w{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        Point n{u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const auto height = [&](const Point& q) { return (n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - a[2])) / len; };
        const double sign = height(centroid) < 0.0 ? 1.0 : -1.0;  // negative inside
        const double h = sign * height(p);
        if (h > margin) return Side::Out;
        if (h > -margin) near = true;
    }
    return near ? Side::Undecided : Side::In;
}

std::shared_ptr<const SurfaceInside> ready(TriangleSurface s) {
    check_surface(s, "test surface");
    return std::make_shared<SurfaceInside>(std::make_shared<TriangleSurface>(std::move(s)));
}

TEST(Surface, TheInsideTestAgreesWithTheConvexPlanesAtEveryLatticePointOfAGeodesicSphere) {
    const Point centre{1e-3, -2e-3, 0.5e-3};
    const TriangleSurface sphere = geodesic_sphere(5e-3, centre, 3);  // 1280 triangles
    ASSERT_EQ(sphere.triangles.size(), 1280u);
    const auto inside = ready(sphere);
    std::size_t in = 0, decided = 0;
    // A lattice whose points are offset by an odd fraction of the spacing, so that a few fall
    // close to the edges and vertices in projection.
    const double s = 0.37e-3;
    for (int i = -16; i <= 16; ++i) {
        for (int j = -16; j <= 16; ++j) {
            for (int k = -16; k <= 16; ++k) {
                const Point p{centre[0] + i * s + 0.1e-6, centre[1] + j * s, centre[2] + k * s + 0.05e-6};
                const Side side = convex_side(sphere, p, 1e-12);
                if (side == Side::Undecided) continue;
                ++decided;
                ASSERT_EQ(inside->inside(p), side == Side::In) << p[0] << " " << p[1] << " " << p[2];
                in += side == Side::In;
            }
        }
    }
    EXPECT_GT(in, 10000u);
    EXPECT_GT(decided, 35000u);
    // Columns through the projected vertices and edges of the surface: the ray is counted once,
    // never twice (the top-left rule), at heights inside and outside.
    for (std::size_t t = 0; t < sphere.triangles.size(); t += 7) {
        const Point& a = sphere.vertices[sphere.triangles[t][0]];
        const Point& b = sphere.vertices[sphere.triangles[t][1]];
        for (const Point& q : {a, Point{0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.0}}) {
            for (const double z : {centre[2] - 6e-3, centre[2] - 0.1e-3, centre[2] + 0.2e-3, centre[2] + 6e-3}) {
                const Point p{q[0], q[1], z};
                const Side side = convex_side(sphere, p, 1e-12);
                if (side == Side::Undecided) continue;
                EXPECT_EQ(inside->inside(p), side == Side::In) << "column through triangle " << t;
            }
        }
    }
    // The enclosed volume: below the sphere's by the facets' cut (1280 facets: about 0.7 %).
    const double sphere_volume = 4.0 / 3.0 * 3.141592653589793 * 125e-9;
    EXPECT_LT(enclosed_volume(sphere), sphere_volume);
    EXPECT_GT(enclosed_volume(sphere), 0.98 * sphere_volume);
}

// The closed surface of a union of unit voxels (x, y, z in [0, n)), each square face split along
// one of its two diagonals by `pick`; empty when the union's surface is not a manifold (voxels that
// touch along an edge only).
TriangleSurface voxel_surface(const std::vector<int>& filled, int n, double unit, unsigned pick) {
    const auto at = [&](int x, int y, int z) {
        return x >= 0 && y >= 0 && z >= 0 && x < n && y < n && z < n && filled[static_cast<std::size_t>((z * n + y) * n + x)] != 0;
    };
    TriangleSurface s;
    std::map<Point, std::uint32_t> index;
    const auto vertex = [&](int x, int y, int z) {
        const Point p{x * unit, y * unit, z * unit};
        const auto [it, added] = index.try_emplace(p, static_cast<std::uint32_t>(s.vertices.size()));
        if (added) s.vertices.push_back(p);
        return it->second;
    };
    unsigned face = 0;
    for (int z = 0; z < n; ++z) {
        for (int y = 0; y < n; ++y) {
            for (int x = 0; x < n; ++x) {
                if (!at(x, y, z)) continue;
                for (int axis = 0; axis < 3; ++axis) {
                    for (const int dir : {-1, 1}) {
                        int q[3] = {x, y, z};
                        q[axis] += dir;
                        if (at(q[0], q[1], q[2])) continue;
                        // The face's corners, in order around it.
                        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
                        std::array<std::uint32_t, 4> c{};
                        for (int k = 0; k < 4; ++k) {
                            int p[3] = {x, y, z};
                            p[axis] += dir > 0 ? 1 : 0;
                            p[u] += (k == 1 || k == 2) ? 1 : 0;
                            p[v] += (k >= 2) ? 1 : 0;
                            c[static_cast<std::size_t>(k)] = vertex(p[0], p[1], p[2]);
                        }
                        if (((pick >> (face++ % 31)) & 1u) != 0) {
                            s.triangles.push_back({c[0], c[1], c[2]});
                            s.triangles.push_back({c[0], c[2], c[3]});
                        } else {
                            s.triangles.push_back({c[0], c[1], c[3]});
                            s.triangles.push_back({c[1], c[2], c[3]});
                        }
                    }
                }
            }
        }
    }
    try {
        check_surface(s, "voxels");
    } catch (const InputError&) {
        return {};
    }
    return s;
}

// The test is exact where rounding would decide: lattice points on the projection of the faces'
// diagonals (x = y, as at the centre of every 4 x 4 column) and on the projections of vertical
// faces, for unions of voxels with cavities, holes through them and separate parts, placed at an
// origin that makes the arithmetic inexact. (Before the exact predicates, a 3 x 1 x 2 mm box lost
// a column of 4 nodes on its faces' diagonal.)
TEST(Surface, UnionsOfVoxelsAreFilledExactlyWhateverTheirFacesDiagonals) {
    const int n = 4;
    const double unit = 1e-3;
    const Point offset{0.123456789e-3, -7.3e-3, 11.1e-3};
    std::size_t checked = 0, surfaces = 0;
    unsigned seed = 12345;
    const auto next = [&] { return seed = seed * 1103515245u + 12345u; };
    for (int trial = 0; trial < 400 && surfaces < 40; ++trial) {
        // A solid block with random voxels taken out (cavities, notches, holes through it) or, every
        // other trial, sparse voxels (separate parts, L-shapes); unions whose surface is not a
        // manifold are skipped.
        std::vector<int> filled(static_cast<std::size_t>(n * n * n));
        const bool block = trial % 2 == 0;
        for (int& f : filled) f = block ? (next() >> 16) % 5 != 0 : (next() >> 16) % 6 == 0;
        if (trial == 0) std::fill(filled.begin(), filled.end(), 1);
        TriangleSurface s = voxel_surface(filled, n, unit, next());
        if (s.triangles.empty()) continue;
        ++surfaces;
        for (auto& v : s.vertices) {
            for (int c = 0; c < 3; ++c) v[c] += offset[c];
        }
        const auto inside = ready(s);
        for (int i = 0; i < 2 * n; ++i) {
            for (int j = 0; j < 2 * n; ++j) {
                for (int k = 0; k < 2 * n; ++k) {
                    // Quarter points: on the diagonals' projections when i = j.
                    const Point p{offset[0] + (i + 0.5) * 0.5 * unit, offset[1] + (j + 0.5) * 0.5 * unit, offset[2] + (k + 0.5) * 0.5 * unit};
                    const bool expected = filled[static_cast<std::size_t>(((k / 2) * n + j / 2) * n + i / 2)] != 0;
                    ASSERT_EQ(inside->inside(p), expected) << "trial " << trial << " point " << i << " " << j << " " << k;
                    ++checked;
                }
            }
        }
    }
    EXPECT_GT(surfaces, 5u);
    EXPECT_EQ(checked, surfaces * 512u);
}

// Boxes of 1 to 6 half-millimetres along each edge, filled at 0.5 mm: every cell centre is inside.
// (Rounding decided the points on the faces' diagonals before the exact predicates: a 3 x 1 x 2 mm
// box lost the column of 4 nodes on its top and bottom faces' diagonal.)
TEST(Surface, EveryBoxFromItsTwelveTrianglesHoldsEveryCellCentre) {
    const double s = 0.5e-3;
    for (int a = 1; a <= 6; ++a) {
        for (int b = 1; b <= 6; ++b) {
            for (int c = 1; c <= 6; ++c) {
                const auto inside = ready(box_surface(a * s, b * s, c * s));
                std::size_t missing = 0;
                for (int i = 0; i < a; ++i) {
                    for (int j = 0; j < b; ++j) {
                        for (int k = 0; k < c; ++k) missing += !inside->inside({(i + 0.5) * s, (j + 0.5) * s, (k + 0.5) * s});
                    }
                }
                EXPECT_EQ(missing, 0u) << a * 0.5 << " x " << b * 0.5 << " x " << c * 0.5 << " mm";
            }
        }
    }
}

TEST(Surface, TheTrianglesOrientationDoesNotMatter) {
    TriangleSurface sphere = geodesic_sphere(2e-3, {0, 0, 0}, 2);
    const auto outward = ready(sphere);
    for (std::size_t t = 0; t < sphere.triangles.size(); t += 3) std::swap(sphere.triangles[t][1], sphere.triangles[t][2]);
    const auto mixed = ready(sphere);
    for (int i = -12; i <= 12; ++i) {
        for (int k = -12; k <= 12; ++k) {
            const Point p{i * 0.19e-3, 0.03e-3 * i, k * 0.19e-3};
            EXPECT_EQ(outward->inside(p), mixed->inside(p));
        }
    }
}

Scene surface_and_box_scene(const Point& origin) {
    Scene s = testing::pulled_elastic_bar(GeometryKind::ThreeD, 2e-3, 4e-3, 4, 0.0, 0.0, 0.3);
    s.prescribed_velocities.clear();
    BodySpec& box = s.bodies[0];
    box.origin = origin;
    box.size = {4e-3, 4e-3, 4e-3};
    box.spacing = 0.5e-3;
    BodySpec surface = box;
    surface.name = "surface";
    surface.shape = ShapeKind::Surface;
    surface.size = {0, 0, 0};
    surface.surface_file = "cube (in code)";
    surface.surface = ready(cube(4e-3));
    surface.origin = {origin[0], origin[1], origin[2] + 10e-3};  // above the box
    s.bodies.push_back(surface);
    return s;
}

TEST(Surface, ACubesSurfaceFillsTheNodesOfTheBoxOfItsSizeMovedByItsOrigin) {
    const Scene scene = surface_and_box_scene({-1e-3, 0.5e-3, 2e-3});
    Simulation sim(scene, 1);
    std::array<std::vector<Point>, 2> nodes;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        const int b = sim.nodes().body[i];
        nodes[static_cast<std::size_t>(b)].push_back(
            {sim.nodes().initial_position[0][i], sim.nodes().initial_position[1][i], sim.nodes().initial_position[2][i] - 10e-3 * b});
    }
    ASSERT_EQ(nodes[0].size(), 512u);
    ASSERT_EQ(nodes[1].size(), 512u);
    std::sort(nodes[0].begin(), nodes[0].end());
    std::sort(nodes[1].begin(), nodes[1].end());
    for (std::size_t k = 0; k < nodes[0].size(); ++k) {
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(nodes[1][k][c], nodes[0][k][c], 1e-15) << k;  // the 10 mm shift's round-off
    }
}

TEST(Surface, OpenSelfMeetingDegenerateAndNonFiniteSurfacesAreRefusedWithTheirReason) {
    const auto refusal = [](const TriangleSurface& s) {
        try {
            check_surface(s, "part.stl");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_EQ(refusal(cube(1.0)), "");
    TriangleSurface open = cube(1.0);
    open.triangles.pop_back();
    EXPECT_NE(refusal(open).find("has a hole"), std::string::npos) << refusal(open);
    EXPECT_NE(refusal(open).find("part.stl"), std::string::npos);
    TriangleSurface twice = cube(1.0);
    twice.triangles.push_back(twice.triangles.front());
    EXPECT_NE(refusal(twice).find("meets itself"), std::string::npos) << refusal(twice);
    TriangleSurface flat = cube(1.0);
    flat.triangles[3] = {0, 0, 1};
    EXPECT_NE(refusal(flat).find("has no area"), std::string::npos) << refusal(flat);
    TriangleSurface not_finite = cube(1.0);
    not_finite.vertices[5][1] = std::nan("");
    EXPECT_NE(refusal(not_finite).find("vertex 5 is not finite"), std::string::npos) << refusal(not_finite);
    EXPECT_NE(refusal(TriangleSurface{}).find("at least 4"), std::string::npos);
    // A body whose surface was never read.
    Scene scene = surface_and_box_scene({0, 0, 0});
    scene.bodies[1].surface.reset();
    try {
        Simulation sim(scene, 1);
        ADD_FAILURE() << "a surface body without its surface ran";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("has not been read"), std::string::npos) << e.what();
    }
}

TEST(Surface, ASurfaceBodyRunsIntoARigidPlaneWithItsMomentumKept) {
    Scene scene = surface_and_box_scene({0, 0, 1e-3});
    scene.bodies.erase(scene.bodies.begin());  // the surface alone, from z = 11 mm up
    scene.bodies[0].velocity = {0.0, 0.0, -100.0};
    PlaneSpec floor;
    floor.name = "floor";
    floor.axis = 2;
    floor.position = 11e-3;  // the cube's lower face: its first nodes half a spacing above
    scene.planes.push_back(floor);
    scene.stop = {};
    scene.stop.max_steps = 60;
    Simulation sim(scene, 2);
    while (!sim.finished()) sim.step();
    const Totals& t = sim.totals();
    // Along x and y nothing acts on the cube but pair forces (and the frictionless floor): round-off.
    EXPECT_LT(std::abs(t.momentum[0]), 1e-12 * std::abs(t.momentum[2]) + 1e-15);
    EXPECT_LT(std::abs(t.momentum[1]), 1e-12 * std::abs(t.momentum[2]) + 1e-15);
    EXPECT_GT(t.planes.at(0).impulse, 0.0);  // it reached the floor
    EXPECT_LT(std::abs(t.energy_error), 1e-9);
}

}  // namespace
}  // namespace gpa
