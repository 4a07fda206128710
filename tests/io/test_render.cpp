// Snapshots read back and drawn (snapshot_reader.hpp, render.hpp): what the writer writes comes
// back bit for bit; the other encodings VTK allows decode to the same values; bad folders and
// files fail naming the file and what is wrong; a picture puts a node's colour at its pixel and
// the background elsewhere, mirrors axisymmetric runs, projects 3D runs in painter's order; the
// PNG decodes (libpng) to the picture drawn.

#include <array>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <png.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/node_store.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/render.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/snapshot_reader.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::io {
namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("gpa_render_" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string read_text(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

void write_text(const fs::path& file, const std::string& text) {
    std::ofstream out(file, std::ios::binary);
    out << text;
}

std::uint64_t bits(double v) {
    std::uint64_t b;
    std::memcpy(&b, &v, 8);
    return b;
}

// The message of the SnapshotError (or other InputError) that `f` throws.
template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no error";
    return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Nodes with distinct values in every field we look at: positions with all 52 bits of mantissa
// in use, pressures of both signs, a tiny and a huge value.
NodeStore sample_nodes(GeometryKind geometry, std::size_t n) {
    NodeStore nodes(geometry, n);
    const int dim = nodes.dim();
    for (std::size_t i = 0; i < n; ++i) {
        for (int c = 0; c < dim; ++c) {
            nodes.position[c][i] = (0.1 + 0.37 * i + 0.011 * c) * 1e-3 / 3.0;
            nodes.velocity[c][i] = std::sin(1.0 + i + 7.0 * c) * 100.0;
        }
        nodes.pressure[i] = (i % 2 ? -1.0 : 1.0) * std::exp(0.3 * i) * 1e8 / 7.0;
        nodes.diameter[i] = 0.25e-3 * (1.0 + 1e-3 * i);
        nodes.plastic_strain[i] = i == 1 ? 1e-300 : i == 2 ? 1.7e300 : 0.1 * i / 3.0;
    }
    return nodes;
}

// --- Reading back --------------------------------------------------------------------------

TEST(SnapshotReader, PositionsAndFieldsOfParticlesComeBackBitForBit) {
    for (GeometryKind g : {GeometryKind::Axisymmetric, GeometryKind::ThreeD}) {
        const fs::path dir = fresh_dir(std::string("roundtrip_") + (g == GeometryKind::ThreeD ? "3d" : "2d"));
        NodeStore nodes = sample_nodes(g, 7);
        for (std::size_t i = 0; i < 7; ++i) {
            nodes.damage[i] = 0.3 * static_cast<double>(i);  // past 1 from the fourth node on
            nodes.failed[i] = nodes.damage[i] >= 1.0 ? 1 : 0;
        }
        SnapshotSeries series(dir);
        series.write(nodes, nodes.size(), 0.0);
        series.write(nodes, 5, 1.234567891234e-5);  // the first 5 nodes only

        const SnapshotIndex index = read_pvd(find_pvd(dir));
        EXPECT_EQ(index.pvd, dir / "particles.pvd");
        ASSERT_EQ(index.snapshots.size(), 2u);
        EXPECT_EQ(index.snapshots[0].time, 0.0);
        // The .pvd writes times with 9 significant digits: that is its round-off.
        EXPECT_NEAR(index.snapshots[1].time, 1.234567891234e-5, 1e-9 * 1.234567891234e-5);
        ASSERT_EQ(index.snapshots[1].files.size(), 1u);
        EXPECT_EQ(index.snapshots[1].files[0], dir / "particles_00001.vtp");

        const VtkFile file(index.snapshots[0].files[0]);
        EXPECT_EQ(file.type(), "PolyData");
        ASSERT_EQ(file.point_count(), 7u);
        const auto points = file.points();
        const auto pressure = file.values("pressure", DataLocation::Point);
        const auto velocity = file.values("velocity", DataLocation::Point);
        const auto strain = file.values("plastic_strain", DataLocation::Point);
        ASSERT_EQ(points.size(), 21u);
        ASSERT_EQ(velocity.size(), 21u);
        const int dim = nodes.dim();
        for (std::size_t i = 0; i < 7; ++i) {
            for (int c = 0; c < 3; ++c) {
                const double position = c < dim ? nodes.position[c][i] : 0.0;  // 2D: (x, z, 0)
                const double v = c < dim ? nodes.velocity[c][i] : 0.0;
                EXPECT_EQ(bits(points[3 * i + c]), bits(position)) << "node " << i << " component " << c;
                EXPECT_EQ(bits(velocity[3 * i + c]), bits(v));
            }
            EXPECT_EQ(bits(pressure[i]), bits(nodes.pressure[i]));
            EXPECT_EQ(bits(strain[i]), bits(nodes.plastic_strain[i]));
            // Damage written in [0, 1]; failure as its own integer array.
            EXPECT_EQ(file.values("damage", DataLocation::Point)[i], std::min(0.3 * static_cast<double>(i), 1.0));
            EXPECT_EQ(file.values("failed", DataLocation::Point)[i], i >= 4 ? 1.0 : 0.0);
        }
        ASSERT_NE(file.find("failed", DataLocation::Point), nullptr);
        EXPECT_EQ(VtkFile(index.snapshots[1].files[0]).point_count(), 5u);
        const auto* info = file.find("velocity", DataLocation::Point);
        ASSERT_NE(info, nullptr);
        EXPECT_EQ(info->components, 3);
        EXPECT_EQ(file.find("velocity", DataLocation::Cell), nullptr);
    }
}

// A two-body element scene: meshed, its cells given distinct values, written as a snapshot.
ElementMesh sample_mesh() {
    const Scene scene = parse_scene(R"toml(
name = "elements"
geometry = "axisymmetric"
[[material]]
name = "rubber"
density = 1000
shear_modulus = "1 MPa"
eos = { model = "linear", bulk_modulus = "10 MPa" }
strength = "elastic"
[[body]]
shape = "cylinder"
material = "rubber"
radius = "2 mm"
length = "3 mm"
spacing = "1 mm"
discretisation = "elements"
[stop]
end_time = "1 us"
)toml",
                                    "elements.toml");
    ElementMesh mesh = mesh_element_bodies(scene);
    initialise_element_state(mesh, scene);
    for (std::size_t t = 0; t < mesh.points.size(); ++t) mesh.points.plastic_strain[t] = 0.01 * t + 1.0 / 3.0;
    return mesh;
}

TEST(SnapshotReader, ElementCellsAndTheirFieldsComeBack) {
    const fs::path dir = fresh_dir("elements");
    Snapshot snapshot;
    snapshot.elements = sample_mesh();
    const ElementMesh& mesh = *snapshot.elements;
    SnapshotSeries(dir).write(snapshot);
    const SnapshotIndex index = read_pvd(dir / "particles.pvd");
    ASSERT_EQ(index.snapshots.size(), 1u);
    ASSERT_EQ(index.snapshots[0].files.size(), 1u);
    const VtkFile file(index.snapshots[0].files[0]);
    EXPECT_EQ(file.type(), "UnstructuredGrid");
    ASSERT_EQ(file.cell_count(), mesh.triangles());
    ASSERT_EQ(file.point_count(), mesh.nodes.size());
    const VtkCells cells = file.cells();
    ASSERT_EQ(cells.types.size(), mesh.triangles());
    for (std::size_t t = 0; t < mesh.triangles(); ++t) {
        EXPECT_EQ(cells.types[t], 5);  // VTK_TRIANGLE
        EXPECT_EQ(cells.offsets[t], static_cast<std::int64_t>(3 * (t + 1)));
        EXPECT_EQ(cells.connectivity[3 * t], static_cast<std::int64_t>(mesh.quads.nodes[t / 4][4]));  // the centre node
    }
    const auto strain = file.values("plastic_strain", DataLocation::Cell);
    ASSERT_EQ(strain.size(), mesh.triangles());
    for (std::size_t t = 0; t < strain.size(); ++t) EXPECT_EQ(bits(strain[t]), bits(mesh.points.plastic_strain[t]));
    const auto points = file.points();
    for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
        EXPECT_EQ(bits(points[3 * i]), bits(mesh.nodes.position[0][i]));
        EXPECT_EQ(bits(points[3 * i + 1]), bits(mesh.nodes.position[1][i]));
    }
}

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const unsigned a = bytes[i], b = i + 1 < bytes.size() ? bytes[i + 1] : 0, c = i + 2 < bytes.size() ? bytes[i + 2] : 0;
        const unsigned v = (a << 16) | (b << 8) | c;
        out += digits[(v >> 18) & 63];
        out += digits[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? digits[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? digits[v & 63] : '=';
    }
    return out;
}

template <class T>
std::vector<unsigned char> raw_bytes(const std::vector<T>& values) {
    std::vector<unsigned char> out(values.size() * sizeof(T));
    std::memcpy(out.data(), values.data(), out.size());
    return out;
}

// A UInt32 length header, then the bytes, each encoded on its own (as VTK writes it) or together.
std::string base64_block(const std::vector<unsigned char>& data, bool together) {
    const auto n = static_cast<std::uint32_t>(data.size());
    std::vector<unsigned char> header(4);
    std::memcpy(header.data(), &n, 4);
    if (!together) return base64(header) + base64(data);
    std::vector<unsigned char> all = header;
    all.insert(all.end(), data.begin(), data.end());
    return base64(all);
}

TEST(SnapshotReader, ReadsBase64AsciiFloat32AndUInt32HeadersAsParaViewWritesThem) {
    const fs::path dir = fresh_dir("encodings");
    const std::vector<double> points{1e-3, 2e-3, 0, 3e-3, 4e-3, 0, 5e-3, 6e-3, 0};
    const std::vector<float> temperature{300.5f, 301.25f, 302.0f};
    const std::vector<std::int32_t> body{0, 1, 1};
    const std::string inline_points = base64_block(raw_bytes(points), false);
    const std::string appended_temperature = base64_block(raw_bytes(temperature), false);
    const std::string appended_body = base64_block(raw_bytes(body), true);
    const std::string text =
        "<?xml version=\"1.0\"?>\n<!-- written by hand -->\n"
        "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt32\">\n"
        "<PolyData>\n<FieldData><DataArray type=\"String\" Name=\"note\" NumberOfTuples=\"1\" format=\"ascii\">104 105 0"
        "</DataArray></FieldData>\n"  // ParaView's field data: not read
        "<Piece NumberOfPoints=\"3\" NumberOfVerts=\"0\">\n<PointData>\n"
        "<DataArray type=\"Float32\" Name=\"temperature\" format=\"appended\" offset=\"0\"/>\n"
        "<DataArray type=\"Int32\" Name=\"body\" format=\"appended\" offset=\"" +
        std::to_string(appended_temperature.size()) +
        "\"/>\n"
        "<DataArray type=\"Float64\" Name=\"pressure\" format=\"ascii\">1.5e9 -2 0.25\n</DataArray>\n"
        "</PointData>\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"binary\">\n" +
        inline_points +
        "\n</DataArray></Points>\n</Piece></PolyData>\n<AppendedData encoding=\"base64\">\n _" + appended_temperature +
        appended_body + "\n</AppendedData>\n</VTKFile>\n";
    write_text(dir / "hand.vtp", text);
    const VtkFile file(dir / "hand.vtp");
    EXPECT_EQ(file.points(), points);
    EXPECT_EQ(file.values("temperature", DataLocation::Point), (std::vector<double>{300.5, 301.25, 302.0}));
    EXPECT_EQ(file.values("body", DataLocation::Point), (std::vector<double>{0, 1, 1}));
    EXPECT_EQ(file.values("pressure", DataLocation::Point), (std::vector<double>{1.5e9, -2, 0.25}));
}

// --- Bad folders and files -----------------------------------------------------------------

TEST(SnapshotReader, BadFoldersAndFilesFailNamingTheFileAndTheFault) {
    const fs::path dir = fresh_dir("bad");
    // A folder that is not there, and one whose run is still going (DIR.partial).
    EXPECT_TRUE(contains(error_of([&] { find_pvd(dir / "nothing"); }), "nothing: no such folder"));
    fs::create_directories(dir / "running.partial");
    EXPECT_TRUE(contains(error_of([&] { find_pvd(dir / "running"); }), "running.partial is there"));
    fs::create_directories(dir / "empty");
    EXPECT_TRUE(contains(error_of([&] { find_pvd(dir / "empty"); }), "no particles.pvd"));

    // A good run folder to break in turn.
    const NodeStore nodes = sample_nodes(GeometryKind::Axisymmetric, 4);
    const fs::path run = dir / "run";
    fs::create_directories(run);
    SnapshotSeries(run).write(nodes, nodes.size(), 0.0);
    const std::string pvd = read_text(run / "particles.pvd");
    const std::string vtp = read_text(run / "particles_00000.vtp");

    write_text(run / "particles.pvd", "this is not XML");
    std::string e = error_of([&] { read_pvd(run / "particles.pvd"); });
    EXPECT_TRUE(contains(e, "particles.pvd") && contains(e, "not a VTK time-series collection")) << e;
    write_text(run / "particles.pvd", pvd.substr(0, pvd.find("<DataSet")));
    e = error_of([&] { read_pvd(run / "particles.pvd"); });
    EXPECT_TRUE(contains(e, "lists no snapshots")) << e;
    std::string bad_time = pvd;
    bad_time.replace(bad_time.find("timestep=\"0\""), 12, "timestep=\"soon\"");
    write_text(run / "particles.pvd", bad_time);
    e = error_of([&] { read_pvd(run / "particles.pvd"); });
    EXPECT_TRUE(contains(e, "timestep 'soon' is not a number") && contains(e, "particles_00000.vtp")) << e;
    write_text(run / "particles.pvd", pvd);

    // The .pvd lists a file that is gone.
    fs::rename(run / "particles_00000.vtp", run / "moved.vtp");
    e = error_of([&] { load_snapshot(read_pvd(run / "particles.pvd"), 0); });
    EXPECT_TRUE(contains(e, "particles_00000.vtp: no such file") && contains(e, "listed in")) << e;
    fs::rename(run / "moved.vtp", run / "particles_00000.vtp");

    // Cut short, in the XML and in the appended data.
    const fs::path file = run / "particles_00000.vtp";
    write_text(file, vtp.substr(0, vtp.find("<Points>") + 20));
    e = error_of([&] { const VtkFile opened(file); });
    EXPECT_TRUE(contains(e, "particles_00000.vtp") && contains(e, "cut short")) << e;
    write_text(file, vtp.substr(0, vtp.size() - 200));
    e = error_of([&] { const VtkFile opened(file); });
    EXPECT_TRUE(contains(e, "particles_00000.vtp") && contains(e, "past the end")) << e;
    // A length header that does not match the array.
    std::string wrong = vtp;
    const std::size_t data = wrong.find('_', wrong.find("<AppendedData")) + 1;
    wrong[data] = static_cast<char>(wrong[data] + 8);
    write_text(file, wrong);
    e = error_of([&] { const VtkFile opened(file); });
    EXPECT_TRUE(contains(e, "holds") && contains(e, "expected")) << e;
    // Compressed, and not VTK at all.
    std::string compressed = vtp;
    compressed.replace(compressed.find("header_type"), 0, "compressor=\"vtkZLibDataCompressor\" ");
    write_text(file, compressed);
    EXPECT_TRUE(contains(error_of([&] { const VtkFile opened(file); }), "compressed data (vtkZLibDataCompressor) is not supported"));
    write_text(file, "<html><body>hello</body></html>");
    EXPECT_TRUE(contains(error_of([&] { const VtkFile opened(file); }), "not a VTK XML file"));
}

TEST(SnapshotReader, AFileCutAnywhereOrWithAByteChangedReadsOrFailsCleanly) {
    const fs::path dir = fresh_dir("cuts");
    const NodeStore nodes = sample_nodes(GeometryKind::Axisymmetric, 3);
    SnapshotSeries(dir).write(nodes, nodes.size(), 0.0);
    const std::string vtp = read_text(dir / "particles_00000.vtp");
    // Reading every array of the file: it either works or throws SnapshotError, nothing else.
    const auto read_all = [&](const std::string& bytes, const std::string& what) {
        try {
            const VtkFile f("damaged.vtp", bytes);
            f.points();
            for (const auto& a : f.arrays()) f.values(a.name, a.location);
            return true;
        } catch (const SnapshotError&) {
        } catch (const std::exception& e) {
            ADD_FAILURE() << what << ": " << e.what();
        }
        return false;
    };
    // The points are the last array read (the vertices after them are not): a cut before the
    // end of their values loses some value that is read.
    const std::size_t data = vtp.find('_', vtp.find("<AppendedData")) + 1;
    const std::size_t points_tag = vtp.find("offset=\"", vtp.find("<Points>")) + 8;
    const std::size_t points_end = data + std::stoul(vtp.substr(points_tag)) + 8 + 3 * 3 * 8;
    ASSERT_LT(points_end, vtp.size());
    for (std::size_t length = 0; length < vtp.size(); length += 3) {
        const bool read = read_all(vtp.substr(0, length), "cut at " + std::to_string(length));
        if (length < points_end) {
            EXPECT_FALSE(read) << "a file cut at byte " << length << " of " << vtp.size() << " was read";
        }
    }
    for (std::size_t at = 0; at < vtp.size(); ++at) {
        std::string changed = vtp;
        changed[at] = static_cast<char>(changed[at] ^ 0x5a);
        read_all(changed, "byte " + std::to_string(at) + " changed");
    }
}

// --- Pictures ------------------------------------------------------------------------------

// A folder with one snapshot of `nodes` and, if given, the scene.toml line naming its geometry.
LoadedSnapshot snapshot_of(const std::string& name, const NodeStore& nodes, double time = 0.0) {
    const fs::path dir = fresh_dir(name);
    SnapshotSeries(dir).write(nodes, nodes.size(), time);
    return load_snapshot(read_pvd(dir / "particles.pvd"), 0);
}

// The pixel of the image at a point of the picture plane.
Rgb pixel_at(const Picture& p, double u, double v) {
    const auto [x, y] = p.frame.pixel(u, v);
    return p.image.at(static_cast<int>(std::floor(x)), static_cast<int>(std::floor(y)));
}

// Three plane-strain nodes 1 mm apart in x (A, B) and one above (C), 0.5 mm across: pressure 0,
// 10 and 5 Pa.
NodeStore three_nodes() {
    NodeStore n(GeometryKind::PlaneStrain, 3);
    const std::array<std::array<double, 2>, 3> at{{{1e-3, 1e-3}, {3e-3, 1e-3}, {2e-3, 3e-3}}};
    const std::array<double, 3> pressure{0.0, 10.0, 5.0};
    for (std::size_t i = 0; i < 3; ++i) {
        n.position[0][i] = at[i][0];
        n.position[1][i] = at[i][1];
        n.diameter[i] = 0.5e-3;
        n.pressure[i] = pressure[i];
        n.mass[i] = 1.0;
    }
    return n;
}

Image decode_png(const std::string& bytes) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    EXPECT_TRUE(png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) << png.message;
    png.format = PNG_FORMAT_RGB;
    Image out(static_cast<int>(png.width), static_cast<int>(png.height), Rgb{});
    EXPECT_TRUE(png_image_finish_read(&png, nullptr, out.rgb.data(), 0, nullptr)) << png.message;
    return out;
}

TEST(Render, ANodeIsDrawnInItsFieldColourAtItsPixelAndTheBackgroundBetween) {
    const LoadedSnapshot s = snapshot_of("three", three_nodes());
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_FALSE(p.mirrored);
    EXPECT_EQ(p.range_min, 0.0);
    EXPECT_EQ(p.range_max, 10.0);
    EXPECT_EQ(p.unit, "Pa");
    EXPECT_EQ(p.discs, 3u);
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(p, 3e-3, 1e-3), colour_map(1.0));
    EXPECT_EQ(pixel_at(p, 2e-3, 3e-3), colour_map(0.5));
    // Off the discs' edges by 0.1 mm or more: background (a disc's radius is 0.25 mm).
    EXPECT_EQ(pixel_at(p, 2e-3, 1e-3), background_colour);
    EXPECT_EQ(pixel_at(p, 1e-3 + 0.35e-3, 1e-3), background_colour);
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3 + 0.35e-3), background_colour);
    EXPECT_EQ(pixel_at(p, 1e-3 + 0.2e-3, 1e-3), colour_map(0.0));
    // The PNG holds exactly this picture.
    const Image back = decode_png(encode_png(p.image));
    EXPECT_EQ(back.width, p.image.width);
    EXPECT_EQ(back.height, p.image.height);
    EXPECT_EQ(back.rgb, p.image.rgb);

    // A range given: values beyond it take its end colours, and are counted.
    o.range_min = 4.0;
    o.range_max = 6.0;
    const Picture q = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(pixel_at(q, 1e-3, 1e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(q, 3e-3, 1e-3), colour_map(1.0));
    EXPECT_EQ(q.below_range, 1u);
    EXPECT_EQ(q.above_range, 1u);
    // One end given: the other is the field's own.
    o.range_min.reset();
    const Picture r = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(r.range_min, 0.0);
    EXPECT_EQ(r.range_max, 6.0);
}

TEST(Render, FailedNodesCarryABlackDotUnlessAskedNot) {
    NodeStore n = three_nodes();
    n.failed[1] = 1;
    const LoadedSnapshot s = snapshot_of("failed_marks", n);
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.failed, 1u);
    EXPECT_EQ(pixel_at(p, 3e-3, 1e-3), text_colour);                   // the dot at the failed node's centre
    EXPECT_EQ(pixel_at(p, 3e-3 + 0.18e-3, 1e-3), colour_map(1.0));     // its field colour beyond the dot (r/3)
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), colour_map(0.0));               // an intact node: no dot
    o.mark_failed = false;
    const Picture plain = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(plain.failed, 0u);
    EXPECT_EQ(pixel_at(plain, 3e-3, 1e-3), colour_map(1.0));
    // Coloured by `failed` itself: no dots, the field says it.
    o.mark_failed = true;
    o.field = "failed";
    const Picture by_field = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(by_field.failed, 0u);
    EXPECT_EQ(pixel_at(by_field, 3e-3, 1e-3), colour_map(1.0));
}

TEST(Render, AFailedNodeBehindAnotherIsCoveredAndMirrorImagesAreNotCounted) {
    // 3D, seen along +y: the failed node at y = 0 lies behind the intact one at y = -1 mm (nearer
    // the viewer) at the same x and z, so the nearer disc hides it and its dot.
    NodeStore solid(GeometryKind::ThreeD, 3);
    solid.position[0] = {1e-3, 1e-3, 3e-3};
    solid.position[1] = {0.0, -1e-3, 0.0};
    solid.position[2] = {1e-3, 1e-3, 1e-3};
    solid.diameter = {0.5e-3, 0.5e-3, 0.5e-3};
    solid.pressure = {1.0, 2.0, 3.0};
    solid.failed = {1, 0, 0};
    const LoadedSnapshot s3 = snapshot_of("failed_behind", solid);
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s3, GeometryKind::ThreeD, o);
    EXPECT_EQ(p.failed, 1u);
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), colour_map(0.5));  // the nearer node's colour, no dot
    // A mirrored 2D run: counts take each node once, with or without a region (which draws the
    // mirror images in it too).
    NodeStore n = three_nodes();
    n.failed[1] = 1;
    const LoadedSnapshot s2 = snapshot_of("failed_mirrored", n);
    RenderOptions m;
    m.field = "pressure";
    const Picture whole = render_snapshot(s2, GeometryKind::Axisymmetric, m);
    EXPECT_EQ(whole.discs, 3u);
    EXPECT_EQ(whole.failed, 1u);
    m.region = std::array<double, 4>{-4e-3, 4e-3, 0.0, 4e-3};
    const Picture framed = render_snapshot(s2, GeometryKind::Axisymmetric, m);
    EXPECT_EQ(framed.discs, 3u);
    EXPECT_EQ(framed.failed, 1u);
    // Only the mirror images in the window: each node is still counted once.
    m.region = std::array<double, 4>{-4e-3, -0.5e-3, 0.0, 4e-3};
    const Picture images = render_snapshot(s2, GeometryKind::Axisymmetric, m);
    EXPECT_EQ(images.discs, 3u);
    EXPECT_EQ(images.failed, 1u);
}

TEST(Render, AWindowOfNanometresFarFromTheOriginDrawsAndEnds) {
    // The doubles' spacing at 1 m is 2.2e-16 m: a window of a few of them once stalled the tick
    // loop and put the nodes at pixel coordinates beyond an int.
    NodeStore n(GeometryKind::PlaneStrain, 1);
    n.position[0] = {1.0};
    n.position[1] = {1.0};
    n.diameter = {1e-3};
    n.pressure = {1.0};
    const LoadedSnapshot s = snapshot_of("tiny_window", n);
    RenderOptions o;
    o.field = "pressure";
    o.region = std::array<double, 4>{1.0, std::nextafter(std::nextafter(1.0, 2.0), 2.0), 1.0, std::nextafter(std::nextafter(1.0, 2.0), 2.0)};
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.discs, 1u);
    EXPECT_EQ(p.image.at(p.image.width / 3, p.image.height / 2), colour_map(0.5));  // inside the one disc
}

TEST(Render, BodiesAndMaterialsAreCategoriesNamedByTheScene) {
    NodeStore n = three_nodes();
    n.body = {0, 2, 1};
    const LoadedSnapshot s = snapshot_of("categories", n);
    Scene scene;
    scene.bodies.resize(3);
    scene.bodies[0].name = "plate";
    scene.bodies[1].name = "sphere";
    scene.bodies[2].name = "backing";
    RenderOptions o;
    o.field = "body";
    o.scene = &scene;
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_TRUE(p.categorical);
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), category_colour(0));
    EXPECT_EQ(pixel_at(p, 3e-3, 1e-3), category_colour(2));
    EXPECT_EQ(pixel_at(p, 2e-3, 3e-3), category_colour(1));
    // Seven colours a colour-blind reader tells apart, none of them the text's or the background's.
    for (int k = 0; k < 7; ++k) {
        for (int j = 0; j < k; ++j) EXPECT_NE(category_colour(k), category_colour(j));
        EXPECT_NE(category_colour(k), text_colour);
        EXPECT_NE(category_colour(k), background_colour);
    }
    EXPECT_EQ(category_colour(7), category_colour(0));
    // A colour range asked for: the indices as numbers on the colour map.
    o.range_min = 0.0;
    o.range_max = 2.0;
    const Picture q = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_FALSE(q.categorical);
    EXPECT_EQ(pixel_at(q, 3e-3, 1e-3), colour_map(1.0));
}

TEST(Render, TheScenesPlanesAreLinesWhereSeenEdgeOn) {
    NodeStore n = three_nodes();
    const LoadedSnapshot s = snapshot_of("planes", n);
    Scene scene;
    PlaneSpec anvil;
    anvil.name = "anvil";
    anvil.axis = 1;  // z in 2D
    anvil.position = 0.5e-3;
    scene.planes.push_back(anvil);
    PlaneSpec symmetry;
    symmetry.name = "mid";
    symmetry.kind = PlaneKind::Symmetry;
    symmetry.axis = 0;
    symmetry.position = 2e-3;
    scene.planes.push_back(symmetry);
    RenderOptions o;
    o.field = "pressure";
    o.scene = &scene;
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.planes_drawn, 2u);
    // The anvil's line at z = 0.5 mm, across the drawing between the nodes.
    EXPECT_EQ(pixel_at(p, 2e-3 - 0.6e-3, 0.5e-3), text_colour);
    // The drawing reaches to a plane away from the bodies; outside a region asked for, a plane is
    // not drawn; in 3D, one facing the viewer neither.
    scene.planes[0].position = -2e-3;
    const Picture reaching = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(reaching.planes_drawn, 2u);
    EXPECT_EQ(pixel_at(reaching, 2e-3 - 0.6e-3, -2e-3), text_colour);
    o.region = std::array<double, 4>{0.0, 4e-3, 0.0, 4e-3};
    EXPECT_EQ(render_snapshot(s, GeometryKind::PlaneStrain, o).planes_drawn, 1u);
    o.region.reset();
    NodeStore solid(GeometryKind::ThreeD, 2);
    solid.position[0] = {0.0, 1e-3};
    solid.position[1] = {0.0, 1e-3};
    solid.position[2] = {1e-3, 2e-3};
    solid.diameter = {0.5e-3, 0.5e-3};
    const LoadedSnapshot s3 = snapshot_of("planes_3d", solid);
    Scene scene_3d;
    PlaneSpec floor;
    floor.name = "floor";
    floor.axis = 2;
    floor.position = 1.2e-3;
    scene_3d.planes.push_back(floor);
    o.scene = &scene_3d;
    EXPECT_EQ(render_snapshot(s3, GeometryKind::ThreeD, o).planes_drawn, 1u);  // +y: z is up
    o.view = ViewDirection::MinusZ;
    EXPECT_EQ(render_snapshot(s3, GeometryKind::ThreeD, o).planes_drawn, 0u);  // seen from above: faces the viewer
}

// An oblique plane (axis = -1, a unit normal) is drawn as a slanted line where the view sees it
// edge-on, and left out where it is seen at a slant.
TEST(Render, ObliquePlanesAreSlantedLinesWhereSeenEdgeOn) {
    NodeStore n = three_nodes();
    const LoadedSnapshot s = snapshot_of("oblique_planes", n);
    Scene scene;
    PlaneSpec ramp;
    ramp.name = "ramp";
    ramp.axis = -1;
    ramp.normal = {-std::sqrt(0.5), std::sqrt(0.5), 0.0};  // the line z = x - 1 mm
    ramp.position = -std::sqrt(0.5) * 1e-3;
    scene.planes.push_back(ramp);
    RenderOptions o;
    o.field = "pressure";
    o.scene = &scene;
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.planes_drawn, 1u);
    // The line through (2, 1) mm and (2.5, 1.5) mm: a pixel of it within one of each such point.
    const auto near_line = [&](double u, double v) {
        const auto [x, y] = p.frame.pixel(u, v);
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                if (p.image.at(static_cast<int>(std::floor(x)) + dx, static_cast<int>(std::floor(y)) + dy) == text_colour) return true;
            }
        }
        return false;
    };
    EXPECT_TRUE(near_line(2e-3, 1e-3));
    EXPECT_TRUE(near_line(2.5e-3, 1.5e-3));
    EXPECT_FALSE(near_line(2e-3, 2e-3));  // away from it, between the nodes

    // A line outside the drawing is not drawn (nor counted).
    scene.planes[0].position = -std::sqrt(0.5) * 50e-3;
    EXPECT_EQ(render_snapshot(s, GeometryKind::PlaneStrain, o).planes_drawn, 0u);

    NodeStore solid(GeometryKind::ThreeD, 2);
    solid.position[0] = {0.0, 1e-3};
    solid.position[1] = {0.0, 1e-3};
    solid.position[2] = {1e-3, 2e-3};
    solid.diameter = {0.5e-3, 0.5e-3};
    const LoadedSnapshot s3 = snapshot_of("oblique_planes_3d", solid);
    Scene scene_3d;
    PlaneSpec floor;
    floor.name = "floor";
    floor.axis = -1;
    floor.normal = {std::sqrt(0.5), 0.0, std::sqrt(0.5)};
    floor.position = std::sqrt(0.5) * 2e-3;  // x + z = 2 mm: between the two nodes
    scene_3d.planes.push_back(floor);
    o.scene = &scene_3d;
    EXPECT_EQ(render_snapshot(s3, GeometryKind::ThreeD, o).planes_drawn, 1u);  // +y: edge-on
    o.view = ViewDirection::MinusZ;
    EXPECT_EQ(render_snapshot(s3, GeometryKind::ThreeD, o).planes_drawn, 0u);  // from above: at a slant
}

TEST(Render, PrescribedVelocityRegionsAreOutlinedAroundTheirNodes) {
    NodeStore n = three_nodes();
    n.velocity_region = {1, 1, 0};  // the two lower nodes held by region 0
    const LoadedSnapshot s = snapshot_of("regions", n);
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.regions_drawn, 1u);
    // The box's lower edge runs two font pixels (up to 8 picture pixels) below the held discs
    // (z = 1 mm less 0.25 mm), dashed: a row there between the nodes is partly dark.
    const auto [x0, y] = p.frame.pixel(1e-3, 0.75e-3);
    const auto [x1, unused] = p.frame.pixel(3e-3, 0.75e-3);
    int darkest_row = 0;
    for (int row = static_cast<int>(y); row <= static_cast<int>(y) + 8; ++row) {
        int dark = 0;
        for (int x = static_cast<int>(x0); x < static_cast<int>(x1); ++x) dark += p.image.at(x, row) == text_colour;
        darkest_row = std::max(darkest_row, dark);
    }
    // Half of a dashed edge is drawn (dashes as long as the gaps).
    EXPECT_GT(darkest_row, static_cast<int>(0.3 * (x1 - x0)));
    EXPECT_EQ(pixel_at(p, 2e-3, 3e-3), colour_map(0.5));
    // Mirrored (axisymmetric): the image has its own box.
    EXPECT_EQ(render_snapshot(s, GeometryKind::Axisymmetric, o).regions_drawn, 2u);
}

TEST(Render, OneFrameHoldsEverySnapshotOfARun) {
    const fs::path dir = fresh_dir("series_extent");
    SnapshotSeries series(dir);
    NodeStore n(GeometryKind::Axisymmetric, 1);
    n.diameter = {0.2e-3};
    n.position[0] = {1e-3};
    n.position[1] = {1e-3};
    series.write(n, 1, 0.0);
    n.position[0] = {2e-3};
    n.position[1] = {5e-3};
    series.write(n, 1, 1e-6);
    const SnapshotIndex index = read_pvd(dir / "particles.pvd");
    RenderOptions o;
    // Mirrored about the axis (axisymmetric): -2.1 to 2.1 mm across, 0.9 to 5.1 mm up.
    const auto e = series_extent(index, GeometryKind::Axisymmetric, o);
    EXPECT_NEAR(e[0], -2.1e-3, 1e-15);
    EXPECT_NEAR(e[1], 2.1e-3, 1e-15);
    EXPECT_NEAR(e[2], 0.9e-3, 1e-15);
    EXPECT_NEAR(e[3], 5.1e-3, 1e-15);
    o.mirror = false;
    EXPECT_NEAR(series_extent(index, GeometryKind::Axisymmetric, o)[0], 0.9e-3, 1e-15);
    // The frame reaches to the scene's planes, as a picture does: an anvil 1 mm below the axis' origin.
    Scene scene;
    PlaneSpec anvil;
    anvil.name = "anvil";
    anvil.axis = 1;
    anvil.position = -1e-3;
    scene.planes.push_back(anvil);
    o.scene = &scene;
    EXPECT_EQ(series_extent(index, GeometryKind::Axisymmetric, o)[2], -1e-3);
    o.scene = nullptr;
    // Passed as the region, the first snapshot is drawn in the frame of the whole run: its
    // node sits in the lower left of a picture as tall as the run's path.
    o.region = e;
    o.mirror.reset();
    const Picture first = render_snapshot(load_snapshot(index, 0), GeometryKind::Axisymmetric, o);
    const Picture last = render_snapshot(load_snapshot(index, 1), GeometryKind::Axisymmetric, o);
    EXPECT_EQ(first.image.height, last.image.height);
    EXPECT_EQ(first.frame.scale, last.frame.scale);
    EXPECT_EQ(first.frame.u_left, last.frame.u_left);
}

TEST(Render, PicturesTakeTheSizeAskedForOrTheScenesProportions) {
    RenderOptions o;
    o.field = "pressure";
    o.width = 640;
    o.height = 480;
    const Picture p = render_snapshot(snapshot_of("sizes", three_nodes()), GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.image.width, 640);
    EXPECT_EQ(p.image.height, 480);
    // With the height left free it follows the scene's proportions: scenes 2 mm wide and 1, 2
    // and 3 mm high (two nodes 0.2 mm across at opposite corners) give heights in equal steps
    // (the plot area's width times 0.5 mm / mm, to a pixel of rounding).
    o.height = 0;
    std::vector<int> heights;
    for (int k = 1; k <= 3; ++k) {
        NodeStore n(GeometryKind::PlaneStrain, 2);
        n.position[0] = {0.1e-3, 1.9e-3};
        n.position[1] = {0.1e-3, k * 1e-3 - 0.1e-3};
        n.diameter = {0.2e-3, 0.2e-3};
        heights.push_back(render_snapshot(snapshot_of("proportions", n), GeometryKind::PlaneStrain, o).image.height);
    }
    EXPECT_GT(heights[1] - heights[0], 100);
    EXPECT_NEAR(heights[2] - heights[1], heights[1] - heights[0], 1.0);
}

TEST(Render, AxisymmetricRunsAreMirroredAboutTheAxisUnlessAskedNotTo) {
    NodeStore n = three_nodes();
    const LoadedSnapshot s = snapshot_of("mirror", n);
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s, GeometryKind::Axisymmetric, o);
    EXPECT_TRUE(p.mirrored);
    EXPECT_EQ(p.discs, 3u);
    EXPECT_EQ(pixel_at(p, -3e-3, 1e-3), colour_map(1.0));  // B's image at x = -3 mm
    EXPECT_EQ(pixel_at(p, -1e-3, 1e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(p, 3e-3, 1e-3), colour_map(1.0));
    EXPECT_EQ(pixel_at(p, 0.0, 1e-3), background_colour);
    o.mirror = false;
    const Picture q = render_snapshot(s, GeometryKind::Axisymmetric, o);
    EXPECT_FALSE(q.mirrored);
    // Without the image, x = -1 mm is outside the drawing or in the background.
    const auto [x, y] = q.frame.pixel(-1e-3, 1e-3);
    if (x >= 0 && x < q.image.width) {
        EXPECT_EQ(q.image.at(static_cast<int>(x), static_cast<int>(y)), background_colour);
    }
    // Mirroring a plane-strain run is asked for.
    o.mirror = true;
    EXPECT_TRUE(render_snapshot(s, GeometryKind::PlaneStrain, o).mirrored);
}

TEST(Render, ViewsAreRightHandedAndPlusYShowsXRightAndZUp) {
    const std::array<std::array<double, 3>, 3> axes{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
    for (const char* name : {"+x", "-x", "+y", "-y", "+z", "-z"}) {
        const auto view = view_direction_named(name);
        ASSERT_TRUE(view) << name;
        EXPECT_EQ(name_of(*view), name);
        std::array<double, 3> right{}, up{}, away{};
        for (int c = 0; c < 3; ++c) {
            const ViewPoint p = project(axes[c], *view);
            right[c] = p.u;
            up[c] = p.v;
            away[c] = p.depth;
        }
        // right x up = towards the viewer = -away
        const std::array<double, 3> cross{right[1] * up[2] - right[2] * up[1], right[2] * up[0] - right[0] * up[2],
                                          right[0] * up[1] - right[1] * up[0]};
        for (int c = 0; c < 3; ++c) EXPECT_EQ(cross[c], -away[c]) << name;
        // The view direction named is the depth axis.
        const int axis = name[1] - 'x';
        EXPECT_EQ(away[axis], name[0] == '+' ? 1.0 : -1.0) << name;
    }
    const ViewPoint front = project({1.0, 2.0, 3.0}, ViewDirection::PlusY);
    EXPECT_EQ(front.u, 1.0);
    EXPECT_EQ(front.v, 3.0);
    EXPECT_EQ(front.depth, 2.0);
    const ViewPoint top = project({1.0, 2.0, 3.0}, ViewDirection::MinusZ);
    EXPECT_EQ(top.u, 1.0);
    EXPECT_EQ(top.v, 2.0);
    EXPECT_EQ(top.depth, -3.0);
    EXPECT_FALSE(view_direction_named("sideways"));
}

TEST(Render, ThreeDNodesAreProjectedAndTheNearestIsDrawnLast) {
    // Two nodes on one line of sight along y (the nearer first in the file) and one beside them.
    NodeStore n(GeometryKind::ThreeD, 3);
    const std::array<std::array<double, 3>, 3> at{{{1e-3, -1e-3, 2e-3}, {1e-3, 1e-3, 2e-3}, {3e-3, 0.0, 1e-3}}};
    const std::array<double, 3> temperature{300.0, 400.0, 350.0};
    for (std::size_t i = 0; i < 3; ++i) {
        for (int c = 0; c < 3; ++c) n.position[c][i] = at[i][c];
        n.diameter[i] = 0.6e-3;
        n.temperature[i] = temperature[i];
    }
    const LoadedSnapshot s = snapshot_of("three_d", n);
    RenderOptions o;
    o.field = "temperature";
    Picture p = render_snapshot(s, GeometryKind::ThreeD, o);  // +y: the node at y = -1 mm is nearer
    EXPECT_EQ(pixel_at(p, 1e-3, 2e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(p, 3e-3, 1e-3), colour_map(0.5));
    EXPECT_EQ(pixel_at(p, 2e-3, 1.5e-3), background_colour);
    o.view = ViewDirection::MinusY;  // from the other side: right is -x, the node at y = +1 mm in front
    p = render_snapshot(s, GeometryKind::ThreeD, o);
    EXPECT_EQ(pixel_at(p, -1e-3, 2e-3), colour_map(1.0));
    EXPECT_EQ(pixel_at(p, -3e-3, 1e-3), colour_map(0.5));
    o.view = ViewDirection::MinusZ;  // from above: x right, y up
    p = render_snapshot(s, GeometryKind::ThreeD, o);
    EXPECT_EQ(pixel_at(p, 1e-3, -1e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), colour_map(1.0));
    EXPECT_EQ(pixel_at(p, 3e-3, 0.0), colour_map(0.5));
}

TEST(Render, VectorFieldsByMagnitudeOrComponent) {
    NodeStore n = three_nodes();
    n.velocity[0] = {3.0, 0.0, 0.0};
    n.velocity[1] = {4.0, -2.0, 1.0};  // z; magnitudes 5, 2, 1
    const LoadedSnapshot s = snapshot_of("vectors", n);
    RenderOptions o;
    const Picture magnitude = render_snapshot(s, GeometryKind::PlaneStrain, o);  // the default field, velocity
    EXPECT_EQ(magnitude.range_min, 1.0);
    EXPECT_EQ(magnitude.range_max, 5.0);
    EXPECT_EQ(pixel_at(magnitude, 1e-3, 1e-3), colour_map(1.0));
    o.field = "velocity:z";
    const Picture z = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(z.range_min, -2.0);
    EXPECT_EQ(z.range_max, 4.0);
    EXPECT_EQ(pixel_at(z, 3e-3, 1e-3), colour_map(0.0));
    EXPECT_EQ(parse_field_choice("velocity:z", GeometryKind::Axisymmetric).component, 1);  // stored (x, z, 0)
    EXPECT_EQ(parse_field_choice("velocity:z", GeometryKind::ThreeD).component, 2);
    EXPECT_EQ(parse_field_choice("velocity:y", GeometryKind::ThreeD).component, 1);
    EXPECT_FALSE(parse_field_choice("velocity:magnitude", GeometryKind::ThreeD).component);
}

TEST(Render, TensorFieldsByComponentInTheStoredOrder) {
    // The snapshot's stress is XX, YY, ZZ, XY, YZ, XZ; 2D runs store (x, z, out of plane).
    NodeStore n = three_nodes();
    n.pressure = {0.0, 0.0, 0.0};
    n.deviatoric_stress[2] = {1.0, 2.0, 3.0};  // xz (2D order: xx, zz, xz, out of plane)
    n.deviatoric_stress[3] = {-5.0, 7.0, 6.0};  // out of plane
    const LoadedSnapshot s = snapshot_of("tensor", n);
    RenderOptions o;
    o.field = "stress:xz";
    const Picture xz = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(xz.range_min, 1.0);
    EXPECT_EQ(xz.range_max, 3.0);
    o.field = "stress:yy";  // plane strain: the out-of-plane stress
    const Picture yy = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(yy.range_min, -5.0);
    EXPECT_EQ(yy.range_max, 7.0);
    o.field = "stress:hoop";
    EXPECT_EQ(render_snapshot(s, GeometryKind::Axisymmetric, o).range_max, 7.0);
    const std::vector<std::pair<std::string, int>> three_d{{"xx", 0}, {"yy", 1}, {"zz", 2}, {"xy", 3}, {"yz", 4}, {"xz", 5}};
    for (const auto& [part, index] : three_d) {
        const FieldChoice c = parse_field_choice("stress:" + part, GeometryKind::ThreeD);
        EXPECT_EQ(c.component, index) << part;
        EXPECT_TRUE(c.tensor) << part;
    }
    EXPECT_EQ(parse_field_choice("stress:zz", GeometryKind::Axisymmetric).component, 1);
    EXPECT_EQ(parse_field_choice("stress:xz", GeometryKind::PlaneStrain).component, 3);
    // The whole tensor, a vector's component of it, a tensor's of a vector, and components of
    // another geometry are refused, naming what to write instead.
    o.field = "stress";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "von_mises_stress"));
    o.field = "stress:x";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "is a tensor"));
    o.field = "velocity:xx";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "is a vector"));
    o.field = "stress:hoop";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "xx, zz, yy, xz"));
    o.field = "stress:yz";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::Axisymmetric, o); }), "xx, zz, hoop, xz"));
}

TEST(Render, ElementCellsAreFilledWithTheirCellValues) {
    const fs::path dir = fresh_dir("element_picture");
    Snapshot snapshot;
    snapshot.elements = sample_mesh();
    const ElementMesh& mesh = *snapshot.elements;
    SnapshotSeries(dir).write(snapshot);
    const LoadedSnapshot s = load_snapshot(read_pvd(dir / "particles.pvd"), 0);
    RenderOptions o;
    o.field = "plastic_strain";
    const Picture p = render_snapshot(s, GeometryKind::Axisymmetric, o);
    EXPECT_EQ(p.triangles, mesh.triangles());
    const double lo = p.range_min, hi = p.range_max;
    EXPECT_EQ(lo, mesh.points.plastic_strain.front());
    EXPECT_EQ(hi, mesh.points.plastic_strain.back());
    for (std::size_t t = 0; t < mesh.triangles(); ++t) {
        const auto& q = mesh.quads.nodes[t / 4];
        const std::array<std::size_t, 3> corner{q[4], q[t % 4], q[(t % 4 + 1) % 4]};
        double u = 0, v = 0;
        for (std::size_t c : corner) {
            u += mesh.nodes.position[0][c] / 3.0;
            v += mesh.nodes.position[1][c] / 3.0;
        }
        const double value = mesh.points.plastic_strain[t];
        EXPECT_EQ(pixel_at(p, u, v), colour_map((value - lo) / (hi - lo))) << "triangle " << t;
        EXPECT_EQ(pixel_at(p, -u, v), colour_map((value - lo) / (hi - lo))) << "mirrored triangle " << t;
    }
    // A point field is interpolated across each triangle: a field linear in z comes out as that
    // line at every pixel's centre (to one colour level: the interpolation's round-off may cross
    // a level of the 8-bit map).
    Snapshot moving = snapshot;
    ElementNodes& nodes = moving.elements->nodes;
    const auto linear = [](double z) { return 2.0e3 * z - 1.0; };
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes.velocity[1][i] = linear(nodes.position[1][i]);
    const fs::path dir2 = fresh_dir("element_points");
    SnapshotSeries(dir2).write(moving);
    o.field = "velocity:z";
    const Picture lines = render_snapshot(load_snapshot(read_pvd(dir2 / "particles.pvd"), 0), GeometryKind::Axisymmetric, o);
    std::size_t checked = 0;
    for (double z = 0.1e-3; z < 2.95e-3; z += 0.37e-3) {
        for (double x : {-1.7e-3, -0.2e-3, 0.6e-3, 1.3e-3}) {
            const auto [px, py] = lines.frame.pixel(x, z);
            const int ix = static_cast<int>(std::floor(px)), iy = static_cast<int>(std::floor(py));
            // the z of this pixel's centre
            const double centre_z = lines.frame.v_top - (iy + 0.5 - lines.frame.top) / lines.frame.scale;
            const Rgb want = colour_map((linear(centre_z) - lines.range_min) / (lines.range_max - lines.range_min));
            const Rgb got = lines.image.at(ix, iy);
            EXPECT_LE(std::abs(int(got.r) - int(want.r)), 1) << x << " " << z;
            EXPECT_LE(std::abs(int(got.g) - int(want.g)), 1) << x << " " << z;
            EXPECT_LE(std::abs(int(got.b) - int(want.b)), 1) << x << " " << z;
            ++checked;
        }
    }
    EXPECT_EQ(checked, 32u);

    // A field the elements do not have: a particle field.
    o.field = "connectivity";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::Axisymmetric, o); }), "no field 'connectivity'"));
}

TEST(Render, BadOptionsFailNamingWhatIsWrong) {
    const LoadedSnapshot s = snapshot_of("bad_options", three_nodes());
    RenderOptions o;
    o.field = "presure";
    std::string e = error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); });
    EXPECT_TRUE(contains(e, "no field 'presure'") && contains(e, "pressure") && contains(e, "plastic_strain")) << e;
    o.field = "pressure:z";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "scalar field"));
    o.field = "velocity:y";
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "x and z"));
    o.field = "pressure";
    o.width = 10;
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "width 10 px"));
    o.width = 800;
    o.height = 100000;
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "height 100000 px"));
    o.height = 0;
    o.range_min = 3.0;
    o.range_max = 3.0;
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "must end above"));
    o.range_min.reset();
    o.range_max.reset();
    o.view = ViewDirection::PlusX;
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); }), "3D runs only"));
    o.view.reset();
    o.mirror = true;
    EXPECT_TRUE(contains(error_of([&] { render_snapshot(s, GeometryKind::ThreeD, o); }), "2D runs only"));
    EXPECT_TRUE(contains(error_of([&] { load_snapshot(read_pvd(s.entry.files[0].parent_path() / "particles.pvd"), 5); }),
                         "no snapshot 5"));
}

TEST(Render, ARegionDrawsOnlyItsWindowAndTakesTheColourRangeFromIt) {
    const LoadedSnapshot s = snapshot_of("region", three_nodes());
    RenderOptions o;
    o.field = "pressure";
    o.width = 400;
    o.height = 400;
    // A window around A and C only (x 0.5 to 2.5 mm, z 0.5 to 3.5 mm): B (x = 3 mm, reaching
    // 2.75 mm) is left out, so the range is A's and C's (0 to 5 Pa) and C takes the top colour.
    o.region = std::array<double, 4>{0.5e-3, 2.5e-3, 0.5e-3, 3.5e-3};
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.discs, 2u);
    EXPECT_EQ(p.range_min, 0.0);
    EXPECT_EQ(p.range_max, 5.0);
    EXPECT_EQ(pixel_at(p, 1e-3, 1e-3), colour_map(0.0));
    EXPECT_EQ(pixel_at(p, 2e-3, 3e-3), colour_map(1.0));
    // The window fills the plot: its corners are on the image, 2 mm high in ~all of the plot's height.
    const auto [x_left, y_top] = p.frame.pixel(0.5e-3, 3.5e-3);
    const auto [x_right, y_bottom] = p.frame.pixel(2.5e-3, 0.5e-3);
    EXPECT_GE(x_left, 0.0);
    EXPECT_LE(x_right, 400.0);
    EXPECT_GE(y_top, 0.0);
    EXPECT_LE(y_bottom, 400.0);
    EXPECT_GT(x_right - x_left, 100.0);
    // A disc reaching into the window from outside it is drawn: B's edge is at 2.75 mm.
    o.region = std::array<double, 4>{2.6e-3, 4e-3, 0.0, 2e-3};
    EXPECT_EQ(render_snapshot(s, GeometryKind::PlaneStrain, o).discs, 1u);
    // Nothing in the window, or a window the wrong way round: an error naming it.
    o.region = std::array<double, 4>{10e-3, 20e-3, 0.0, 1e-3};
    std::string e = error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); });
    EXPECT_TRUE(contains(e, "nothing to draw in the region") && contains(e, "spans")) << e;
    o.region = std::array<double, 4>{2e-3, 1e-3, 0.0, 1e-3};
    e = error_of([&] { render_snapshot(s, GeometryKind::PlaneStrain, o); });
    EXPECT_TRUE(contains(e, "must end above")) << e;
}

TEST(Render, NotFiniteValuesAreMarkedAndLeftOutOfTheRange) {
    NodeStore n = three_nodes();
    n.pressure[2] = std::nan("");
    const LoadedSnapshot s = snapshot_of("nan", n);
    RenderOptions o;
    o.field = "pressure";
    const Picture p = render_snapshot(s, GeometryKind::PlaneStrain, o);
    EXPECT_EQ(p.not_finite_values, 1u);
    EXPECT_EQ(p.range_max, 10.0);
    EXPECT_EQ(pixel_at(p, 2e-3, 3e-3), not_finite_colour);
}

TEST(ColourMap, LightnessRisesEvenlyFromEndToEnd) {
    // CIE L* of an sRGB colour (D65).
    const auto lightness = [](Rgb c) {
        const auto linear = [](std::uint8_t v) {
            const double s = v / 255.0;
            return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
        };
        const double y = 0.2126 * linear(c.r) + 0.7152 * linear(c.g) + 0.0722 * linear(c.b);
        return y > 216.0 / 24389.0 ? 116.0 * std::cbrt(y) - 16.0 : 24389.0 / 27.0 * y;
    };
    const int steps = 32;
    std::vector<double> rise;
    for (int k = 0; k < steps; ++k) rise.push_back(lightness(colour_map((k + 1.0) / steps)) - lightness(colour_map(double(k) / steps)));
    double total = 0.0;
    for (double r : rise) {
        EXPECT_GT(r, 0.0);
        total += r;
    }
    // Even: no step of 1/32 rises less than half or more than twice the mean step.
    for (double r : rise) {
        EXPECT_GT(r, 0.5 * total / steps);
        EXPECT_LT(r, 2.0 * total / steps);
    }
    EXPECT_GT(total, 60.0);  // dark to light: most of L*'s 0-100
    EXPECT_EQ(colour_map(-1.0), colour_map(0.0));
    EXPECT_EQ(colour_map(2.0), colour_map(1.0));
    EXPECT_EQ(colour_map(std::nan("")), colour_map(0.0));
}

TEST(Render, QuantitiesAreWrittenWithTheirPrefix) {
    EXPECT_EQ(format_quantity(4e-5, "s"), "40 us");
    EXPECT_EQ(format_quantity(1.25e9, "Pa"), "1.25 GPa");
    EXPECT_EQ(format_quantity(-3.5e8, "Pa"), "-350 MPa");
    EXPECT_EQ(format_quantity(999.7, "Pa"), "1 kPa");  // not "1e+03 Pa"
    EXPECT_EQ(format_quantity(2.5e-3, "m"), "2.5 mm");
    EXPECT_EQ(format_quantity(3e-6, "kg"), "3 mg");
    EXPECT_EQ(format_quantity(0.0, "kg"), "0 kg");
    EXPECT_EQ(format_quantity(0.0, "s"), "0 s");
    EXPECT_EQ(format_quantity(190.0, "m/s"), "190 m/s");
    EXPECT_EQ(format_quantity(0.5, ""), "0.5");
    EXPECT_EQ(field_unit("von_mises_stress"), "Pa");
    EXPECT_EQ(field_unit("plastic_strain"), "");
}

TEST(SnapshotReader, TheRunsGeometryComesFromItsSceneOrSummary) {
    const fs::path dir = fresh_dir("geometry");
    EXPECT_FALSE(read_run_geometry(dir));
    write_text(dir / "summary.json", "{\n  \"scene\": \"x\",\n  \"geometry\": \"plane strain\",\n  \"status\": \"finished\"\n}\n");
    auto g = read_run_geometry(dir);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->geometry, GeometryKind::PlaneStrain);
    EXPECT_EQ(g->source, "summary.json");
    write_text(dir / "scene.toml", "name = \"x\"\ngeometry = \"3d\"\n");
    g = read_run_geometry(dir);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->geometry, GeometryKind::ThreeD);
    EXPECT_EQ(g->source, "scene.toml");
    write_text(dir / "scene.toml", "geometry = \"spherical\"\n");
    EXPECT_TRUE(contains(error_of([&] { read_run_geometry(dir); }), "geometry 'spherical'"));
}

}  // namespace
}  // namespace gpa::io
