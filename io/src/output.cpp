#include "gpa/io/output.hpp"
#include "gpa/io/reference.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <system_error>

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/measure.hpp"

namespace gpa::io {

namespace fs = std::filesystem;

RunFolder::RunFolder(fs::path folder, bool overwrite, Mode mode) : final_(std::move(folder)), overwrite_(overwrite) {
    if (final_.empty()) throw OutputError("the output folder name is empty");
    if (final_.filename().empty()) final_ = final_.parent_path();  // "out/" -> "out"
    if (mode == Mode::Resume && final_.extension() == ".partial") final_.replace_extension();
    partial_ = final_;
    partial_ += ".partial";
    lock_.emplace(final_);
    std::error_code ec;
    if (mode == Mode::Resume) {
        if (!fs::is_directory(partial_, ec)) {
            // Say what the folder is: a finished run's (it has its summary), empty, or something else.
            std::string what;
            if (fs::exists(final_ / "summary.json", ec)) what = " (the run in it has finished)";
            else if (fs::is_directory(final_, ec) && fs::is_empty(final_, ec)) what = fmt::format(", and '{}' is empty: there is nothing to resume", final_.string());
            else if (fs::is_directory(final_, ec)) what = fmt::format(", and '{}' holds no gpa run: there is nothing to resume", final_.string());
            throw OutputError(fmt::format("there is no stopped run to resume in '{}': '{}' does not exist{}", final_.string(),
                                          partial_.string(), what));
        }
        return;
    }
    if (fs::exists(final_, ec)) {
        if (!fs::is_directory(final_, ec)) {
            throw OutputError(fmt::format("output '{}' exists and is not a folder", final_.string()));
        }
        if (!fs::is_empty(final_, ec) && !overwrite_) {
            throw OutputError(fmt::format("output folder '{}' exists and is not empty; choose another with -o "
                                          "or pass --overwrite to replace it when the run ends",
                                          final_.string()));
        }
    }
    // A stopped run that can still be resumed is work the user may want back: it is discarded
    // only on request, and checked before anything else touches the folder.
    if (!overwrite_ && fs::exists(partial_ / checkpoint_file_name, ec)) {
        throw OutputError(fmt::format("'{}' holds a stopped run that can be resumed (it has a checkpoint); continue it with "
                                      "gpa run --resume {}, or pass --overwrite to discard it and start again",
                                      partial_.string(), final_.string()));
    }
    fs::remove_all(partial_, ec);
    if (ec) throw OutputError(fmt::format("cannot clear '{}': {}", partial_.string(), ec.message()));
    fs::create_directories(partial_, ec);
    if (ec) throw OutputError(fmt::format("cannot create '{}': {}", partial_.string(), ec.message()));
}

void RunFolder::commit() {
    std::error_code ec;
    if (fs::exists(final_, ec)) {
        if (!overwrite_ && !fs::is_empty(final_, ec)) {
            throw OutputError(fmt::format("output folder '{}' appeared during the run; results stay in '{}'",
                                          final_.string(), partial_.string()));
        }
        fs::remove_all(final_, ec);
        if (ec) throw OutputError(fmt::format("cannot replace '{}': {}", final_.string(), ec.message()));
    }
    fs::rename(partial_, final_, ec);
    if (ec) throw OutputError(fmt::format("cannot rename '{}' to '{}': {}", partial_.string(), final_.string(), ec.message()));
}

namespace {

// A unit of an extensive quantity (energy, momentum, force, impulse): per metre of thickness in
// plane strain, where the bodies are slices of unit thickness.
std::string extensive(const HistoryLayout& layout, std::string_view unit) {
    return layout.per_metre ? fmt::format("{}_per_m", unit) : std::string(unit);
}

// Per-body columns, for scenes of more than one body (body_report.hpp defines them).
std::string body_columns(const Totals& t, const HistoryLayout& layout) {
    if (t.bodies.size() < 2) return {};
    const int dim = layout.dim;
    std::string h;
    for (const auto& b : t.bodies) {
        const std::string& n = b.name;
        h += fmt::format(",{0}_kinetic_energy_{1},{0}_internal_energy_{1}", n, extensive(layout, "J"));
        for (int c = 0; c < dim; ++c) h += fmt::format(",{}_momentum_{}_{}", n, axis_letter(c, dim), extensive(layout, "kg_m_s"));
        for (int c = 0; c < dim; ++c) h += fmt::format(",{}_velocity_{}_m_s", n, axis_letter(c, dim));
        h += fmt::format(",{0}_residual_velocity_m_s,{0}_pieces,{0}_failed_nodes", n);
        if (b.target) h += fmt::format(",{0}_crater_depth_m,{0}_crater_diameter_m,{0}_perforated", n);
    }
    return h;
}

std::string body_values(const Totals& t, int dim) {
    if (t.bodies.size() < 2) return {};
    std::string r;
    for (const auto& b : t.bodies) {
        r += fmt::format(",{:.9e},{:.9e}", b.kinetic_energy, b.internal_energy);
        for (int c = 0; c < dim; ++c) r += fmt::format(",{:.9e}", b.momentum[c]);
        for (int c = 0; c < dim; ++c) r += fmt::format(",{:.9e}", b.centre_velocity[c]);
        r += fmt::format(",{:.9e},{},{}", b.residual_speed_along_axis, b.pieces, b.failed_nodes);
        if (b.target) r += fmt::format(",{:.9e},{:.9e},{}", b.crater_depth, b.crater_diameter, b.perforated ? 1 : 0);
    }
    return r;
}

std::string history_header(const Totals& first, const HistoryLayout& layout) {
    const int dim = layout.dim;
    const std::string J = extensive(layout, "J");
    std::string header = fmt::format("time_s,dt_s,step,kinetic_energy_{0},internal_energy_{0},plastic_work_{0},viscous_work_{0},"
                                     "boundary_work_{0},total_energy_error_percent,hourglass_work_{0},hourglass_energy_{0}",
                                     J);
    for (int c = 0; c < dim; ++c) header += fmt::format(",momentum_{}_{}", axis_letter(c, dim), extensive(layout, "kg_m_s"));
    if (layout.specimen) header += ",length_m,footprint_diameter_m,base_height_m";
    // Local peaks (measure.hpp): the neighbourhood peak, where it is, the largest single value.
    for (const char* field : {"plastic_strain", "temperature_K"}) {
        const std::string name = field;
        const std::string stem = name.substr(0, name.find("_K"));
        const std::string unit = name.size() > stem.size() ? "_K" : "";
        header += fmt::format(",peak_{}{}", stem, unit);
        for (int c = 0; c < dim; ++c) header += fmt::format(",peak_{}_{}_m", stem, axis_letter(c, dim));
        header += fmt::format(",max_{}{}", stem, unit);
    }
    if (layout.specimen) header += ",face_plastic_strain_roughness";
    for (const auto& p : first.planes) {
        const std::string name = p.name.empty() ? "plane" : p.name;
        header += fmt::format(",{0}_reaction_{1},{0}_impulse_{2}", name, extensive(layout, "N"), extensive(layout, "N_s"));
        if (p.friction) header += fmt::format(",{}_friction_work_{}", name, J);
    }
    for (const auto& r : first.regions) {
        const std::string name = r.name.empty() ? "region" : r.name;
        for (const char* quantity : {"reaction", "impulse", "displacement"}) {
            const std::string unit = quantity[0] == 'r' ? extensive(layout, "N") : quantity[0] == 'i' ? extensive(layout, "N_s") : "m";
            for (int c = 0; c < dim; ++c) {
                if (r.held[c]) header += fmt::format(",{}_{}_{}_{}", name, quantity, axis_letter(c, dim), unit);
            }
        }
        header += fmt::format(",{}_work_{}", name, J);
    }
    header += ",real_nodes,ghost_nodes,variable_nodes,failed_nodes,neighbour_pairs,element_nodes,elements";
    header += body_columns(first, layout);
    return header + "\n";
}

}  // namespace

std::uint64_t history_digest(std::string_view bytes, std::uint64_t digest) {
    for (const char c : bytes) {
        digest ^= static_cast<unsigned char>(c);
        digest *= 1099511628211ull;
    }
    return digest;
}

RowFile::RowFile(const fs::path& file, const std::string& header) : path_(file) {
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw OutputError(fmt::format("cannot write '{}': {}", file.string(), std::strerror(errno)));
    append(header);
}

std::string RowFile::kept_for_resume(const fs::path& file, const std::string& header, std::size_t step_column,
                                     std::size_t last_step, std::size_t every, Mark at, const std::string& checkpoint) {
    every = std::max<std::size_t>(every, 1);
    std::string old;
    {
        std::ifstream in(file, std::ios::binary);
        if (!in) throw OutputError(fmt::format("cannot read '{}' of the stopped run", file.string()));
        old.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        if (in.bad()) throw OutputError(fmt::format("cannot read '{}' of the stopped run", file.string()));
    }
    const std::string cannot = "the stopped run cannot be continued from it (start it again with --overwrite)";
    if (at.bytes > 0) {
        // What was written after the checkpoint goes; what was written before must be as it was.
        if (static_cast<long long>(old.size()) < at.bytes) {
            throw OutputError(fmt::format("'{}' has been cut short: it holds {} bytes, {} when '{}' was written at step {}; {}",
                                          file.string(), old.size(), at.bytes, checkpoint, last_step, cannot));
        }
        old.resize(static_cast<std::size_t>(at.bytes));
        if (history_digest(old) != at.digest) {
            throw OutputError(fmt::format("'{}' is not the file '{}' was written with (its first {} bytes differ): the checkpoint "
                                          "belongs to another run, or the file was changed; {}",
                                          file.string(), checkpoint, at.bytes, cannot));
        }
    }
    if (old.compare(0, header.size(), header) != 0) {
        throw OutputError(fmt::format("'{}' does not start with the header this run writes (it was written by another version "
                                      "of gpa, or changed); {}",
                                      file.string(), cannot));
    }
    // The rows of the schedule (steps 0, every, 2 every, ...) up to the checkpoint, each once and in
    // order; rows off the schedule (the last one of an interruption) and beyond it are left out.
    std::string text = header;
    std::size_t next = 0;  // the step of the next row expected
    std::size_t begin = header.size();
    while (begin < old.size()) {
        const std::size_t end = old.find('\n', begin);
        if (end == std::string::npos) break;  // a last line without its end: not a whole row
        const std::string_view line(old.data() + begin, end - begin);
        begin = end + 1;
        std::size_t field = 0;  // where column `step_column` starts
        for (std::size_t c = 0; c < step_column && field != std::string::npos; ++c) {
            field = line.find(',', field);
            if (field != std::string::npos) ++field;
        }
        if (field == std::string::npos) continue;
        const std::string step_text(line.substr(field, line.find(',', field) - field));
        if (step_text.empty() || step_text.find_first_not_of("0123456789") != std::string::npos) continue;
        const std::size_t step = static_cast<std::size_t>(std::stoull(step_text));
        if (step > last_step || step % every != 0) continue;
        if (step != next) {
            throw OutputError(fmt::format("'{}' has a row of step {} where the row of step {} belongs (rows every {} step{} up to "
                                          "step {} of '{}'): {}",
                                          file.string(), step, next, every, every == 1 ? "" : "s", last_step, checkpoint, cannot));
        }
        text.append(line);
        text += '\n';
        next += every;
    }
    if (next <= last_step) {
        throw OutputError(fmt::format("'{}' has been cut short: it has no row of step {}, though '{}' was written at step {}; {}",
                                      file.string(), next, checkpoint, last_step, cannot));
    }
    return text;
}

RowFile::RowFile(const fs::path& file, const std::string& text, bool) : path_(file) {
    write_text_file(file, text);
    fd_ = ::open(file.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
    if (fd_ < 0) throw OutputError(fmt::format("cannot write '{}': {}", file.string(), std::strerror(errno)));
    size_ = static_cast<long long>(text.size());
    digest_ = history_digest(text);
}

RowFile::~RowFile() {
    if (fd_ >= 0) ::close(fd_);
}

void RowFile::append(const std::string& text) {
    std::size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            const int error = n < 0 ? errno : ENOSPC;
            // Cut back to the whole lines before this one.
            const bool cut = ::ftruncate(fd_, static_cast<off_t>(size_)) == 0;
            throw OutputError(fmt::format("writing '{}' failed: {}{}", path_.string(), std::strerror(error),
                                          cut ? "" : " (and the incomplete row could not be removed)"));
        }
        done += static_cast<std::size_t>(n);
    }
    size_ += static_cast<long long>(text.size());
    digest_ = history_digest(text, digest_);
}

namespace {

std::vector<bool> plane_friction(const Totals& first) {
    std::vector<bool> out;
    for (const auto& p : first.planes) out.push_back(p.friction);
    return out;
}

std::vector<std::array<bool, 3>> held_components(const Totals& first) {
    std::vector<std::array<bool, 3>> out;
    for (const auto& r : first.regions) out.push_back(r.held);
    return out;
}

}  // namespace

HistoryLayout HistoryLayout::of(const Scene& scene) {
    HistoryLayout layout;
    layout.dim = dimension_of(scene.geometry);
    layout.per_metre = scene.geometry == GeometryKind::PlaneStrain;
    layout.specimen = std::any_of(scene.planes.begin(), scene.planes.end(), [](const PlaneSpec& p) { return p.kind == PlaneKind::Rigid; });
    return layout;
}

HistoryWriter::HistoryWriter(const fs::path& file, const Totals& first, const HistoryLayout& layout)
    : file_(file, history_header(first, layout)), layout_(layout), planes_(first.planes.size()), friction_(plane_friction(first)),
      regions_(held_components(first)) {}

std::string HistoryWriter::kept_for_resume(const fs::path& file, const Totals& first, const HistoryLayout& layout,
                                           std::size_t last_step, std::size_t every, Mark at, const std::string& checkpoint) {
    return RowFile::kept_for_resume(file, history_header(first, layout), 2, last_step, every, at, checkpoint);
}

HistoryWriter::HistoryWriter(const fs::path& file, const Totals& first, const HistoryLayout& layout, const std::string& text)
    : file_(file, text, true), layout_(layout), planes_(first.planes.size()), friction_(plane_friction(first)),
      regions_(held_components(first)) {}

void HistoryWriter::write(const Totals& t) {
    std::string row = fmt::format("{:.9e},{:.6e},{},{:.9e},{:.9e},{:.9e},{:.9e},{:.9e},{:.6e},{:.9e},{:.9e}", t.time, t.time_step,
                                  t.step, t.kinetic_energy, t.internal_energy, t.plastic_work, t.viscous_work,
                                  t.boundary_work, 100.0 * t.energy_error, t.hourglass_work, t.hourglass_energy);
    for (int c = 0; c < layout_.dim; ++c) row += fmt::format(",{:.9e}", t.momentum[c]);
    if (layout_.specimen) row += fmt::format(",{:.9e},{:.9e},{:.9e}", t.length, t.footprint_diameter, t.base_height);
    for (const auto* peak : {&t.local.plastic_strain, &t.local.temperature}) {
        row += fmt::format(",{:.9e}", peak->value);
        for (int c = 0; c < layout_.dim; ++c) row += fmt::format(",{:.9e}", peak->position[c]);
        row += fmt::format(",{:.9e}", peak->raw);
    }
    if (layout_.specimen) row += fmt::format(",{:.9e}", t.local.face_roughness);
    for (std::size_t p = 0; p < planes_; ++p) {
        const PlaneReport r = p < t.planes.size() ? t.planes[p] : PlaneReport{};
        row += fmt::format(",{:.9e},{:.9e}", r.reaction, r.impulse);
        if (p < friction_.size() && friction_[p]) row += fmt::format(",{:.9e}", r.friction_work);
    }
    for (std::size_t k = 0; k < regions_.size(); ++k) {
        const RegionReport r = k < t.regions.size() ? t.regions[k] : RegionReport{};
        for (const auto& values : {r.reaction, r.impulse, r.displacement}) {
            for (int c = 0; c < layout_.dim; ++c) {
                if (regions_[k][c]) row += fmt::format(",{:.9e}", values[c]);
            }
        }
        row += fmt::format(",{:.9e}", r.work);
    }
    row += fmt::format(",{},{},{},{},{},{},{}", t.real_nodes, t.ghost_nodes, t.variable_nodes, t.failed_nodes, t.pairs,
                       t.element_nodes, t.elements);
    row += body_values(t, layout_.dim);
    file_.append(row + "\n");
}

namespace {

std::string gauge_header(const Gauge& g) {
    std::string h = "time_s,step";
    for (const auto& c : g.columns()) h += "," + c;
    return h + "\n";
}

std::vector<Gauge> place_gauges(const Simulation& sim) {
    std::vector<Gauge> out;
    for (const auto& spec : sim.scene().gauges) out.emplace_back(spec, sim.scene(), sim.nodes(), sim.real_count());
    return out;
}

}  // namespace

GaugeWriter::GaugeWriter(const fs::path& folder, const Simulation& sim) : gauges_(place_gauges(sim)) {
    for (const auto& g : gauges_) files_.push_back(std::make_unique<RowFile>(folder / file_name(g.spec().name), gauge_header(g)));
}

GaugeWriter::GaugeWriter(const fs::path& folder, const Simulation& sim, std::size_t last_step, std::size_t every,
                         const std::vector<Mark>& at, const std::string& checkpoint)
    : gauges_(place_gauges(sim)) {
    if (at.size() != gauges_.size()) {
        throw OutputError(fmt::format("'{}' records {} gauge file{} and the scene has {} gauge{}: the stopped run cannot be continued "
                                      "from it (start it again with --overwrite)",
                                      checkpoint, at.size(), at.size() == 1 ? "" : "s", gauges_.size(), gauges_.size() == 1 ? "" : "s"));
    }
    std::vector<std::string> kept;
    for (std::size_t k = 0; k < gauges_.size(); ++k) {
        kept.push_back(RowFile::kept_for_resume(folder / file_name(gauges_[k].spec().name), gauge_header(gauges_[k]), 1, last_step,
                                                every, at[k], checkpoint));
    }
    for (std::size_t k = 0; k < gauges_.size(); ++k) {
        files_.push_back(std::make_unique<RowFile>(folder / file_name(gauges_[k].spec().name), kept[k], true));
    }
}

void GaugeWriter::write(const Simulation& sim) {
    for (std::size_t k = 0; k < gauges_.size(); ++k) {
        std::string row = fmt::format("{:.9e},{}", sim.time(), sim.steps());
        for (const double v : gauges_[k].read(sim.nodes(), sim.real_count())) row += fmt::format(",{:.9e}", v);
        files_[k]->append(row + "\n");
    }
}

std::vector<GaugeWriter::Mark> GaugeWriter::marks() const {
    std::vector<Mark> out;
    for (const auto& f : files_) out.push_back(f->mark());
    return out;
}

SnapshotSeries::SnapshotSeries(fs::path folder, std::string stem, SnapshotFormat format)
    : folder_(std::move(folder)), stem_(std::move(stem)), format_(std::move(format)) {}

std::string SnapshotSeries::write(const NodeStore& nodes, std::size_t count, double time) {
    const std::string name = fmt::format("{}_{:05d}.vtp", stem_, scheduled_);
    write_vtp(folder_ / name, nodes, count, format_);
    entries_.push_back({time, name});
    ++scheduled_;
    write_pvd(folder_ / (stem_ + ".pvd"), entries_);
    return name;
}

Snapshot take_snapshot(const Simulation& sim) {
    Snapshot s;
    s.time = sim.time();
    s.particles = sim.nodes();
    s.particles.resize(sim.real_count());
    if (const ElementPart* e = sim.elements()) s.elements = e->mesh();
    return s;
}

std::vector<std::string> SnapshotSeries::write_parts(const Snapshot& snapshot, const std::string& suffix, const std::string& mark) {
    std::vector<std::string> names;
    int part = 0;
    const auto add = [&](const std::string& name) {
        PvdEntry e{snapshot.time, name};
        e.name = mark;
        e.part = part++;
        entries_.push_back(e);
        names.push_back(name);
    };
    if (snapshot.particles.size() > 0 || !snapshot.elements) {
        const std::string name = fmt::format("{}_{}.vtp", stem_, suffix);
        write_vtp(folder_ / name, snapshot.particles, snapshot.particles.size(), format_);
        add(name);
    }
    if (snapshot.elements) {
        const std::string name = fmt::format("elements_{}.vtu", suffix);
        write_vtu(folder_ / name, *snapshot.elements, format_);
        add(name);
    }
    write_pvd(folder_ / (stem_ + ".pvd"), entries_);
    return names;
}

std::vector<std::string> SnapshotSeries::write(const Snapshot& snapshot) {
    auto names = write_parts(snapshot, fmt::format("{:05d}", scheduled_), "");
    ++scheduled_;
    return names;
}

std::vector<std::string> SnapshotSeries::write_marked(const Snapshot& snapshot, const std::string& label, const std::string& mark) {
    return write_parts(snapshot, label, mark);
}

void SnapshotSeries::restore(std::vector<PvdEntry> entries, std::size_t scheduled) {
    entries_ = std::move(entries);
    scheduled_ = scheduled;
    write_pvd(folder_ / (stem_ + ".pvd"), entries_);
}

namespace {

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (c < 0x20) {
                    out += fmt::format("\\u{:04x}", c);
                } else {
                    out += static_cast<char>(c);
                }
        }
    }
    return out + "\"";
}

std::string json_number(double v) { return std::isfinite(v) ? fmt::format("{:.10g}", v) : "null"; }

}  // namespace

std::map<std::string, double> run_metrics(const Simulation& sim) {
    const auto& t = sim.totals();
    // A half or quarter model's plastic work is that of its share of the body; the metric is the
    // whole body's, as its length and footprint are (measure.hpp). Bodies cut into different
    // shares have no whole-body figure: the metric is left out.
    const Scene& scene = sim.scene();
    int copies = scene.bodies.empty() ? 1 : symmetry_copies(scene, 0);
    for (std::size_t b = 1; b < scene.bodies.size(); ++b) {
        if (symmetry_copies(scene, b) != copies) copies = 0;
    }
    std::map<std::string, double> m;
    if (copies > 0) m["plastic_work"] = copies * t.plastic_work;
    // Length and footprint are measured above the first rigid plane (measure.hpp): a scene without
    // one has no such metrics (its totals read 0, which no reference should be divided into).
    if (!t.planes.empty()) {
        m["final_length"] = t.length;
        m["footprint_diameter"] = t.footprint_diameter;
    }
    if (t.local.measured && t.local.plastic_strain.has_peak()) {
        m["peak_plastic_strain"] = t.local.plastic_strain.value;
        m["peak_temperature"] = t.local.temperature.value;
        m["peak_radius"] = t.local.radius;
    }
    return m;
}

std::string element_reference_json(const Simulation& sim) {
    const Scene& scene = sim.scene();
    if (scene.element_reference.empty()) return {};
    ElementReference ref;
    try {
        ref = read_element_reference(scene.element_reference);
    } catch (const InputError& e) {
        return fmt::format("{{\"file\": {}, \"error\": {}}}", json_string(scene.element_reference), json_string(e.what()));
    }
    const auto metrics = run_metrics(sim);
    const auto ratios = compare_with_reference(metrics, final_outline(sim), ref);
    std::string values;
    for (const auto& [key, v] : ref.values) {
        const auto m = metrics.find(key);
        const auto r = ratios.find(key);
        values += fmt::format("{}{}: {{\"reference\": {}, \"kind\": {}, \"uncertainty\": {}, \"computed\": {}, \"ratio\": {}}}",
                              values.empty() ? "" : ", ", json_string(key), json_number(v.value), json_string(v.kind),
                              json_number(v.uncertainty), json_number(m != metrics.end() ? m->second : NAN),
                              json_number(r != ratios.end() ? r->second : NAN));
    }
    const auto d = ratios.find("outline_distance");
    return fmt::format("{{\"file\": {}, \"commit\": {}, \"date\": {}, \"values\": {{{}}}, \"outline_distance_m\": {}}}",
                       json_string(scene.element_reference), json_string(ref.commit), json_string(ref.date), values,
                       json_number(d != ratios.end() ? d->second : NAN));
}

std::vector<ReferenceComparison> compare_with_reference(const Simulation& sim) {
    std::vector<ReferenceComparison> out;
    const std::map<std::string, double> computed = run_metrics(sim);
    for (const auto& [key, value] : sim.scene().reference) {
        const auto it = computed.find(key);
        if (it == computed.end()) continue;
        out.push_back({key, value, it->second, value != 0.0 ? (it->second - value) / value : 0.0});
    }
    return out;
}

void write_summary(const fs::path& file, const Simulation& sim, const RunSummary& run) {
    const auto& t = sim.totals();
    const auto& scene = sim.scene();
    std::string j = "{\n";
    const auto field = [&](const std::string& key, const std::string& value, bool last = false) {
        j += fmt::format("  {}: {}{}\n", json_string(key), value, last ? "" : ",");
    };
    field("scene", json_string(scene.name));
    field("scene_file", json_string(run.scene_file));
    field("geometry", json_string(std::string(name_of(scene.geometry))));
    field("status", json_string(run.status));
    field("message", json_string(run.message));
    if (!run.failure_json.empty()) field("failure", run.failure_json);
    field("time_s", json_number(t.time));
    field("steps", std::to_string(t.step));
    field("real_nodes", std::to_string(t.real_nodes));
    field("ghost_nodes", std::to_string(t.ghost_nodes));
    field("variable_nodes", std::to_string(t.variable_nodes));
    field("failed_nodes", std::to_string(t.failed_nodes));
    field("element_nodes", std::to_string(t.element_nodes));
    field("elements", std::to_string(t.elements));
    field("threads", std::to_string(sim.threads()));
    // In 3D the footprint is the mean width over directions (measure.hpp), with its narrowest and widest.
    const std::string spread = sim.nodes().dim() == 3 ? fmt::format(", \"footprint_narrowest_m\": {}, \"footprint_widest_m\": {}",
                                                                     json_number(t.footprint_narrowest), json_number(t.footprint_widest))
                                                         : std::string();
    field("final", fmt::format("{{\"length_m\": {}, \"footprint_diameter_m\": {}{}, \"base_height_m\": {}, \"plastic_work_J\": {}}}",
                               json_number(t.length), json_number(t.footprint_diameter), spread, json_number(t.base_height),
                               json_number(t.plastic_work)));
    {
        // Local peaks (measure.hpp): the mean over a neighbourhood of `radius_m`, where it is
        // centred, and the largest value at one material point.
        const auto peak = [&](const measure::LocalPeak& p) {
            std::string at = "[";
            for (int c = 0; c < dimension_of(scene.geometry); ++c) at += (c ? ", " : "") + json_number(p.position[c]);
            std::string raw_at = "[";
            for (int c = 0; c < dimension_of(scene.geometry); ++c) raw_at += (c ? ", " : "") + json_number(p.raw_position[c]);
            return fmt::format("{{\"peak\": {}, \"at_m\": {}], \"max\": {}, \"max_at_m\": {}]}}", json_number(p.value), at,
                               json_number(p.raw), raw_at);
        };
        field("local", fmt::format("{{\"radius_m\": {}, \"plastic_strain\": {}, \"temperature_K\": {}, "
                                   "\"points\": {}, \"points_alone\": {}, "
                                   "\"face_plastic_strain_roughness\": {}, \"face_points\": {}}}",
                                   json_number(t.local.radius), peak(t.local.plastic_strain), peak(t.local.temperature),
                                   t.local.plastic_strain.points, t.local.plastic_strain.alone,
                                   json_number(t.local.face_roughness), t.local.face_points));
    }
    field("energy", fmt::format("{{\"initial_J\": {}, \"kinetic_J\": {}, \"internal_J\": {}, \"plastic_work_J\": {}, "
                                "\"viscous_work_J\": {}, \"hourglass_work_J\": {}, \"hourglass_energy_J\": {}, \"boundary_work_J\": {}, \"given_J\": {}, \"relative_error\": {}}}",
                                json_number(t.initial_energy), json_number(t.kinetic_energy), json_number(t.internal_energy),
                                json_number(t.plastic_work), json_number(t.viscous_work), json_number(t.hourglass_work), json_number(t.hourglass_energy),
                                json_number(t.boundary_work), json_number(t.energy_given),
                                json_number(t.energy_error)));
    std::string planes = "[";
    for (std::size_t p = 0; p < t.planes.size(); ++p) {
        const std::string friction =
            t.planes[p].friction ? fmt::format(", \"friction_work_J\": {}", json_number(t.planes[p].friction_work)) : std::string();
        planes += fmt::format("{}{{\"name\": {}, \"reaction_N\": {}, \"impulse_N_s\": {}{}}}", p ? ", " : "",
                              json_string(t.planes[p].name), json_number(t.planes[p].reaction), json_number(t.planes[p].impulse),
                              friction);
    }
    field("planes", planes + "]");
    std::string regions = "[";
    const int dim = dimension_of(scene.geometry);
    for (std::size_t k = 0; k < t.regions.size(); ++k) {
        const auto& r = t.regions[k];
        const auto components = [&](const std::array<double, 3>& v) {
            std::string out = "{";
            for (int c = 0; c < dim; ++c) {
                if (r.held[c]) out += fmt::format("{}\"{}\": {}", out.size() > 1 ? ", " : "", axis_letter(c, dim), json_number(v[c]));
            }
            return out + "}";
        };
        regions += fmt::format("{}{{\"name\": {}, \"nodes\": {}, \"velocity_m_s\": {}, \"displacement_m\": {}, \"reaction_N\": {}, "
                               "\"impulse_N_s\": {}, \"work_J\": {}}}",
                               k ? ", " : "", json_string(r.name), r.nodes, components(r.velocity), components(r.displacement),
                               components(r.reaction), components(r.impulse), json_number(r.work));
    }
    field("prescribed_velocities", regions + "]");
    std::string bodies = "[";
    for (std::size_t k = 0; k < t.bodies.size(); ++k) {
        const auto& b = t.bodies[k];
        const auto vec = [&](const std::array<double, 3>& v) {
            std::string s = "[";
            for (int c = 0; c < dim; ++c) s += fmt::format("{}{}", c ? ", " : "", json_number(v[c]));
            return s + "]";
        };
        bodies += fmt::format(
            "{}{{\"name\": {}, \"nodes\": {}, \"failed_nodes\": {}, \"mass_kg\": {}, \"kinetic_energy_J\": {}, "
            "\"internal_energy_J\": {}, \"momentum_kg_m_s\": {}, \"centre_velocity_m_s\": {}",
            k ? ",\n    " : "", json_string(b.name), b.nodes, b.failed_nodes, json_number(b.mass), json_number(b.kinetic_energy),
            json_number(b.internal_energy), vec(b.momentum), vec(b.centre_velocity));
        // A half or quarter model (symmetry planes cut or bound the body): its figures above are
        // those of the model, one of `symmetry_copies` shares of the whole body.
        if (k < scene.bodies.size()) bodies += fmt::format(", \"symmetry_copies\": {}", symmetry_copies(scene, k));
        if (b.measured) {
            bodies += fmt::format(", \"pieces\": {}, \"main_piece_mass_kg\": {}, \"residual_velocity_m_s\": {}, "
                                  "\"residual_speed_along_impact_m_s\": {}",
                                  b.pieces, json_number(b.main_piece_mass), vec(b.residual_velocity),
                                  json_number(b.residual_speed_along_axis));
            if (b.target) {
                bodies += fmt::format(", \"crater_depth_m\": {}, \"crater_diameter_m\": {}, \"perforated\": {}",
                                      json_number(b.crater_depth), json_number(b.crater_diameter), b.perforated ? "true" : "false");
            }
        }
        bodies += "}";
    }
    field("bodies", bodies + "]");
    std::string refs = "[";
    const auto comparisons = compare_with_reference(sim);
    for (std::size_t k = 0; k < comparisons.size(); ++k) {
        const auto& c = comparisons[k];
        refs += fmt::format("{}{{\"key\": {}, \"reference\": {}, \"computed\": {}, \"relative_error\": {}}}", k ? ", " : "",
                            json_string(c.key), json_number(c.reference), json_number(c.computed), json_number(c.relative_error));
    }
    field("reference", refs + "]");
    field("reference_source", json_string(scene.reference_source));
    // The element reference of the scene ([reference] elements; io/reference.hpp): the paper's
    // L*, D*, PW* and the peaks as ratios, the outline distance.
    if (const std::string e = element_reference_json(sim); !e.empty()) field("element_reference", e);
    std::string phases = "{";
    double stepping = 0.0;
    const auto times = sim.phase_times();
    for (std::size_t k = 0; k < times.size(); ++k) {
        phases += fmt::format("{}{}: {}", k ? ", " : "", json_string(times[k].name), json_number(times[k].seconds));
        stepping += times[k].seconds;
    }
    field("phase_seconds", phases + "}");
    field("step_seconds", json_number(stepping));
    field("output_seconds", json_number(run.output_seconds));
    field("wall_seconds", json_number(run.wall_seconds));
    field("node_steps_per_second", json_number(stepping > 0.0 ? sim.node_steps() / stepping : 0.0));
    field("element_steps_per_second", json_number(stepping > 0.0 ? sim.element_steps() / stepping : 0.0));
    field("neighbour_searches", std::to_string(sim.totals().neighbour_searches));
    field("row_searches", std::to_string(sim.totals().row_searches));
    field("rows_searched", std::to_string(sim.totals().rows_searched));
    field("snapshots", std::to_string(run.snapshots), true);
    j += "}\n";
    // In plane strain the bodies are slices of unit thickness: the extensive quantities (masses,
    // energies, momenta, forces, impulses, works) are per metre of it, and their keys say so, as
    // history.csv's columns do.
    if (scene.geometry == GeometryKind::PlaneStrain) {
        for (const char* key : {"plastic_work_J", "initial_J", "kinetic_J", "internal_J", "viscous_work_J", "hourglass_work_J",
                                "hourglass_energy_J", "boundary_work_J", "given_J", "reaction_N", "impulse_N_s", "friction_work_J",
                                "work_J", "mass_kg", "kinetic_energy_J", "internal_energy_J", "momentum_kg_m_s", "main_piece_mass_kg"}) {
            const std::string from = fmt::format("\"{}\":", key), to = fmt::format("\"{}_per_m\":", key);
            for (std::size_t at = j.find(from); at != std::string::npos; at = j.find(from, at + to.size())) j.replace(at, from.size(), to);
        }
    }
    write_text_file(file, j);
}

namespace {

// The outline of element bodies (measure.hpp, element rule: the nodes lie on the boundary): at
// the height of every boundary node, the largest radius of the boundary edges that span that
// height, interpolated along each edge.
std::vector<std::pair<double, double>> element_outline(const ElementMesh& m, const PlaneSpec& plane, int across_axis,
                                                       double centre, bool axisymmetric) {
    const auto height = [&](NodeIndex i) { return plane.side * (m.nodes.position[plane.axis][i] - plane.position); };
    const auto radius = [&](NodeIndex i) {
        const double x = m.nodes.position[across_axis][i] - centre;
        return measure::element_outline_radius(axisymmetric ? x : std::abs(x));
    };
    std::vector<double> heights;
    for (const auto& e : m.boundary_edges) heights.push_back(height(e[0]));
    std::sort(heights.begin(), heights.end());
    heights.erase(std::unique(heights.begin(), heights.end()), heights.end());
    std::vector<std::pair<double, double>> out;
    for (double h : heights) {
        double r = -1.0;
        for (const auto& e : m.boundary_edges) {
            const double h0 = height(e[0]), h1 = height(e[1]);
            if (h < std::min(h0, h1) || h > std::max(h0, h1)) continue;
            const double r0 = radius(e[0]), r1 = radius(e[1]);
            r = std::max(r, h0 == h1 ? std::max(r0, r1) : r0 + (r1 - r0) * (h - h0) / (h1 - h0));
        }
        if (r >= 0.0) out.emplace_back(h, r);
    }
    return out;
}

}  // namespace

std::vector<std::pair<double, double>> final_outline(const Simulation& sim) {
    const Scene& scene = sim.scene();
    const auto plane = std::find_if(scene.planes.begin(), scene.planes.end(),
                                    [](const PlaneSpec& p) { return p.kind == PlaneKind::Rigid; });
    std::vector<std::pair<double, double>> out;
    if (plane == scene.planes.end()) return out;
    const NodeStore& n = sim.nodes();
    const std::size_t count = sim.real_count();
    const ElementPart* elements = sim.elements();
    if (count == 0 && !elements) return out;
    const int dim = n.dim();
    // Heights from the body's base (measure.hpp): the plane while it stands on it, else its underside.
    const double base = sim.totals().base_height;
    // The horizontal axes: those other than the plane's normal (all of them for an oblique plane,
    // whose radii are distances from a line along its normal).
    std::vector<int> across;
    for (int c = 0; c < dim; ++c) {
        if (c != plane->axis) across.push_back(c);
    }
    const std::array<double, 3> normal = plane_normal(*plane);
    // A node's height above the plane, n . x - position towards the bodies (the coordinate itself for
    // an axis-aligned plane, so that its heights are what they always were, bit for bit).
    const auto height_above = [&](std::size_t i) {
        if (plane->axis >= 0) return plane->side * (n.position[plane->axis][i] - plane->position);
        double along = 0.0;
        for (int c = 0; c < dim; ++c) along += normal[static_cast<std::size_t>(c)] * n.position[c][i];
        return plane->side * (along - plane->position);
    };
    // Radii from the axis of an axisymmetric scene, otherwise from the vertical through the nodes'
    // centroid.
    const bool axisymmetric = scene.geometry == GeometryKind::Axisymmetric && plane->axis == 1;
    std::array<double, 3> centre{0, 0, 0};
    if (elements) {
        // Element bodies are 2D, their planes axis-aligned (validate_scene): one axis across the plane.
        if (plane->axis < 0) return out;
        const ElementMesh& m = elements->mesh();
        if (!axisymmetric) {
            for (std::size_t i = 0; i < m.nodes.size(); ++i) centre[across[0]] += m.nodes.position[across[0]][i] / double(m.nodes.size());
        }
        double top = 0.0;
        for (auto [h, r] : element_outline(m, *plane, across[0], centre[across[0]], axisymmetric)) {
            out.emplace_back(h - base, r);
            top = std::max(top, h - base);
        }
        out.emplace_back(top, 0.0);
        return out;
    }
    if (!axisymmetric) {
        for (std::size_t i = 0; i < count; ++i) {
            for (int c : across) centre[c] += n.position[c][i] / double(count);
        }
        // A half or quarter model: the whole body's centroid lies on the symmetry planes it reaches,
        // the centroid of the share moved onto each: for an axis-aligned plane its coordinate set, for
        // an oblique one projected along its normal. (The planes that cut one body lie on faces of its
        // lattice cells, so they are perpendicular to one another and one projection each is exact.)
        for (std::size_t k = 0; k < scene.planes.size(); ++k) {
            for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
                const PlaneSpec& mirror = scene.planes[k];
                if (mirror.axis == plane->axis && mirror.axis >= 0) continue;  // along the normal: no radius changes
                if (!reaches_symmetry_plane(scene, b, k)) continue;
                if (mirror.axis >= 0) {
                    centre[static_cast<std::size_t>(mirror.axis)] = mirror.position;
                } else {
                    const std::array<double, 3> m = plane_normal(mirror);
                    double off = -mirror.position;
                    for (int c = 0; c < dim; ++c) off += m[static_cast<std::size_t>(c)] * centre[static_cast<std::size_t>(c)];
                    for (int c = 0; c < dim; ++c) centre[static_cast<std::size_t>(c)] -= off * m[static_cast<std::size_t>(c)];
                }
            }
        }
    }
    double mean_d = 0.0;
    measure::Extent extent;
    for (std::size_t i = 0; i < count; ++i) {
        const double cell = measure::particle_cell_size(n.size_weight[i], dim);
        mean_d += cell / double(count);
        measure::add_particle(extent, height_above(i) - base, 0.0, cell, false);
    }
    const double top = std::max(extent.length(), 0.0);
    const double bin = mean_d;  // one row of nodes: narrower bins hold only inner nodes every other time
    // Only the bins that hold nodes, at most one per node, however far apart the bodies are.
    std::map<double, double> radius;  // bin index (a whole number) -> largest extent
    for (std::size_t i = 0; i < count; ++i) {
        const double h = height_above(i) - base;
        double r = 0.0;
        if (plane->axis >= 0) {
            for (int c : across) r += (n.position[c][i] - centre[c]) * (n.position[c][i] - centre[c]);
        } else {
            // The distance from the line through the centre along the normal.
            std::array<double, 3> d{0, 0, 0};
            double along = 0.0;
            for (int c : across) {
                d[static_cast<std::size_t>(c)] = n.position[c][i] - centre[c];
                along += normal[static_cast<std::size_t>(c)] * d[static_cast<std::size_t>(c)];
            }
            for (int c : across) {
                const double off = d[static_cast<std::size_t>(c)] - along * normal[static_cast<std::size_t>(c)];
                r += off * off;
            }
        }
        r = std::sqrt(r);
        const double k = std::floor(std::max(h / bin, 0.0));
        const double extent_r = measure::particle_outline_radius(r, measure::particle_cell_size(n.size_weight[i], dim));
        const auto [it, added] = radius.try_emplace(k, extent_r);
        if (!added) it->second = std::max(it->second, extent_r);
    }
    for (const auto& [k, r] : radius) out.emplace_back((k + 0.5) * bin, r);
    out.emplace_back(top, 0.0);
    return out;
}

void write_profile(const fs::path& file, const Simulation& sim) {
    const auto outline = final_outline(sim);
    if (outline.empty()) return;
    std::string text = "height_m,radius_m\n";
    for (const auto& [h, r] : outline) text += fmt::format("{:.6e},{:.6e}\n", h, r);
    write_text_file(file, text);
}

}  // namespace gpa::io
