// Gauges (engine/include/gpa/engine/gauges.hpp): material points recorded over a run. Their
// histories against one-dimensional wave theory on the elastic bar of scenes/elastic-bar.toml,
// their nodes followed by id through reorderings, their files (GaugeWriter) and their bad input.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/gauges.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa {
namespace {

namespace fs = std::filesystem;

std::string elastic_bar_text() {
    std::ifstream in(fs::path(GPA_SCENES_DIR) / "elastic-bar.toml");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The elastic bar with `gauges` (TOML) added before its [stop] table.
Scene bar_with(const std::string& gauges) {
    std::string text = elastic_bar_text();
    const auto stop = text.find("\n[stop]");
    EXPECT_NE(stop, std::string::npos);
    text.insert(stop + 1, gauges + "\n");
    return io::parse_scene(text, "elastic-bar+gauges.toml");
}

// The time at which a recorded series first crosses `level` (linear between steps); NaN if never.
double crossing(const std::vector<double>& t, const std::vector<double>& v, double level) {
    for (std::size_t k = 1; k < t.size(); ++k) {
        if ((v[k - 1] - level) * (v[k] - level) <= 0.0 && v[k] != v[k - 1]) {
            return t[k - 1] + (level - v[k - 1]) / (v[k] - v[k - 1]) * (t[k] - t[k - 1]);
        }
    }
    return std::nan("");
}

// The mean of a series over [from, to].
double mean_over(const std::vector<double>& t, const std::vector<double>& v, double from, double to) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < t.size(); ++k) {
        if (t[k] >= from && t[k] <= to) {
            sum += v[k];
            ++n;
        }
    }
    return n > 0 ? sum / n : std::nan("");
}

// One-dimensional wave theory for the bar (scenes/elastic-bar.toml: E = 200 GPa, nu = 0,
// rho = 7800 kg/m^3, L = 20 mm, 10 m/s onto a rigid plane at t = 0): a compression wave runs up at
// c = sqrt(E / rho), with the bar at rest and sigma_zz = -rho c v0 behind it; it reflects from
// the free top as a release wave, behind which the bar moves up at v0 with no stress.
constexpr double rho = 7800.0, young = 200e9, v0 = 10.0, bar_length = 20e-3;
const double c_bar = std::sqrt(young / rho);

TEST(Gauges, APointInTheBarSeesTheCompressionWaveOfOneDimensionalTheory) {
    Scene scene = bar_with(R"([[gauge]]
name = "middle"
at = [0, "10 mm"]
fields = ["position", "velocity", "stress", "displacement"]

[[gauge]]
name = "top"
kind = "free_surface"
body = "bar"
at = [0, "20 mm"]
normal = "+z"
radius = "1 mm"
fields = ["normal_velocity", "velocity"]
)");
    scene.stop.end_time = 7.0e-6;  // before the release wave is back at the plane (2 L / c = 7.9 us)
    Simulation sim(scene, 2);
    Gauge middle(scene.gauges[0], scene, sim.nodes(), sim.real_count());
    Gauge top(scene.gauges[1], scene, sim.nodes(), sim.real_count());
    ASSERT_EQ(middle.node_ids().size(), 1u);
    // The top face's outermost row: every node of the last row (8 across the radius).
    EXPECT_EQ(top.node_ids().size(), 8u);
    ASSERT_EQ(middle.columns(), (std::vector<std::string>{"position_x_m", "position_z_m", "velocity_x_m_s", "velocity_z_m_s",
                                                           "stress_xx_Pa", "stress_zz_Pa", "stress_xz_Pa", "stress_tt_Pa",
                                                           "displacement_x_m", "displacement_z_m"}));
    ASSERT_EQ(top.columns(), (std::vector<std::string>{"normal_velocity_m_s", "velocity_x_m_s", "velocity_z_m_s"}));
    const double z_gauge = middle.read(sim.nodes(), sim.real_count())[1];
    EXPECT_NEAR(z_gauge, 10e-3, 0.0625e-3 + 1e-12);  // the node nearest to 10 mm: half a spacing away at most
    std::vector<double> t, v_mid, s_mid, v_top;
    while (!sim.finished()) {
        sim.step();
        const auto m = middle.read(sim.nodes(), sim.real_count());
        const auto f = top.read(sim.nodes(), sim.real_count());
        t.push_back(sim.time());
        v_mid.push_back(m[3]);
        s_mid.push_back(m[5]);
        v_top.push_back(f[0]);
        EXPECT_DOUBLE_EQ(f[0], f[2]);  // the normal +z: normal velocity is v_z
    }
    // Arrival at the gauge: the velocity half-way from -v0 to 0. The front is smeared over a few
    // spacings and travels at the lattice's bar speed, which is 0.5 % below c at 8 nodes across
    // the radius (the contact time comes out 0.46 % above 2 L / c, docs/performance.md, 1.1), so
    // the half-way point is allowed two spacings' travel time (0.049 us) plus 0.5 % of the path's.
    // (Measured: 0.024 us late half-way up, 0.046 us at the top.)
    const double spacing_time = 0.125e-3 / c_bar;
    const auto allowed = [&](double path) { return 2.0 * spacing_time + 0.005 * path / c_bar; };
    const double arrival = crossing(t, v_mid, -0.5 * v0);
    EXPECT_NEAR(arrival, z_gauge / c_bar, allowed(z_gauge)) << "arrival " << arrival * 1e6 << " us";
    // Behind the front, until the release wave returns from the top ((2 L - z) / c = 5.92 us): at
    // rest, sigma_zz = -rho c v0 = -395 MPa. The means over the plateau (0.5 us, 20 spacings'
    // travel, away from either front) smooth the lattice's ringing (+-5 % about the mean in the
    // undamped bar); 1 % allows for the discrete wave impedance at 8 nodes across the radius.
    // (Measured: -395.3 MPa, +0.09 %; velocity 0.001 m/s.)
    const double plateau_from = z_gauge / c_bar + 0.5e-6, plateau_to = (2.0 * bar_length - z_gauge) / c_bar - 0.5e-6;
    EXPECT_NEAR(mean_over(t, s_mid, plateau_from, plateau_to), -rho * c_bar * v0, 0.01 * rho * c_bar * v0);
    EXPECT_NEAR(mean_over(t, v_mid, plateau_from, plateau_to), 0.0, 0.01 * v0);
    // The free top: -v0 until the wave reaches it at L / c = 3.95 us, then +v0 (the free-surface
    // velocity doubles the particle velocity jump). Its nodes stand half a spacing below the face.
    // (Measured: -10.000 m/s before, +10.040 m/s after.)
    const double top_path = bar_length - 0.0625e-3;
    const double top_arrival = crossing(t, v_top, 0.0);
    EXPECT_NEAR(top_arrival, top_path / c_bar, allowed(top_path)) << "top " << top_arrival * 1e6 << " us";
    EXPECT_NEAR(mean_over(t, v_top, 0.2e-6, bar_length / c_bar - 0.5e-6), -v0, 0.01 * v0);
    EXPECT_NEAR(mean_over(t, v_top, bar_length / c_bar + 0.5e-6, 7.0e-6), v0, 0.01 * v0);
}

TEST(Gauges, AGaugeFollowsItsNodesByIdThroughReorderings) {
    Scene scene = bar_with(R"([[gauge]]
name = "ring"
at = [0, "5 mm"]
radius = "0.3 mm"
fields = ["position", "velocity", "pressure"]
)");
    scene.solver.reorder_interval = 3;
    scene.stop.end_time = 0.0;
    scene.stop.max_steps = 10;
    Simulation sim(scene, 2);
    Gauge gauge(scene.gauges[0], scene, sim.nodes(), sim.real_count());
    const auto ids = gauge.node_ids();
    ASSERT_GE(ids.size(), 3u);
    EXPECT_TRUE(std::is_sorted(ids.begin(), ids.end()));
    for (int k = 0; k < 10; ++k) sim.step();
    const NodeStore& n = sim.nodes();
    // The mass-weighted means of the nodes that carry the ids, wherever they are now.
    double mass = 0.0, x = 0.0, z = 0.0, vz = 0.0, p = 0.0;
    std::size_t found = 0;
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        if (!std::binary_search(ids.begin(), ids.end(), n.id[i])) continue;
        ++found;
        mass += n.mass[i];
        x += n.mass[i] * n.position[0][i];
        z += n.mass[i] * n.position[1][i];
        vz += n.mass[i] * n.velocity[1][i];
        p += n.mass[i] * n.pressure[i];
    }
    ASSERT_EQ(found, ids.size());
    const auto values = gauge.read(n, sim.real_count());
    ASSERT_EQ(values.size(), 5u);
    // The same sums in another order: equal to round-off.
    EXPECT_NEAR(values[0], x / mass, 1e-15);
    EXPECT_NEAR(values[1], z / mass, 1e-15);
    EXPECT_NEAR(values[3], vz / mass, 1e-14 * v0);
    EXPECT_NEAR(values[4], p / mass, 1e-12 * std::max(1.0, std::abs(p / mass)));
    // Read again after the store is reversed: the gauge finds its nodes by id and sums them in
    // the order of their ids, so the values are the same bit for bit.
    NodeStore reversed = n;
    std::vector<NodeIndex> new_to_old(n.size());
    for (std::size_t i = 0; i < n.size(); ++i) new_to_old[i] = static_cast<NodeIndex>(i < sim.real_count() ? sim.real_count() - 1 - i : i);
    reversed.permute(new_to_old);
    ASSERT_NE(reversed.id[0], n.id[0]);
    EXPECT_EQ(gauge.read(reversed, sim.real_count()), values);
    // The nodes are those within the radius of the point at t = 0.
    for (std::size_t i = 0; i < sim.real_count(); ++i) {
        const double d = std::hypot(n.initial_position[0][i], n.initial_position[1][i] - 5e-3);
        EXPECT_EQ(std::binary_search(ids.begin(), ids.end(), n.id[i]), d <= 0.3e-3) << "node id " << n.id[i];
    }
}

TEST(Gauges, WriterFilesHaveAHeaderAndARowPerCall) {
    const Scene scene = bar_with(R"([[gauge]]
name = "a"
at = [0, "1 mm"]
fields = ["temperature", "damage"]
)");
    Simulation sim(scene, 1);
    const fs::path dir = fs::temp_directory_path() / fmt::format("gpa_gauges_{}", ::getpid());
    fs::remove_all(dir);
    fs::create_directories(dir);
    {
        io::GaugeWriter writer(dir, sim);
        writer.write(sim);
        sim.step();
        writer.write(sim);
        ASSERT_EQ(writer.marks().size(), 1u);
        EXPECT_EQ(writer.marks()[0].bytes, static_cast<long long>(fs::file_size(dir / "gauge_a.csv")));
    }
    std::ifstream in(dir / "gauge_a.csv");
    std::string header, row0, row1, more;
    std::getline(in, header);
    std::getline(in, row0);
    std::getline(in, row1);
    EXPECT_FALSE(std::getline(in, more));
    EXPECT_EQ(header, "time_s,step,temperature_K,damage");
    EXPECT_EQ(row0.substr(0, row0.find(',')), "0.000000000e+00");
    EXPECT_NE(row1.find(",1,"), std::string::npos) << row1;
    fs::remove_all(dir);
}

// Each rule of a gauge fails with a message that names the gauge (or, for the reader's rules, its
// key and line) and says what to write instead.
TEST(Gauges, BadGaugesAreRefusedWithTheirNameAndWhy) {
    const auto refused = [](const std::string& gauges, const std::string& words) {
        try {
            Scene scene = bar_with(gauges);
            Simulation sim(scene, 1);
            for (const auto& spec : scene.gauges) Gauge(spec, scene, sim.nodes(), sim.real_count());
            ADD_FAILURE() << "accepted: " << gauges;
        } catch (const std::exception& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    refused("[[gauge]]\nat = [0, \"1 mm\"]", "gauge[0]: missing required key \"name\"");
    refused("[[gauge]]\nname = \"a b\"\nat = [0, \"1 mm\"]", "letters, digits, '-' and '_' only");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\n[[gauge]]\nname = \"a\"\nat = [0, \"2 mm\"]", "already used by gauge[0]");
    refused("[[gauge]]\nname = \"a\"", "gauge \"a\" (gauge[0]): missing required key \"at\"");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\", 0]", "gauge \"a\" (gauge[0]).at: expected an array of 2 length values [x, z], got 3 values");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 kg\"]", "gauge \"a\" (gauge[0]).at[1]: \"1 kg\" is in kg (SI kg), which no scene value is; a length takes");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nbody = \"rod\"", "body \"rod\" is not a body of the scene");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nradius = \"-1 mm\"", "gauge \"a\" (gauge[0]).radius: \"-1 mm\" must not be negative");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nkind = \"line\"", "\"line\" is not one of \"point\" or \"free_surface\"");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nnormal = \"+z\"", "normal: applies to free-surface gauges only");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nbody = \"bar\"\nat = [0, \"20 mm\"]",
            "missing required key \"normal\"");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nbody = \"bar\"\nat = [0, \"20 mm\"]\nnormal = \"+y\"",
            "\"+x\", \"-x\", \"+z\" or \"-z\"");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nat = [0, \"20 mm\"]\nnormal = \"+z\"", "a free-surface gauge names its body");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nbody = \"bar\"\nat = [0, \"10 mm\"]\nnormal = \"-x\"",
            "normal -x points at the axis");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nfields = [\"speed\"]", "\"speed\" is not a gauge field");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nfields = []", "a list of field names");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nfields = [\"pressure\", \"pressure\"]", "pressure is listed twice");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\nfields = [\"normal_velocity\"]", "a point gauge has none");
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"1 mm\"]\ncolour = 1", "gauge \"a\" (gauge[0]).colour: unknown key; a gauge takes name, kind, at, body, radius, normal, fields");
    // Rules that need the nodes: a point away from the body, nothing within the radius, a free
    // surface away from the face or beside it.
    refused("[[gauge]]\nname = \"a\"\nat = [0, \"100 mm\"]", "is not in any particle body: the nearest node is");
    refused("[[gauge]]\nname = \"a\"\nat = [\"5 mm\", \"1 mm\"]\nradius = \"0.1 mm\"", "no node of any particle body lies within radius");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nbody = \"bar\"\nat = [0, \"15 mm\"]\nnormal = \"+z\"", "is not on the face");
    refused("[[gauge]]\nname = \"a\"\nkind = \"free_surface\"\nbody = \"bar\"\nat = [\"50 mm\", \"20 mm\"]\nnormal = \"+z\"",
            "is beside body \"bar\"");
}

}  // namespace
}  // namespace gpa
