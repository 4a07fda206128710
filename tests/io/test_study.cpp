// The arithmetic and the parsers of `gpa study`: Richardson extrapolation on exact synthetic
// sequences f0 + C h^p (constant and unequal refinement ratios), the flags for sequences that
// do not converge, the command's lists and variants, what a run is measured by, and the
// study's outputs.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"
#include "gpa/io/svg_plot.hpp"

namespace gpa::io {
namespace {

std::vector<double> values_on(const std::vector<double>& h, double f0, double c, double p) {
    std::vector<double> f;
    for (double x : h) f.push_back(f0 + c * std::pow(x, p));
    return f;
}

// --- Richardson extrapolation --------------------------------------------------------------

TEST(Richardson, ConstantRatioRecoversOrderAndLimitToRoundOff) {
    const std::vector<double> h{1.0, 0.5, 0.25};
    for (double p : {0.5, 1.0, 2.0, 3.0}) {
        for (double c : {0.3, -2.0}) {
            const auto f = values_on(h, 16.21, c, p);
            const auto e = extrapolate(h, f);
            ASSERT_EQ(e.status, ConvergenceStatus::Converging) << "p " << p << ", C " << c;
            EXPECT_NEAR(e.order, p, 1e-11 * p);
            EXPECT_NEAR(e.extrapolated, 16.21, 1e-13 * 16.21);
            EXPECT_DOUBLE_EQ(e.ratio, 2.0);
            EXPECT_NEAR(observed_order(1.0, 0.5, 0.25, f[0], f[1], f[2]), p, 1e-11 * p);
        }
    }
}

TEST(Richardson, UnequalRatiosAreSolvedForTheOrder) {
    // --refine 1,1.5,2: ratios 1.5 and 4/3.
    const std::vector<double> h{0.3, 0.2, 0.15};
    for (double p : {0.15, 0.45, 0.55, 1.0, 1.7, 4.0}) {
        const auto f = values_on(h, 7.9, 0.8, p);
        const auto e = extrapolate(h, f);
        ASSERT_EQ(e.status, ConvergenceStatus::Converging);
        EXPECT_NEAR(e.order, p, 1e-9 * p);
        EXPECT_NEAR(e.extrapolated, 7.9, 1e-12 * 7.9);
        EXPECT_NEAR(e.ratio, 4.0 / 3.0, 1e-15);
        // Orders below one half are marked slow; the gain is (f0 - f3) / (f3 - f2), here
        // h3^p / (h2^p - h3^p) = 1 / ((h2/h3)^p - 1).
        EXPECT_EQ(e.slow, p < slow_order) << "p " << p;
        EXPECT_NEAR(e.gain, (7.9 - f[2]) / (f[2] - f[1]), 1e-9 * e.gain) << "p " << p;
    }
    // Random spacings and orders, negative orders among them (diverging sequences).
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> ratio(1.05, 3.0), order(-3.0, 6.0);
    for (int k = 0; k < 200; ++k) {
        const double h3 = 1.0, h2 = h3 * ratio(rng), h1 = h2 * ratio(rng), p = order(rng);
        if (std::abs(p) < 1e-3) continue;
        const auto f = values_on({h1, h2, h3}, 1.0, 1.0, p);
        EXPECT_NEAR(observed_order(h1, h2, h3, f[0], f[1], f[2]), p, 1e-7 * std::max(1.0, std::abs(p)))
            << "h " << h1 << ", " << h2 << ", " << h3;
    }
}

TEST(Richardson, DivergingSeriesAreNeitherSlowNorGivenAGain) {
    const std::vector<double> h{0.3, 0.2, 0.15};
    const auto d = extrapolate(h, values_on(h, 1.0, 1.0, -1.0));
    ASSERT_EQ(d.status, ConvergenceStatus::Diverging);
    EXPECT_FALSE(d.slow);
    EXPECT_TRUE(std::isnan(d.gain));
}

TEST(Richardson, UsesTheThreeFinestSpacingsInAnyOrder) {
    const std::vector<double> h{0.25, 2.0, 0.5, 1.0};
    auto f = values_on(h, 3.0, 1.0, 2.0);
    f[1] = 1e9;  // the coarsest is not used
    const auto e = extrapolate(h, f);
    ASSERT_EQ(e.status, ConvergenceStatus::Converging);
    EXPECT_NEAR(e.order, 2.0, 1e-11);
    EXPECT_NEAR(e.extrapolated, 3.0, 1e-13);
    EXPECT_EQ(e.used[0], 3u);
    EXPECT_EQ(e.used[1], 2u);
    EXPECT_EQ(e.used[2], 0u);
}

TEST(Richardson, NonMonotoneSequencesAreFlaggedAndNotExtrapolated) {
    const std::vector<double> h{1.0, 0.5, 0.25};
    for (const std::vector<double>& f : {std::vector<double>{1.0, 1.2, 1.1}, std::vector<double>{1.0, 0.9, 1.0},
                                         std::vector<double>{1.0, 1.0, 1.1}, std::vector<double>{1.0, 1.1, 1.1}}) {
        const auto e = extrapolate(h, f);
        EXPECT_EQ(e.status, ConvergenceStatus::NotMonotone) << f[0] << ", " << f[1] << ", " << f[2];
        EXPECT_TRUE(std::isnan(e.order));
        EXPECT_TRUE(std::isnan(e.extrapolated));
        EXPECT_TRUE(std::isnan(observed_order(1.0, 0.5, 0.25, f[0], f[1], f[2])));
    }
    EXPECT_EQ(describe(ConvergenceStatus::NotMonotone), "not monotone");
}

TEST(Richardson, GrowingDifferencesAreDivergingWithANegativeOrder) {
    const auto e = extrapolate(std::vector<double>{1.0, 0.5, 0.25}, std::vector<double>{1.0, 1.1, 1.3});
    EXPECT_EQ(e.status, ConvergenceStatus::Diverging);
    EXPECT_NEAR(e.order, -1.0, 1e-12);
    EXPECT_TRUE(std::isnan(e.extrapolated));
}

TEST(Richardson, TwoResolutionsGiveNoOrder) {
    const auto e = extrapolate(std::vector<double>{1.0, 0.5}, std::vector<double>{1.0, 1.1});
    EXPECT_EQ(e.status, ConvergenceStatus::TooFew);
    EXPECT_TRUE(std::isnan(e.order));
    EXPECT_TRUE(std::isnan(e.extrapolated));
}

TEST(Richardson, EqualValuesAreTheirOwnLimitAndMissingValuesGiveNothing) {
    const std::vector<double> h{1.0, 0.5, 0.25};
    const auto same = extrapolate(h, std::vector<double>{2.5, 2.5, 2.5});
    EXPECT_EQ(same.status, ConvergenceStatus::Unchanged);
    EXPECT_EQ(same.extrapolated, 2.5);
    EXPECT_TRUE(std::isnan(same.order));
    const auto missing = extrapolate(h, std::vector<double>{1.0, 1.1, std::nan("")});
    EXPECT_EQ(missing.status, ConvergenceStatus::NotAvailable);
    EXPECT_TRUE(std::isnan(missing.extrapolated));
}

TEST(Richardson, SpacingsMustBeDistinctPositiveAndDecreasing) {
    EXPECT_THROW(extrapolate(std::vector<double>{1.0, 0.5, 0.5}, std::vector<double>{1, 2, 3}), std::invalid_argument);
    EXPECT_THROW(extrapolate(std::vector<double>{1.0, 0.0, 0.5}, std::vector<double>{1, 2, 3}), std::invalid_argument);
    EXPECT_THROW(extrapolate(std::vector<double>{1.0, 0.5}, std::vector<double>{1, 2, 3}), std::invalid_argument);
    EXPECT_THROW(observed_order(0.5, 1.0, 0.25, 1, 2, 3), std::invalid_argument);
}

TEST(Richardson, RelativeErrorNeedsANonZeroReference) {
    EXPECT_NEAR(relative_error(10.2, 10.0), 0.02, 1e-15);
    EXPECT_NEAR(relative_error(-9.0, -10.0), 0.1, 1e-15);
    EXPECT_TRUE(std::isnan(relative_error(1.0, 0.0)));
    EXPECT_TRUE(std::isnan(relative_error(std::nan(""), 1.0)));
}

// --- the command's lists --------------------------------------------------------------------

std::string input_error(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    ADD_FAILURE() << "no InputError";
    return {};
}

TEST(StudyLists, RefinementsAreSortedPositiveAndDistinct) {
    EXPECT_EQ(parse_refinements("1,1.5,2"), (std::vector<double>{1.0, 1.5, 2.0}));
    EXPECT_EQ(parse_refinements(" 2, 0.5 ,1"), (std::vector<double>{0.5, 1.0, 2.0}));
    for (const char* bad : {"", "1,,2", "1,x", "0,1", "-1", "1,1", "inf", "nan", "1;2"}) {
        const std::string m = input_error([&] { parse_refinements(bad); });
        EXPECT_NE(m.find("--refine"), std::string::npos) << bad << ": " << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
    EXPECT_NE(input_error([] { parse_refinements("1,x"); }).find("e.g. 1,1.5,2"), std::string::npos);
    EXPECT_NE(input_error([] { parse_refinements("1,2,1"); }).find("twice"), std::string::npos);
}

TEST(StudyLists, ThreadCounts) {
    EXPECT_EQ(parse_thread_counts("1,2"), (std::vector<int>{1, 2}));
    EXPECT_EQ(parse_thread_counts("0"), (std::vector<int>{0}));
    for (const char* bad : {"", "-1", "1.5", "5000", "1,1", "two"}) {
        EXPECT_NE(input_error([&] { parse_thread_counts(bad); }).find("--threads"), std::string::npos) << bad;
    }
}

TEST(StudyVariants, ParsesNamesSettingsAndThreads) {
    const auto plain = parse_variant("scene");
    EXPECT_EQ(plain.name, "scene");
    EXPECT_TRUE(plain.settings.empty());
    EXPECT_FALSE(plain.threads);
    EXPECT_TRUE(parse_variant("as-written:").settings.empty());
    const auto v = parse_variant("sph-bond:weight=sph-nsf, viscosity=bond,smoothing=tension,cfl=0.3,threads=2");
    EXPECT_EQ(v.name, "sph-bond");
    ASSERT_EQ(v.settings.size(), 4u);
    EXPECT_EQ(v.settings[0], (std::pair<std::string, std::string>{"weight", "sph-nsf"}));
    EXPECT_EQ(v.settings[1], (std::pair<std::string, std::string>{"viscosity", "bond"}));
    EXPECT_EQ(v.settings[3], (std::pair<std::string, std::string>{"cfl", "0.3"}));
    ASSERT_TRUE(v.threads);
    EXPECT_EQ(*v.threads, 2);
}

TEST(StudyVariants, BadVariantsNameTheOptionAndWhatIsAllowed) {
    const struct {
        const char* text;
        const char* fragment;
    } cases[] = {
        {"", "needs a name"},
        {":weight=sph", "needs a name"},
        {"weight=sph", "name before its settings"},
        {"a b:weight=sph", "letters, digits"},
        {"x:weight=foo", "solver.weight: \"foo\" is not one of \"gpa\" or \"sph-nsf\""},
        // A scene file has never taken "sph" for "sph-nsf"; a variant no longer does either.
        {"x:weight=sph", "solver.weight: \"sph\" is not one of \"gpa\" or \"sph-nsf\""},
        {"x:connectivity=sometimes", "solver.connectivity: \"sometimes\" is not one of \"fixed\", \"variable\" or \"automatic\""},
        {"x:viscosity=lots", "solver.viscosity: \"lots\" is not one of \"none\", \"nodal\" or \"bond\""},
        {"x:smoothing=on", "solver.smoothing: \"on\" is not one of \"off\", \"everywhere\" or \"tension\""},
        {"x:normalisation=full", "solver.normalisation: \"full\" is not one of \"per-direction\" or \"moment-matrix\""},
        {"x:discretisation=fem", "discretisation must be one of particles, elements, not 'fem'"},
        {"x:colour=red", "unknown key 'colour'; keys: connectivity, switch_plastic_strain"},
        {"x:cfl=2", "solver.cfl = 2 is outside (0, 1]"},
        {"x:neighbor_skin=0", "unknown key 'neighbor_skin'; did you mean 'neighbour_skin'?"},
        {"x:max_time_step=10 m", "solver.max_time_step"},
        {"x:failure=yes", "solver.failure: expected true or false"},
        {"x:reorder_interval=-1", "solver.reorder_interval: -1 is not a whole number of at least 0"},
        {"x:weight", "'weight' is not key=value"},
        {"x:weight=gpa,weight=sph", "weight is set twice"},
        {"x:cfl=fast", "solver.cfl: \"fast\" is not a number"},
        {"x:threads=-1", "threads must be a whole number"},
    };
    for (const auto& c : cases) {
        const std::string m = input_error([&] { parse_variant(c.text); });
        EXPECT_NE(m.find(fmt::format("--variant '{}'", c.text)), std::string::npos) << m;
        EXPECT_NE(m.find(c.fragment), std::string::npos) << c.text << ": " << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

Scene bar_scene(bool lift_off) {
    Scene s;
    s.name = "bar";
    s.geometry = GeometryKind::Axisymmetric;
    materials::Material m;
    m.name = "elastic";
    m.density = 7800.0;
    m.shear_modulus = 100e9;  // E = 200 GPa, nu = 0
    m.eos = materials::LinearEos{200e9 / 3.0, false};
    m.strength = materials::ElasticStrength{};
    s.materials.push_back(m);
    BodySpec bar;
    bar.name = "bar";
    bar.radius = 1e-3;
    bar.length = 10e-3;
    bar.spacing = 0.25e-3;
    bar.material = "elastic";
    bar.velocity = {0.0, -10.0, 0.0};
    bar.connectivity = ConnectivityMode::Variable;
    s.bodies.push_back(bar);
    PlaneSpec anvil;
    anvil.name = "anvil";
    anvil.lift_off = lift_off;
    s.planes.push_back(anvil);
    s.solver.viscosity = ViscosityKind::None;
    s.stop.end_time = 6e-6;
    return s;
}

TEST(StudyVariants, APresetAppliesFirstAndTheVariantsKeysOverrideIt) {
    Scene s = bar_scene(true);
    apply_variant(parse_variant("x:influence_distance=1.2,preset=taylor-bar,cfl=0.3"), s);
    EXPECT_EQ(s.solver.weight, WeightKind::SphNsf);
    EXPECT_DOUBLE_EQ(s.solver.influence_distance, 1.2);
    EXPECT_DOUBLE_EQ(s.solver.cfl, 0.3);
    EXPECT_EQ(input_error([&] { parse_variant("x:preset=nsf"); }),
              "--variant 'x:preset=nsf': preset must be one of paper, taylor-bar, not 'nsf'");
}

TEST(StudyVariants, ApplyChangesTheSolverAndChecksTheScene) {
    Scene s = bar_scene(true);
    apply_variant(parse_variant("x:connectivity=automatic,weight=sph-nsf,viscosity=bond,smoothing=everywhere,"
                                "normalisation=moment-matrix,cfl=0.3,influence_distance=1.2"),
                  s);
    EXPECT_EQ(s.solver.connectivity, ConnectivityMode::Automatic);
    EXPECT_FALSE(s.bodies[0].connectivity) << "the variant's connectivity holds for every body";
    EXPECT_EQ(s.solver.weight, WeightKind::SphNsf);
    EXPECT_EQ(s.solver.viscosity, ViscosityKind::Bond);
    EXPECT_EQ(s.solver.smoothing, SmoothingMode::Everywhere);
    EXPECT_EQ(s.solver.normalisation, Normalisation::MomentMatrix);
    EXPECT_DOUBLE_EQ(s.solver.cfl, 0.3);
    EXPECT_DOUBLE_EQ(s.solver.influence_distance, 1.2);
    Scene t = bar_scene(true);
    // parse_variant refuses the range at once; apply_variant checks a Variant built in code too.
    EXPECT_NE(input_error([&] { parse_variant("slow:cfl=2"); }).find("--variant 'slow:cfl=2': solver.cfl"), std::string::npos);
    const std::string m = input_error([&] { apply_variant(Variant{"slow", {{"cfl", "2"}}, std::nullopt}, t); });
    EXPECT_NE(m.find("--variant slow"), std::string::npos) << m;
    EXPECT_NE(m.find("cfl"), std::string::npos) << m;
}

TEST(StudyVariants, RefinementDividesEverySpacing) {
    Scene s = bar_scene(true);
    s.bodies[0].spacing_z = 0.5e-3;
    const Scene r = refined(s, 2.0);
    EXPECT_DOUBLE_EQ(r.bodies[0].spacing, 0.125e-3);
    EXPECT_DOUBLE_EQ(r.bodies[0].spacing_z, 0.25e-3);
    EXPECT_NEAR(lattice_cell_size(refined(bar_scene(true), 2.0)), 0.125e-3, 1e-15);
    // A spacing that does not fit the radius: the lattice's own cell, 1 mm / 3 across, 10 mm / 30 along.
    Scene odd = bar_scene(true);
    odd.bodies[0].spacing = 0.34e-3;
    EXPECT_NEAR(lattice_cell_size(odd), std::sqrt(1e-3 / 3 * 10e-3 / 29), 1e-15);
}

// --- what a run is measured by --------------------------------------------------------------

TEST(RunProbe, ABarThatBouncesHasAContactTimeAndAReboundSpeed) {
    Simulation sim(bar_scene(true), 1);
    RunProbe probe(sim);
    while (!sim.finished()) {
        sim.step();
        probe.observe(sim);
    }
    const auto m = probe.metrics(sim);
    const double c = std::sqrt(200e9 / 7800.0);
    ASSERT_TRUE(m.count("contact_time"));
    ASSERT_TRUE(m.count("rebound_speed"));
    // The bar has left the plane: its length and footprint are measured on the body itself
    // (docs/measurement.md): the 10 mm bar, 2 mm across, each to within one cell (0.25 mm) of the
    // reach at its ends (the free vibration adds only the strain v/c = 0.2 %).
    ASSERT_TRUE(m.count("final_length"));
    EXPECT_NEAR(m.at("final_length"), 10e-3, 0.25e-3);
    ASSERT_TRUE(m.count("footprint_diameter"));
    EXPECT_NEAR(m.at("footprint_diameter"), 2e-3, 0.25e-3);
    // 4 nodes across the radius: within 5 % of 2 L / c and of the impact speed.
    EXPECT_NEAR(m.at("contact_time"), 2 * 10e-3 / c, 0.05 * 2 * 10e-3 / c);
    EXPECT_NEAR(m.at("rebound_speed"), 10.0, 0.5);
    EXPECT_TRUE(m.count("energy_error"));
}

TEST(RunProbe, ABarHeldOnThePlaneHasALengthAndAFootprint) {
    Simulation sim(bar_scene(false), 1);
    RunProbe probe(sim);
    while (!sim.finished()) {
        sim.step();
        probe.observe(sim);
    }
    const auto m = probe.metrics(sim);
    EXPECT_FALSE(m.count("contact_time"));
    ASSERT_TRUE(m.count("final_length"));
    EXPECT_NEAR(m.at("final_length"), 10e-3, 0.5e-3);
    EXPECT_GT(m.at("footprint_diameter"), 1.5e-3);
}

// A projectile and a target: the crater and the residual velocity, and no Taylor metrics (no
// rigid plane); a bar on its anvil has no crater metrics (nothing at rest).
TEST(RunProbe, AProjectileAndATargetHaveACraterAndAResidualVelocity) {
    const std::string impact = R"toml(
name = "impact"
geometry = "axisymmetric"
[[body]]
name = "plate"
shape = "cylinder"
material = "OFHC copper"
radius = "3 mm"
length = "1 mm"
spacing = "0.25 mm"
[[body]]
name = "rod"
shape = "cylinder"
material = "OFHC copper"
origin = [0, "1 mm"]
radius = "0.5 mm"
length = "1 mm"
spacing = "0.25 mm"
velocity = [0, "-1000 m/s"]
[stop]
end_time = "0.3 us"
)toml";
    Simulation sim(io::parse_scene(impact, "impact.toml"), 1);
    RunProbe probe(sim);
    while (!sim.finished()) {
        sim.step();
        probe.observe(sim);
    }
    sim.measure_bodies();
    const auto m = probe.metrics(sim);
    ASSERT_TRUE(m.count("crater_depth"));
    ASSERT_TRUE(m.count("crater_diameter"));
    ASSERT_TRUE(m.count("residual_velocity"));
    // 0.3 us after a 1 km/s impact: the rod has slowed (a copper-on-copper impact halves the speed
    // at the interface) but still moves into the plate, which has a dent: at most the rod's travel,
    // 0.3 mm, plus a node's reach (d/2 = 0.125 mm) by which the rule measures it.
    EXPECT_GT(m.at("residual_velocity"), 0.0);
    EXPECT_LT(m.at("residual_velocity"), 1000.0);
    EXPECT_GT(m.at("crater_depth"), 0.0);
    EXPECT_LT(m.at("crater_depth"), 0.3e-3 + 0.125e-3);
    EXPECT_FALSE(m.count("final_length"));
    EXPECT_FALSE(m.count("contact_time"));
    Simulation bar(bar_scene(false), 1);
    for (int k = 0; k < 5; ++k) bar.step();
    bar.measure_bodies();
    EXPECT_FALSE(RunProbe(bar).metrics(bar).count("crater_depth"));
}

// scenes/elastic-bar.toml states its answers from its own material and size: Poisson's ratio 0,
// contact time 2 L / c with the bar speed c = sqrt(E / rho), rebound at the impact speed.
TEST(RunProbe, TheElasticBarSceneStatesTheAnswersOfItsOwnNumbers) {
    const Scene s = load_scene(std::string(GPA_SCENES_DIR) + "/elastic-bar.toml");
    const auto& m = s.materials.at(0);
    const double k = std::get<materials::LinearEos>(m.eos).bulk_modulus, g = m.shear_modulus;
    EXPECT_NEAR((3 * k - 2 * g) / (2 * (3 * k + g)), 0.0, 1e-9) << "Poisson's ratio";
    const double young = 9 * k * g / (3 * k + g);
    const double c = std::sqrt(young / m.density);
    EXPECT_NEAR(std::sqrt((k + 4 * g / 3) / m.density), c, 1e-6 * c) << "bar and dilatational speeds";
    const auto& bar = s.bodies.at(0);
    EXPECT_GE(bar.length, 10 * 2 * bar.radius);
    EXPECT_NEAR(s.reference.at("contact_time"), 2 * bar.length / c, 1e-5 * 2 * bar.length / c);
    EXPECT_DOUBLE_EQ(s.reference.at("rebound_speed"), std::abs(bar.velocity[1]));
    EXPECT_EQ(s.solver.viscosity, ViscosityKind::None);
    EXPECT_TRUE(s.planes.at(0).lift_off);
    EXPECT_GT(s.stop.end_time, 1.3 * 2 * bar.length / c) << "the run must outlast the contact";
}

// --- a study's outputs ----------------------------------------------------------------------

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

StudyReport synthetic_report() {
    StudyReport r;
    r.scene_name = "synthetic";
    r.scene_file = "synthetic.toml";
    r.refinements = {1.0, 2.0, 4.0};
    r.variants = {Variant{"a", {}, {}}, Variant{"b", {{"weight", "sph"}}, {}}};
    r.reference = {{"final_length", 0.0162}};
    for (const char* series : {"a", "b"}) {
        for (double f : r.refinements) {
            StudyCase c;
            c.variant = c.series = series;
            c.refinement = f;
            c.cell_size = 1e-3 / f;
            c.threads = 1;
            c.finished = true;
            c.message = "end time reached";
            c.nodes = 100 * static_cast<std::size_t>(f * f);
            c.steps = 10;
            c.wall_seconds = 0.1 * f * f * f;
            c.peak_bytes = 1e7;
            c.case_bytes = 1e6;
            // a: f0 + C h (order 1); b: not monotone.
            const double length = std::string(series) == "a" ? 0.0165 + 2.0 * c.cell_size : 0.0165 + (f == 2.0 ? 1e-4 : 0.0);
            c.metrics = {{"final_length", length}, {"energy_error", 1e-3}, {"plastic_work", 0.0}};
            r.cases.push_back(c);
        }
    }
    return r;
}

TEST(StudyOutputs, AnalysisKeepsDiscretisationAndReferenceErrorsApart) {
    const auto r = synthetic_report();
    const auto a = analyse_study(r);
    EXPECT_EQ(a.metrics, (std::vector<std::string>{"final_length", "energy_error"})) << "plastic work is zero everywhere";
    EXPECT_EQ(a.series, (std::vector<std::string>{"a", "b"}));
    const auto& ea = a.extrapolations.at({"a", "final_length"});
    ASSERT_EQ(ea.status, ConvergenceStatus::Converging);
    EXPECT_NEAR(ea.order, 1.0, 1e-9);
    EXPECT_NEAR(ea.extrapolated, 0.0165, 1e-14);
    EXPECT_EQ(a.extrapolations.at({"b", "final_length"}).status, ConvergenceStatus::NotMonotone);
    // Case 0 (a, h = 1 mm): 0.0185 against the limit 0.0165 and the answer 0.0162.
    EXPECT_NEAR(a.errors[0].at("final_length").discretisation, 0.002 / 0.0165, 1e-10);
    EXPECT_NEAR(a.errors[0].at("final_length").reference, (0.0185 - 0.0162) / 0.0162, 1e-10);
    EXPECT_TRUE(std::isnan(a.errors[3].at("final_length").discretisation)) << "no limit for a non-monotone series";
    EXPECT_FALSE(a.errors[0].count("energy_error")) << "the energy error is shown, not analysed";
}

TEST(StudyOutputs, CsvMarkdownAndPlotsAreWritten) {
    const auto dir = std::filesystem::temp_directory_path() / "gpa_test_study_outputs";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    const auto r = synthetic_report();
    const auto a = analyse_study(r);
    write_study_csv(dir / "study.csv", r, a);
    write_study_markdown(dir / "study.md", r, a);
    const auto plots = write_study_plots(dir, r, a);
    const std::string csv = read_text(dir / "study.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);
    EXPECT_EQ(csv.rfind("variant,series,threads,refinement,cell_size_m,", 0), 0u);
    for (const char* column : {"wall_s", "node_steps_per_s", "peak_memory_MB", "bytes_per_node", "final_length_m",
                               "final_length_discretisation_error", "final_length_reference_error", "energy_error"}) {
        EXPECT_NE(csv.find(column), std::string::npos) << column;
    }
    const std::string md = read_text(dir / "study.md");
    for (const char* text : {"## final_length (mm)", "| a | 1 |", "discretisation error", "reference error",
                             "## Observed orders", "not monotone", "| a | 1.00 |"}) {
        EXPECT_NE(md.find(text), std::string::npos) << text;
    }
    ASSERT_EQ(plots.size(), 2u);
    const std::string svg = read_text(dir / "error_vs_time.svg");
    EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
    EXPECT_NE(svg.find("against the scene's answer"), std::string::npos);
    EXPECT_EQ(svg.find("</svg>"), svg.size() - 7);
    const std::string disc = read_text(dir / "discretisation_error_vs_time.svg");
    EXPECT_NE(disc.find("b (not monotone)"), std::string::npos) << "the series without a limit is named";
    // A unitless metric's heading has no empty parentheses.
    StudyReport strain = r;
    for (auto& c : strain.cases) c.metrics["peak_plastic_strain"] = 1.0 + c.cell_size;
    write_study_markdown(dir / "strain.md", strain, analyse_study(strain));
    const std::string strain_md = read_text(dir / "strain.md");
    EXPECT_NE(strain_md.find("## peak_plastic_strain\n"), std::string::npos);
    EXPECT_EQ(strain_md.find("()"), std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST(StudyOutputs, MetricsChosenByNameAreTheOnlyOnesAnalysed) {
    EXPECT_EQ(parse_metric_list("crater_depth, residual_velocity"), (std::vector<std::string>{"crater_depth", "residual_velocity"}));
    for (const auto& [text, fragment] : std::vector<std::pair<std::string, std::string>>{
             {"crater_dept", "no metric 'crater_dept'; the metrics are final_length,"},
             {"final_length,,plastic_work", "an empty name"},
             {"plastic_work,plastic_work", "'plastic_work' is named twice"}}) {
        try {
            parse_metric_list(text);
            ADD_FAILURE() << text << " was accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    }
    StudyReport r = synthetic_report();
    for (auto& c : r.cases) c.metrics["plastic_work"] = 1.0 + c.cell_size;
    EXPECT_EQ(analyse_study(r).metrics, (std::vector<std::string>{"final_length", "plastic_work", "energy_error"}));
    r.chosen_metrics = {"plastic_work"};
    EXPECT_EQ(analyse_study(r).metrics, (std::vector<std::string>{"plastic_work"}));
}

TEST(StudyOutputs, PanelsWithoutAPointAndFiguresWithoutAPanelAreLeftOut) {
    const auto dir = std::filesystem::temp_directory_path() / "gpa_test_study_panels";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    // Series a converges in final_length; the plastic work is not monotone in either series: its
    // panel of the discretisation error would have no point and is left out.
    StudyReport r = synthetic_report();
    r.reference.clear();
    for (auto& c : r.cases) c.metrics["plastic_work"] = c.refinement == 2.0 ? 2.0 : 1.0;
    const auto a = analyse_study(r);
    const auto plots = write_study_plots(dir, r, a);
    ASSERT_EQ(plots.size(), 1u);
    const std::string svg = read_text(dir / "error_vs_time.svg");
    EXPECT_NE(svg.find("final_length"), std::string::npos);
    EXPECT_EQ(svg.find("plastic_work"), std::string::npos);
    EXPECT_EQ(svg.find("no points to draw"), std::string::npos);
    // Two resolutions: no metric has a discretisation error, so no figure at all.
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    StudyReport two = synthetic_report();
    two.reference.clear();
    std::erase_if(two.cases, [](const StudyCase& c) { return c.refinement == 4.0; });
    two.refinements = {1.0, 2.0};
    EXPECT_TRUE(write_study_plots(dir, two, analyse_study(two)).empty());
    EXPECT_FALSE(std::filesystem::exists(dir / "error_vs_time.svg"));
    std::filesystem::remove_all(dir);
}

TEST(SvgPlot, DrawsOnlyPositivePointsWithDecadeTicks) {
    LogLogFigure fig;
    fig.title = "t & <t>";
    fig.legend = {"one", "two", "none"};
    PlotPanel p;
    p.title = "panel";
    p.x_label = "wall time (s)";
    p.y_label = "|relative error|";
    p.series = {{{0.5, 0.02, "tip"}, {5.0, 0.004, ""}}, {{1.0, 0.0, ""}, {2.0, 0.01, ""}}, {{-1.0, 1.0, ""}}};
    fig.panels = {p};
    const std::string svg = loglog_svg(fig);
    EXPECT_NE(svg.find("t &amp; &lt;t&gt;"), std::string::npos);
    std::size_t lines = 0;
    for (auto at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++lines;
    EXPECT_EQ(lines, 2u) << "the third series has no point that a log axis can show";
    EXPECT_NE(svg.find("<title>tip</title>"), std::string::npos);
    // x from 0.1 to 10: plain decade labels; y from 10^-3 to 10^-1: powers of ten.
    for (const char* label : {">0.1<", ">1<", ">10<", ">-3</tspan>", ">-2</tspan>", ">-1</tspan>"}) {
        EXPECT_NE(svg.find(label), std::string::npos) << label;
    }
}

}  // namespace
}  // namespace gpa::io
