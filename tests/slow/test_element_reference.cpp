// GPA against the converged element solution of the same impact (issue 13). Each scene names its
// element reference in `[reference] elements` (scenes/references/, written by `gpa study
// --reference`: the element solver at three resolutions, with the rule of io/reference.hpp); the
// particle run is the finest resolution of the study of record (docs/validation.md: 20 nodes
// across the radius of the 7.62 mm bars, 26.7 across the Armco cylinder), run to the scene's stop
// rule on 2 threads. Long: labelled "slow".

#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include <gtest/gtest.h>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"
#include "gpa/io/study.hpp"

namespace gpa {
namespace {

// The finest refinement of the study of record (scripts/reference_study.sh).
constexpr double finest = 4.0 / 3.0;

struct Result {
    double length = 0.0, footprint = 0.0, plastic_work = 0.0, peak = 0.0, roughness = 0.0;
    std::size_t face_points = 0;
    io::ElementReference reference;
    std::map<std::string, double> experiment;
};

Result run(const std::string& name, NodeDiameter rule = NodeDiameter::Hoop) {
    static std::map<std::pair<std::string, int>, Result> done;
    const auto key = std::make_pair(name, static_cast<int>(rule));
    if (const auto it = done.find(key); it != done.end()) return it->second;
    Scene s = io::load_scene(std::string(GPA_SOURCE_DIR) + "/scenes/" + name + ".toml");
    s.solver.node_diameter = rule;
    Result r;
    r.reference = io::read_element_reference(s.element_reference);
    r.experiment = s.reference;
    Simulation sim(io::refined(s, finest), 2);
    while (!sim.finished()) sim.step();
    sim.measure_bodies();
    const auto& t = sim.totals();
    r.length = t.length;
    r.footprint = t.footprint_diameter;
    r.plastic_work = t.plastic_work;
    r.peak = t.local.plastic_strain.value;
    r.roughness = t.local.face_roughness;
    r.face_points = t.local.face_points;
    std::printf("[ measured ] %s: L %.4f mm, D %.4f mm, PW %.2f J, peak plastic strain %.4f, face roughness %.4f (%zu points)\n",
                name.c_str(), r.length * 1e3, r.footprint * 1e3, r.plastic_work, r.peak, r.roughness, r.face_points);
    done[key] = r;
    return r;
}

double reference(const Result& r, const std::string& key) {
    const auto it = r.reference.values.find(key);
    if (it == r.reference.values.end()) {
        ADD_FAILURE() << "the element reference of " << r.reference.scene << " has no " << key;
        return NAN;
    }
    return it->second.value;
}

void against_elements(const std::string& name) {
    const Result r = run(name);
    const double dl = r.length / reference(r, "final_length") - 1.0;
    const double dd = r.footprint / reference(r, "footprint_diameter") - 1.0;
    std::printf("[ measured ] %s against the elements: L* %.4f (goal 1 %%: %s by %.2f %%), D* %.4f (goal 2 %%: %s by %.2f %%)\n",
                name.c_str(), 1.0 + dl, std::abs(dl) <= 0.01 ? "within" : "outside", 100 * (std::abs(dl) - 0.01), 1.0 + dd,
                std::abs(dd) <= 0.02 ? "within" : "outside", 100 * (std::abs(dd) - 0.02));
    // The bounds (the goal, 1 % and 2 %, is reported above). The element references are
    // converged to 0.1-0.2 % (their uncertainty in the reference file), far inside these.
    EXPECT_LT(std::abs(dl), 0.02) << name << ": final length " << r.length << " m";
    EXPECT_LT(std::abs(dd), 0.03) << name << ": footprint " << r.footprint << " m";
}

// Copper 190 against its element reference, and the copper acceptance in the same run (one
// bar per ctest process): GPA no farther from the measured length and footprint (Johnson and Cook
// 1983) than the element solution of the same model is, plus 1 %. The element reference's own
// distance from the experiment (+7.3 % long, +7.6 % wide) is the model's error; the 1 % is what the
// issue allows the particles to add. Met since the Taylor scenes take the SPH-NSF weight at a = 1.3
// (docs/validation.md, "The weight at the impact face"); with the paper's weight at a = 1 GPA's
// footprint was +10.0 %.
TEST(AgainstElements, Copper190AgainstTheElementsAndNoFartherFromTheExperimentThanTheyArePlusOnePercent) {
    against_elements("taylor-copper-190");
    const Result r = run("taylor-copper-190");
    for (const char* key : {"final_length", "footprint_diameter"}) {
        const double measured = r.experiment.at(key);
        const double gpa = std::string(key) == "final_length" ? r.length : r.footprint;
        const double gpa_error = std::abs(gpa / measured - 1.0);
        const double element_error = std::abs(reference(r, key) / measured - 1.0);
        std::printf("[ measured ] copper 190 %s: GPA %+.2f %%, elements %+.2f %% from the experiment\n", key,
                    100 * (gpa / measured - 1.0), 100 * (reference(r, key) / measured - 1.0));
        EXPECT_LE(gpa_error, element_error + 0.01) << key;
    }
}
TEST(AgainstElements, ArmcoCylinderLengthAndFootprint) { against_elements("armco-cylinder-nodal"); }

// One test for steel 208, so that ctest (a process per test) runs its bar once.
TEST(AgainstElements, Steel208LengthFootprintPeakPlasticStrainAndAFaceWithoutScatter) {
    against_elements("taylor-steel-208");
    const Result r = run("taylor-steel-208");
    const double ref = reference(r, "peak_plastic_strain");
    std::printf("[ measured ] steel 208 peak plastic strain %.4f against the elements' %.4f (%+.1f %%)\n", r.peak, ref,
                100 * (r.peak / ref - 1));
    // The bound: within 10 % of the element reference (both the mean over the scene's
    // peak_radius, docs/measurement.md).
    EXPECT_NEAR(r.peak, ref, 0.10 * ref);
    // Node-to-node scatter along the face: the mean departure of a face node from the mean of its
    // two neighbours. Bound 0.025, 3 % of the face's plastic strain (0.5-0.9): the element face
    // has none at this scale, so what is left is the particles' own noise; Eq. 3's diameters
    // measured 0.022 at 15 and 0.040 at 30 nodes across (docs/validation.md), and must stay above
    // the new rule's at the same resolution for the comparison to mean that the rule removed it.
    EXPECT_GE(r.face_points, 15u);
    EXPECT_LT(r.roughness, 0.025);
    const Result eq3 = run("taylor-steel-208", NodeDiameter::Section);
    EXPECT_LT(r.roughness, eq3.roughness) << "Eq. 3's diameters: " << eq3.roughness;
}

}  // namespace
}  // namespace gpa
