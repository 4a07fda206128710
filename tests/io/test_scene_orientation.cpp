// Scene files with bodies and planes in any orientation (docs/scene-format.md, "Orientation"):
// planes given by a normal and a point, body rotations, the top-level rotation of the whole scene,
// and the messages for each form the reader refuses, naming file, line and key.

#include <cmath>
#include <numbers>
#include <string>
#include <string_view>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/io/scene_file.hpp"

namespace gpa::io {
namespace {
// A namespace of its own: in a unity build the helpers below would meet test_scene_file.cpp's.
namespace orientation_files {

constexpr double pi = std::numbers::pi;

std::string error_of(std::string_view text) {
    try {
        parse_scene(text, "turned.toml");
    } catch (const SceneError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no SceneError for:\n" << text;
    return {};
}

// The 1-based line of the first line of `text` that holds `marker`.
std::size_t line_with(std::string_view text, std::string_view marker) {
    const std::size_t at = text.find(marker);
    EXPECT_NE(at, std::string_view::npos) << marker;
    std::size_t line = 1;
    for (std::size_t i = 0; i < at && i < text.size(); ++i) line += text[i] == '\n';
    return line;
}

// The start of "file:line: key: " that a message about `marker`'s line and `key` begins with.
std::string where(std::string_view text, std::string_view marker, std::string_view key) {
    return fmt::format("turned.toml:{}: {}: ", line_with(text, marker), key);
}

// Scenes of one elastic block (a rectangle 4 mm square at z = 10 mm in 2D, a 4 mm cube at z = 1 mm
// in 3D); `top` goes before the tables (top-level keys), `tables` after the body.
const std::string rubber = R"toml(
[[material]]
name = "rubber"
density = 1000
shear_modulus = "1 MPa"
eos = { model = "linear", bulk_modulus = "10 MPa" }
strength = "elastic"
)toml";

std::string scene_2d(std::string_view top, std::string_view body_extra, std::string_view tables,
                     std::string_view geometry = "plane-strain") {
    return fmt::format(R"toml(geometry = "{}"
{}
[stop]
end_time = "10 us"
{}
[[body]]
name = "block"
shape = "rectangle"
material = "rubber"
origin = ["1 mm", "10 mm"]
size = ["4 mm", "4 mm"]
spacing = "1 mm"
{}
{})toml",
                       geometry, top, rubber, body_extra, tables);
}

std::string scene_3d(std::string_view top, std::string_view body_extra, std::string_view tables) {
    return fmt::format(R"toml(geometry = "3d"
{}
[stop]
end_time = "10 us"
{}
[[body]]
name = "block"
shape = "box"
material = "rubber"
origin = ["1 mm", 0, "1 mm"]
size = ["4 mm", "4 mm", "4 mm"]
spacing = "1 mm"
{}
{})toml",
                       top, rubber, body_extra, tables);
}

void expect_rotation_near(const Rotation& got, const Rotation& want) {
    for (std::size_t k = 0; k < 9; ++k) EXPECT_NEAR(got[k], want[k], 1e-15) << "entry " << k;
}

TEST(SceneFileOrientation, AnObliqueNormalIsMadeAUnitVectorAndThePointGivesThePosition) {
    const Scene s = parse_scene(scene_2d("", "", R"toml(
[[plane]]
name = "ramp"
kind = "rigid"
normal = [3, 4]
point = ["1 mm", "2 mm"]
)toml"),
                                "turned.toml");
    ASSERT_EQ(s.planes.size(), 1u);
    const PlaneSpec& p = s.planes[0];
    EXPECT_EQ(p.axis, -1);
    EXPECT_DOUBLE_EQ(p.normal[0], 0.6);
    EXPECT_DOUBLE_EQ(p.normal[1], 0.8);
    EXPECT_EQ(p.normal[2], 0.0);
    EXPECT_DOUBLE_EQ(p.position, 0.6 * 1e-3 + 0.8 * 2e-3);
    EXPECT_EQ(p.side, 1);
    EXPECT_EQ(plane_normal(p), p.normal);

    // In 3D, of any length, however large.
    const Scene big = parse_scene(scene_3d("", "", R"toml(
[[plane]]
name = "ramp"
kind = "symmetry"
normal = [1e300, 0, 1e300]
point = [0, 0, 0]
side = "above"
)toml"),
                                  "turned.toml");
    EXPECT_EQ(big.planes[0].axis, -1);
    EXPECT_DOUBLE_EQ(big.planes[0].normal[0], std::sqrt(0.5));
    EXPECT_EQ(big.planes[0].normal[1], 0.0);
    EXPECT_DOUBLE_EQ(big.planes[0].normal[2], std::sqrt(0.5));
    EXPECT_EQ(big.planes[0].position, 0.0);
}

TEST(SceneFileOrientation, ANormalAlongAnAxisIsTheAxisForm) {
    // -z, of length 2, through z = 20 mm: the plane z = 20 mm with the bodies below it.
    const Scene s = parse_scene(scene_3d("", "", R"toml(
[[plane]]
name = "lid"
kind = "rigid"
normal = [0, 0, -2]
point = ["7 mm", "-3 mm", "20 mm"]
)toml"),
                                "turned.toml");
    const PlaneSpec& lid = s.planes[0];
    EXPECT_EQ(lid.axis, 2);
    EXPECT_EQ(lid.position, 0.02);
    EXPECT_EQ(lid.side, -1);

    // The same plane as axis = "z" would give, field for field.
    const Scene same = parse_scene(scene_3d("", "", R"toml(
[[plane]]
name = "lid"
kind = "rigid"
axis = "z"
position = "20 mm"
side = "below"
)toml"),
                                   "turned.toml");
    EXPECT_EQ(same.planes[0].axis, lid.axis);
    EXPECT_EQ(same.planes[0].position, lid.position);
    EXPECT_EQ(same.planes[0].side, lid.side);
    EXPECT_EQ(same.planes[0].normal, lid.normal);

    // In 2D, -x with side "below": the bodies lie where -x < -0.5 mm, above x = 0.5 mm.
    const Scene wall = parse_scene(scene_2d("", "", R"toml(
[[plane]]
name = "wall"
kind = "rigid"
normal = [-1, 0]
point = ["0.5 mm", "3 mm"]
side = "below"
)toml"),
                                   "turned.toml");
    EXPECT_EQ(wall.planes[0].axis, 0);
    EXPECT_EQ(wall.planes[0].position, 0.0005);
    EXPECT_EQ(wall.planes[0].side, 1);

    // An axisymmetric scene takes a normal along x or z.
    const Scene round = parse_scene(scene_2d("", "", R"toml(
[[plane]]
name = "anvil"
kind = "rigid"
normal = [0, 5]
point = [0, "1 mm"]
)toml",
                                             "axisymmetric"),
                                    "turned.toml");
    EXPECT_EQ(round.planes[0].axis, 1);
    EXPECT_EQ(round.planes[0].position, 0.001);
    EXPECT_EQ(round.planes[0].side, 1);
}

TEST(SceneFileOrientation, BodyRotationsAreReadInDegreesOrRadians) {
    const Scene s = parse_scene(scene_3d("", R"toml(rotation = { axis = [0, 0, 3], angle = "90 deg" })toml", ""), "turned.toml");
    expect_rotation_near(s.bodies[0].rotation, rotation_about({0, 0, 1}, pi / 2));
    EXPECT_EQ(s.bodies[0].origin, (std::array<double, 3>{0.001, 0.0, 0.001}));  // a body turns about its own origin

    // A plain number is radians; the degree sign and the words are read too.
    const Scene r = parse_scene(scene_3d("", R"toml(rotation = { axis = [1, 1, 0], angle = 0.5 })toml", ""), "turned.toml");
    expect_rotation_near(r.bodies[0].rotation, rotation_about({1, 1, 0}, 0.5));
    for (const char* angle : {"\"30\u00B0\"", "\"30 degrees\"", "\"0.5235987755982988 rad\""}) {
        const Scene d = parse_scene(scene_3d("", fmt::format("rotation = {{ axis = [0, 1, 0], angle = {} }}", angle), ""), "turned.toml");
        expect_rotation_near(d.bodies[0].rotation, rotation_about({0, 1, 0}, pi / 6));
    }

    // Plane strain: an angle alone, from x towards z.
    const Scene p = parse_scene(scene_2d("", R"toml(rotation = { angle = "-45 deg" })toml", ""), "turned.toml");
    expect_rotation_near(p.bodies[0].rotation, rotation_in_plane(-pi / 4));

    // None given: exactly the identity.
    EXPECT_TRUE(is_identity(parse_scene(scene_3d("", "", ""), "turned.toml").bodies[0].rotation));
}

TEST(SceneFileOrientation, TheTopLevelRotationTurnsTheWholeScene) {
    const std::string plane = R"toml(
[[plane]]
name = "floor"
kind = "rigid"
axis = "z"
position = 0
)toml";
    // A quarter turn about z takes the body's origin (1 mm, 0, 1 mm) to (0, 1 mm, 1 mm).
    const Scene s = parse_scene(scene_3d(R"toml(rotation = { axis = [0, 0, 1], angle = "90 deg" })toml", "", plane), "turned.toml");
    EXPECT_NEAR(s.bodies[0].origin[0], 0.0, 1e-18);
    EXPECT_NEAR(s.bodies[0].origin[1], 0.001, 1e-18);
    EXPECT_NEAR(s.bodies[0].origin[2], 0.001, 1e-18);
    expect_rotation_near(s.bodies[0].rotation, rotation_about({0, 0, 1}, pi / 2));
    // The floor is turned in itself: the same plane.
    const auto n = plane_normal(s.planes[0]);
    EXPECT_NEAR(n[0], 0.0, 1e-15);
    EXPECT_NEAR(n[1], 0.0, 1e-15);
    EXPECT_NEAR(n[2], 1.0, 1e-15);
    EXPECT_EQ(s.planes[0].position, 0.0);

    // Plane strain: from x towards z, the origin (1 mm, 10 mm) to (-10 mm, 1 mm).
    const Scene p = parse_scene(scene_2d(R"toml(rotation = { angle = "90 deg" })toml", "", ""), "turned.toml");
    EXPECT_NEAR(p.bodies[0].origin[0], -0.01, 1e-17);
    EXPECT_NEAR(p.bodies[0].origin[1], 0.001, 1e-17);
    expect_rotation_near(p.bodies[0].rotation, rotation_in_plane(pi / 2));
}

TEST(SceneFileOrientation, PlaneFormsThatDoNotFitAreRefusedAtTheirLine) {
    const auto plane_with = [](std::string_view keys) {
        return scene_2d("", "", fmt::format("[[plane]]\nname = \"ramp\"\nkind = \"rigid\"\n{}\n", keys));
    };
    const std::string both = plane_with("axis = \"z\"\nnormal = [1, 1]\npoint = [0, 0]");
    EXPECT_EQ(error_of(both), where(both, "normal =", "plane \"ramp\" (plane[0]).normal") +
                                  "give axis and position, or normal and point, not both");

    const std::string no_point = plane_with("normal = [1, 1]");
    EXPECT_EQ(error_of(no_point), where(no_point, "[[plane]]", "plane \"ramp\" (plane[0])") +
                                      "missing required key \"point\": a point on the plane, [x, z] with units (with normal)");

    const std::string no_normal = plane_with("axis = \"z\"\nposition = 0\npoint = [0, 0]");
    EXPECT_EQ(error_of(no_normal), where(no_normal, "point =", "plane \"ramp\" (plane[0]).point") +
                                       "applies with normal (a plane through a point, normal to a direction); with axis give position");

    const std::string position = plane_with("normal = [1, 1]\nposition = 0\npoint = [0, 0]");
    EXPECT_EQ(error_of(position), where(position, "position =", "plane \"ramp\" (plane[0]).position") +
                                      "applies with axis; a plane given by its normal takes point = [x, z] (any point on it) instead");

    const std::string zero = plane_with("normal = [0, 0.0]\npoint = [0, 0]");
    EXPECT_EQ(error_of(zero), where(zero, "normal =", "plane \"ramp\" (plane[0]).normal") +
                                  "is a zero vector: a normal needs a direction, [x, z] of any length");

    const std::string not_finite = plane_with("normal = [nan, 1]\npoint = [0, 0]");
    EXPECT_EQ(error_of(not_finite), where(not_finite, "normal =", "plane \"ramp\" (plane[0]).normal[0]") +
                                        "nan is not allowed: a number must be finite");
    const std::string infinite = plane_with("normal = [1, inf]\npoint = [0, 0]");
    EXPECT_NE(error_of(infinite).find(where(infinite, "normal =", "plane \"ramp\" (plane[0]).normal[1]")), std::string::npos);

    const std::string three = plane_with("normal = [0, 0, 1]\npoint = [0, 0]");
    EXPECT_EQ(error_of(three), where(three, "normal =", "plane \"ramp\" (plane[0]).normal") +
                                   "expected an array of 2 numbers [x, z], got 3 values");
    const std::string short_point = plane_with("normal = [1, 1]\npoint = [0]");
    EXPECT_EQ(error_of(short_point), where(short_point, "point =", "plane \"ramp\" (plane[0]).point") +
                                         "expected an array of 2 length values [x, z], got 1 value");
    const std::string unit = plane_with("normal = [\"1 mm\", 1]\npoint = [0, 0]");
    EXPECT_NE(error_of(unit).find(where(unit, "normal =", "plane \"ramp\" (plane[0]).normal[0]")), std::string::npos);

    const std::string oblique = scene_2d("", "", "[[plane]]\nname = \"ramp\"\nkind = \"rigid\"\nnormal = [1, 1]\npoint = [0, 0]\n",
                                         "axisymmetric");
    EXPECT_EQ(error_of(oblique), where(oblique, "normal =", "plane \"ramp\" (plane[0]).normal") +
                                     "is oblique: an axisymmetric scene takes planes normal to x or z only (a plane there turns "
                                     "about the axis), normal = [1, 0] or [0, 1]");

    const std::string neither = plane_with("side = 1");
    EXPECT_EQ(error_of(neither), where(neither, "[[plane]]", "plane \"ramp\" (plane[0])") +
                                     "missing required key \"axis\": the plane's normal: x or z (or normal = [x, z] with point = [x, z])");
}

TEST(SceneFileOrientation, RotationsThatDoNotFitAreRefusedAtTheirLine) {
    const std::string body = "body \"block\" (body[0]).rotation";
    const std::string axisymmetric = scene_2d("", "rotation = { angle = \"10 deg\" }", "", "axisymmetric");
    EXPECT_EQ(error_of(axisymmetric), where(axisymmetric, "rotation =", body) +
                                          "does not apply to a body in an axisymmetric scene: its symmetry axis is fixed along z "
                                          "(bodies and scenes turn in plane-strain and 3d scenes)");
    const std::string top = scene_2d("rotation = { angle = \"10 deg\" }", "", "", "axisymmetric");
    EXPECT_EQ(error_of(top), where(top, "rotation =", "rotation") +
                                 "does not apply to an axisymmetric scene: its symmetry axis is fixed along z (bodies and scenes "
                                 "turn in plane-strain and 3d scenes)");

    const std::string axis_2d = scene_2d("", "rotation = { axis = [0, 1, 0], angle = \"10 deg\" }", "");
    EXPECT_EQ(error_of(axis_2d), where(axis_2d, "rotation =", body + ".axis") +
                                     "does not apply in a plane-strain scene: a rotation there turns the (x, z) plane about y; "
                                     "give angle only (positive from x towards z)");

    const std::string no_axis = scene_3d("", "rotation = { angle = \"10 deg\" }", "");
    EXPECT_EQ(error_of(no_axis), where(no_axis, "rotation =", body) +
                                     "missing required key \"axis\": the direction the rotation turns about, [x, y, z] of any "
                                     "length, e.g. [0, 0, 1]");
    const std::string zero_axis = scene_3d("", "rotation = { axis = [0, 0, 0], angle = \"10 deg\" }", "");
    EXPECT_EQ(error_of(zero_axis), where(zero_axis, "rotation =", body + ".axis") +
                                       "is a zero vector: give a direction to turn about, [x, y, z] of any length, e.g. [0, 0, 1]");
    const std::string no_angle = scene_3d("", "rotation = { axis = [0, 0, 1] }", "");
    EXPECT_NE(error_of(no_angle).find(where(no_angle, "rotation =", body) + "missing required key \"angle\": an angle"),
              std::string::npos);

    const std::string length = scene_3d("", "rotation = { axis = [0, 0, 1], angle = \"30 mm\" }", "");
    EXPECT_NE(error_of(length).find(where(length, "rotation =", body + ".angle") + "\"30 mm\" is a length, not an angle"),
              std::string::npos);
    const std::string plain = scene_3d("", "rotation = { axis = [0, 0, 1], angle = 30 }", "");
    EXPECT_EQ(error_of(plain), where(plain, "rotation =", body + ".angle") +
                                   "30 rad (1718.87 deg) is more than a full turn: give an angle from -360 to 360 deg (a plain "
                                   "number is in radians; write degrees as \"30 deg\")");
    const std::string not_table = scene_3d("", "rotation = \"30 deg\"", "");
    EXPECT_EQ(error_of(not_table), where(not_table, "rotation =", body) +
                                       "expected a table such as { axis = [0, 0, 1], angle = \"30 deg\" }, got \"30 deg\"");
    const std::string typo = scene_3d("", "rotation = { axis = [0, 0, 1], angel = \"30 deg\" }", "");
    EXPECT_NE(error_of(typo).find("did you mean \"angle\"?"), std::string::npos);

    const std::string elements = scene_2d("", "discretisation = \"elements\"\nrotation = { angle = \"10 deg\" }", "");
    EXPECT_EQ(error_of(elements), where(elements, "rotation =", body) +
                                      "applies to particle bodies only: an element body's mesh follows the scene's axes");
}

// What the engine cannot turn (rotated_scene) is reported at the top-level rotation's line.
TEST(SceneFileOrientation, TheTopLevelRotationsEngineErrorsNameTheFileAndLine) {
    const std::string region = scene_2d("rotation = { angle = \"10 deg\" }", "", R"toml(
[[prescribed_velocity]]
body = "block"
region = { above = { z = "13 mm" } }
velocity = { z = "1 m/s" }
)toml");
    const std::string message = error_of(region);
    EXPECT_EQ(message.rfind(where(region, "rotation =", "rotation"), 0), 0u) << message;
    EXPECT_EQ(message.find("rotation: rotation:"), std::string::npos) << message << " (the key named once)";
}

}  // namespace orientation_files
}  // namespace
}  // namespace gpa::io
