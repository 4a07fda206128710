#include "gpa/io/reference.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>

#include <fmt/format.h>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/version.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/study.hpp"
#include "toml_include.hpp"
#include "toml_reading.hpp"

namespace gpa::io {

namespace fs = std::filesystem;

namespace {

constexpr double no_value = std::numeric_limits<double>::quiet_NaN();

// The settled rule's bound: the three finest values within 2 % of the finest.
constexpr double settled_spread = 0.02;

std::string today_utc() {
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    std::tm tm{};
    gmtime_r(&now, &tm);
    char buffer[16];
    std::strftime(buffer, sizeof buffer, "%Y-%m-%d", &tm);
    return buffer;
}

std::string toml_string(const std::string& s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        out += c;
    }
    return out + "\"";
}

std::string toml_number(double v) { return std::isfinite(v) ? fmt::format("{:.10g}", v) : "nan"; }

std::string toml_array(const std::vector<double>& v) {
    std::string s = "[";
    for (std::size_t k = 0; k < v.size(); ++k) s += (k ? ", " : "") + toml_number(v[k]);
    return s + "]";
}

// r(z) of an outline (heights ascending), linear between points; NaN outside it.
double radius_at(const std::vector<std::pair<double, double>>& o, double z) {
    for (std::size_t k = 0; k + 1 < o.size(); ++k) {
        const auto [z0, r0] = o[k];
        const auto [z1, r1] = o[k + 1];
        if (z >= z0 && z <= z1) return z1 > z0 ? r0 + (r1 - r0) * (z - z0) / (z1 - z0) : std::max(r0, r1);
    }
    return no_value;
}

}  // namespace

ElementReference reference_from_study(const StudyReport& report, const StudyAnalysis& analysis, const std::string& series,
                                      std::vector<std::pair<double, double>> outline) {
    std::vector<const StudyCase*> cases;
    for (const auto& c : report.cases) {
        if (c.series == series && c.finished) cases.push_back(&c);
    }
    if (cases.size() < 3) {
        throw InputError(fmt::format("--reference: the series '{}' has {} finished resolutions; a reference needs three",
                                     series, cases.size()));
    }
    std::sort(cases.begin(), cases.end(), [](const StudyCase* a, const StudyCase* b) { return a->cell_size > b->cell_size; });
    ElementReference r;
    r.scene = report.scene_name;
    r.scene_file = report.scene_file;
    for (const auto& v : report.variants) {
        if (series.rfind(v.name, 0) != 0) continue;
        r.variant = v.name;
        for (std::size_t k = 0; k < v.settings.size(); ++k) {
            r.variant += fmt::format("{}{}={}", k ? "," : ":", v.settings[k].first, v.settings[k].second);
        }
    }
    for (const auto* c : cases) r.cell_sizes.push_back(c->cell_size);
    r.date = today_utc();
    r.commit = std::string(source_commit());
    r.outline = std::move(outline);
    for (const auto& key : analysis.metrics) {
        const auto* info = find_study_metric(key);
        if (!info || !info->analysed) continue;
        const auto& x = analysis.extrapolations.at({series, key});
        ReferenceValue v;
        for (const auto* c : cases) {
            const auto it = c->metrics.find(key);
            v.values.push_back(it != c->metrics.end() ? it->second : no_value);
        }
        const std::size_t n = v.values.size();
        const double f1 = v.values[n - 3], f2 = v.values[n - 2], f3 = v.values[n - 1];
        if (!std::isfinite(f1) || !std::isfinite(f2) || !std::isfinite(f3)) continue;  // the metric does not apply
        v.status = std::string(describe(x.status));
        v.order = x.order;
        if ((x.status == ConvergenceStatus::Converging && !x.slow) || x.status == ConvergenceStatus::Unchanged) {
            v.kind = "richardson";
            v.value = x.extrapolated;
            v.uncertainty = std::abs(x.extrapolated - f3);
        } else {
            const double spread = std::max({f1, f2, f3}) - std::min({f1, f2, f3});
            if (spread <= settled_spread * std::abs(f3)) {
                v.kind = "finest";
                v.value = f3;
                v.uncertainty = spread;
                if (x.slow) v.status = "converging slowly";
            } else {
                r.missing[key] = fmt::format("{}{}, and the three finest values spread by {:.3g} % (more than {:g} %)", v.status,
                                             x.slow ? " slowly" : "", 100.0 * spread / std::abs(f3), 100.0 * settled_spread);
                continue;
            }
        }
        r.values[key] = v;
    }
    return r;
}

void write_element_reference(const fs::path& file, const ElementReference& r) {
    std::string s = fmt::format(
        "# Element reference of {}: written by {} ({}).\n"
        "# Per metric: the Richardson estimate of the three finest resolutions when they converge monotonically\n"
        "# with an observed order >= 0.5 (kind \"richardson\", uncertainty |f0 - f3|); otherwise the finest value\n"
        "# when the three finest lie within 2 % of each other (kind \"finest\", uncertainty max - min); otherwise\n"
        "# none ([missing] says why). Values in SI units (m, J, K). docs/validation.md, \"Element references\".\n",
        r.scene, r.written_by, r.date);
    s += fmt::format("scene = {}\nscene_file = {}\nvariant = {}\ncell_sizes_m = {}\npeak_radius_m = {}\ndate = {}\ncommit = {}\n"
                     "written_by = {}\n",
                     toml_string(r.scene), toml_string(r.scene_file), toml_string(r.variant), toml_array(r.cell_sizes),
                     toml_number(r.peak_radius), toml_string(r.date), toml_string(r.commit), toml_string(r.written_by));
    for (const auto& [key, v] : r.values) {
        s += fmt::format("\n[values.{}]\nvalue = {}\nkind = {}\nstatus = {}\norder = {}\nuncertainty = {}\nseries = {}\n", key,
                         toml_number(v.value), toml_string(v.kind), toml_string(v.status), toml_number(v.order),
                         toml_number(v.uncertainty), toml_array(v.values));
    }
    if (!r.missing.empty()) {
        s += "\n[missing]\n";
        for (const auto& [key, why] : r.missing) s += fmt::format("{} = {}\n", key, toml_string(why));
    }
    std::vector<double> z, radius;
    for (const auto& [h, rr] : r.outline) {
        z.push_back(h);
        radius.push_back(rr);
    }
    s += fmt::format("\n# The outline of the finest run: radius against height above the base.\n[outline]\nheight_m = {}\nradius_m = {}\n",
                     toml_array(z), toml_array(radius));
    write_text_file(file, s);
}

ElementReference read_element_reference(const fs::path& file) {
    const auto fail = [&](const std::string& what) -> InputError {
        return InputError(fmt::format("{}: {}", file.string(), what));
    };
    std::error_code ec;
    if (!fs::exists(file, ec)) throw fail("no such element reference file (write one with gpa study --reference)");
    if (fs::is_directory(file, ec)) throw fail("is a folder, not an element reference file (write one with gpa study --reference)");
    const toml::table t = detail::read_guarded_toml(file);  // its errors name the file and line
    if (t.empty()) throw fail("the file is empty (or holds only comments): an element reference holds what gpa study --reference writes");
    const auto text = [&](const toml::table& tab, const char* key, const std::string& where) {
        const auto* n = tab.get(key);
        if (!n || !n->is_string()) throw fail(fmt::format("{}{} must be a string", where, key));
        return n->as_string()->get();
    };
    const auto number = [&](const toml::table& tab, const char* key, const std::string& where) {
        const auto* n = tab.get(key);
        if (!n) throw fail(fmt::format("{}{} is missing", where, key));
        if (const auto* f = n->as_floating_point()) return f->get();
        if (const auto* i = n->as_integer()) return static_cast<double>(i->get());
        throw fail(fmt::format("{}{} must be a number", where, key));
    };
    const auto numbers = [&](const toml::table& tab, const char* key, const std::string& where) {
        const auto* a = tab.get_as<toml::array>(key);
        if (!a) throw fail(fmt::format("{}{} must be an array of numbers", where, key));
        std::vector<double> out;
        for (const auto& e : *a) {
            if (const auto* f = e.as_floating_point()) out.push_back(f->get());
            else if (const auto* i = e.as_integer()) out.push_back(static_cast<double>(i->get()));
            else throw fail(fmt::format("{}{} must be an array of numbers", where, key));
        }
        return out;
    };
    ElementReference r;
    r.scene = text(t, "scene", "");
    r.scene_file = text(t, "scene_file", "");
    r.variant = text(t, "variant", "");
    r.cell_sizes = numbers(t, "cell_sizes_m", "");
    if (t.get("peak_radius_m")) r.peak_radius = number(t, "peak_radius_m", "");
    r.date = text(t, "date", "");
    r.commit = text(t, "commit", "");
    if (t.get("written_by")) r.written_by = text(t, "written_by", "");
    if (const auto* values = t.get_as<toml::table>("values")) {
        for (const auto& [key, node] : *values) {
            const auto* v = node.as_table();
            const std::string where = fmt::format("values.{}.", key.str());
            if (!v) throw fail(fmt::format("values.{} must be a table", key.str()));
            ReferenceValue x;
            x.value = number(*v, "value", where);
            if (!std::isfinite(x.value)) throw fail(fmt::format("{}value must be finite", where));
            x.kind = text(*v, "kind", where);
            if (x.kind != "richardson" && x.kind != "finest") throw fail(fmt::format("{}kind must be \"richardson\" or \"finest\", not \"{}\"", where, x.kind));
            x.status = text(*v, "status", where);
            x.order = number(*v, "order", where);
            x.uncertainty = number(*v, "uncertainty", where);
            x.values = numbers(*v, "series", where);
            r.values[std::string(key.str())] = x;
        }
    }
    if (const auto* missing = t.get_as<toml::table>("missing")) {
        for (const auto& [key, node] : *missing) {
            if (const auto* s = node.as_string()) r.missing[std::string(key.str())] = s->get();
        }
    }
    if (const auto* o = t.get_as<toml::table>("outline")) {
        const auto z = numbers(*o, "height_m", "outline.");
        const auto radius = numbers(*o, "radius_m", "outline.");
        if (z.size() != radius.size()) throw fail("outline.height_m and outline.radius_m must be as long as each other");
        for (std::size_t k = 0; k < z.size(); ++k) r.outline.emplace_back(z[k], radius[k]);
    }
    return r;
}

double outline_distance(const std::vector<std::pair<double, double>>& a, const std::vector<std::pair<double, double>>& b) {
    if (a.size() < 2 || b.size() < 2) return no_value;
    auto sorted = [](std::vector<std::pair<double, double>> o) {
        std::stable_sort(o.begin(), o.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
        return o;
    };
    const auto sa = sorted(a), sb = sorted(b);
    const double lo = std::max(sa.front().first, sb.front().first);
    const double top = std::min(sa.back().first, sb.back().first);
    const double hi = lo + 0.98 * (top - lo);
    if (!(hi > lo)) return no_value;
    constexpr int samples = 200;
    double sum = 0.0;
    int counted = 0;
    for (int k = 0; k < samples; ++k) {
        const double z = lo + (hi - lo) * (k + 0.5) / samples;
        const double ra = radius_at(sa, z), rb = radius_at(sb, z);
        if (!std::isfinite(ra) || !std::isfinite(rb)) continue;
        sum += std::abs(ra - rb);
        ++counted;
    }
    return counted ? sum / counted : no_value;
}

std::map<std::string, double> compare_with_reference(const std::map<std::string, double>& metrics,
                                                     const std::vector<std::pair<double, double>>& outline,
                                                     const ElementReference& reference) {
    std::map<std::string, double> out;
    const auto radius = metrics.find("peak_radius");
    const bool same_peaks = radius != metrics.end() && reference.peak_radius > 0.0 &&
                            std::abs(radius->second - reference.peak_radius) <= 1e-9 * reference.peak_radius;
    for (const auto& [key, v] : reference.values) {
        if (key.rfind("peak_", 0) == 0 && !same_peaks) continue;
        const auto it = metrics.find(key);
        if (it == metrics.end() || !std::isfinite(it->second) || v.value == 0.0) continue;
        out[key] = it->second / v.value;
    }
    const double d = outline_distance(outline, reference.outline);
    if (std::isfinite(d)) out["outline_distance"] = d;
    return out;
}

}  // namespace gpa::io
