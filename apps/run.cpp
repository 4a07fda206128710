#include "run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <ctime>
#include <exception>
#include <fstream>
#include <future>
#include <limits>
#include <sstream>
#include <string_view>
#include <system_error>

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <sys/statvfs.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/elements.hpp"
#include "gpa/engine/errors.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/io/checkpoint.hpp"
#include "gpa/io/material_library.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace gpa::app {

std::string_view default_scene_text();  // scenes/armco-cylinder-nodal.toml, embedded at build time

namespace {

namespace fs = std::filesystem;

constexpr const char* checkpoint_name = io::checkpoint_file_name;
constexpr const char* scene_copy_name = "scene.toml";

// The scene's text and what messages call it.
struct SceneSource {
    std::string text;
    std::string name;   // for messages ("scenes/x.toml")
    std::string label;  // for the summary's scene_file
};

// The file the built-in default scene was embedded from: the files it names (its element
// reference) are found beside it, in the source tree the program was built from.
const fs::path default_scene_file{GPA_DEFAULT_SCENE_FILE};
constexpr const char* builtin_label = "(built-in default)";  // the summary's scene_file of the built-in scene

// Resolves the files a scene names relative to the file its text came from (the built-in scene's:
// default_scene_file) and says, whatever --quiet, when one is not there (io::resolve_scene_files).
void resolve_files(Scene& scene, const fs::path& scene_file) {
    if (const std::string warning = io::resolve_scene_files(scene, scene_file); !warning.empty()) spdlog::warn("{}", warning);
}

SceneSource read_source(const std::optional<fs::path>& file) {
    if (file) return {io::read_scene_text(*file), file->string(), file->string()};
    return {std::string(default_scene_text()), "built-in default scene (scenes/armco-cylinder-nodal.toml)", builtin_label};
}

// Scheduled snapshot times: t_k = k * interval for whole k, from `snapshot_interval`, or from
// `snapshots` spread over the end time; with neither known, the first and the last only. The
// snapshot of t_k is the state of the step nearest to it (its own time is written with it): a step
// at t writes the next t_k when the step after it, at t + dt_next, would be further from t_k, that
// is when t + dt_next / 2 has passed t_k (the steps are not shortened to land on t_k: the run is the
// same whatever its output schedule). Which t_k that is is computed from the time (a whole number,
// floor(t / interval)), never by adding the interval up, so that an interval below the rounding step
// of the time cannot stall the schedule (at most one snapshot per step).
class SnapshotSchedule {
public:
    explicit SnapshotSchedule(const Scene& s) {
        if (s.output.snapshot_interval > 0.0) {
            interval_ = s.output.snapshot_interval;
        } else if (s.output.snapshots > 1 && s.stop.end_time > 0.0) {
            interval_ = s.stop.end_time / double(s.output.snapshots - 1);
        }
    }
    double interval() const { return interval_; }
    // The last t_k at or before t (with a relative 1e-9 for a step that lands on t_k).
    double slot(double t) const { return interval_ > 0.0 ? std::floor(t / interval_ * (1.0 + 1e-9)) : 0.0; }
    // True (and remembered) when the step at t is the nearest to a scheduled time not yet written:
    // t + dt_next / 2 has passed it (dt_next: the step that would follow).
    bool due(double t, double dt_next) {
        if (!(interval_ > 0.0)) return false;
        const double k = slot(t + 0.5 * dt_next);
        if (!(k > last_)) return false;
        last_ = k;
        return true;
    }
    double last_slot() const { return last_; }
    void set_last_slot(double k) { last_ = k; }
    // How many scheduled snapshots [0, end] holds (without a known end: 2).
    double planned(double end) const {
        if (!(interval_ > 0.0) || !(end > 0.0) || !std::isfinite(end)) return 2.0;
        return std::floor(end / interval_ * (1.0 + 1e-9)) + 1.0;
    }

private:
    double interval_ = 0.0;
    double last_ = 0.0;
};

// A copy of the real nodes and element bodies, written by a background task while the run goes on.
// A write that failed is reported by the next call (write, write_marked or wait).
class SnapshotWriter {
public:
    SnapshotWriter(fs::path folder, SnapshotFormat format) : series_(std::move(folder), "particles", std::move(format)) {}
    ~SnapshotWriter() {
        try {
            wait();
        } catch (...) {
        }
    }
    void write(const Simulation& sim) {
        wait();
        pending_ = std::async(std::launch::async, [this, snapshot = io::take_snapshot(sim)] {
            const auto t0 = std::chrono::steady_clock::now();
            series_.write(snapshot);
            seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        });
    }
    // A snapshot outside the schedule, written now (the run stops after it).
    std::string write_marked(const Simulation& sim, const std::string& label, const std::string& mark) {
        wait();
        const auto names = series_.write_marked(io::take_snapshot(sim), label, mark);
        return names.empty() ? std::string() : names.front();
    }
    void wait() {
        if (pending_.valid()) pending_.get();
    }
    io::SnapshotSeries& series() { return series_; }
    double seconds() const { return seconds_; }
    void add_seconds(double s) { seconds_ += s; }

private:
    io::SnapshotSeries series_;
    std::future<void> pending_;
    double seconds_ = 0.0;
};

// What a checkpoint holds for the program besides the simulation (its user data): where the run
// came from and how far its outputs had got.
struct RunState {
    std::string scene_file;
    bool overwrite = false;
    double wall_seconds = 0.0, output_seconds = 0.0;
    double snapshot_slot = 0.0;
    std::vector<io::PvdEntry> snapshots;  // the scheduled ones, in order
    io::HistoryWriter::Mark history;      // history.csv as it was (not recorded by older checkpoints)
    std::vector<io::GaugeWriter::Mark> gauges;  // each gauge_<name>.csv as it was, in the scene's gauge order
};

std::string encode(const RunState& s) {
    std::string scene = s.scene_file;
    std::replace(scene.begin(), scene.end(), '\n', '?');
    std::string out = "gpa-run-state 1\n";
    out += fmt::format("scene_file={}\noverwrite={}\nwall_seconds={:.17g}\noutput_seconds={:.17g}\nsnapshot_slot={:.17g}\n",
                       scene, s.overwrite ? 1 : 0, s.wall_seconds, s.output_seconds, s.snapshot_slot);
    for (const auto& e : s.snapshots) out += fmt::format("snapshot={:.17g} {} {}\n", e.time, e.part, e.file);
    out += fmt::format("history={} {:016x}\n", s.history.bytes, s.history.digest);
    for (const auto& g : s.gauges) out += fmt::format("gauge={} {:016x}\n", g.bytes, g.digest);
    return out;
}

RunState decode(const std::string& text, const std::string& source) {
    std::istringstream in(text);
    std::string line;
    if (!std::getline(in, line) || line != "gpa-run-state 1") {
        throw CheckpointError(fmt::format("checkpoint {}: it holds no state of a gpa run", source));
    }
    RunState s;
    while (std::getline(in, line)) {
        const auto eq = line.find('=');
        if (eq == std::string::npos) continue;
        const std::string key = line.substr(0, eq), value = line.substr(eq + 1);
        try {
            if (key == "scene_file") s.scene_file = value;
            else if (key == "overwrite") s.overwrite = value == "1";
            else if (key == "wall_seconds") s.wall_seconds = std::stod(value);
            else if (key == "output_seconds") s.output_seconds = std::stod(value);
            else if (key == "snapshot_slot") s.snapshot_slot = std::stod(value);
            else if (key == "history" || key == "gauge") {
                const auto space = value.find(' ');
                if (space == std::string::npos) throw std::invalid_argument(value);
                io::RowFile::Mark mark;
                mark.bytes = std::stoll(value.substr(0, space));
                mark.digest = std::stoull(value.substr(space + 1), nullptr, 16);
                if (mark.bytes <= 0) throw std::invalid_argument(value);
                if (key == "history") {
                    s.history = mark;
                } else {
                    s.gauges.push_back(mark);
                }
            }
            else if (key == "snapshot") {
                const auto space = value.find(' ');
                const auto second = space == std::string::npos ? space : value.find(' ', space + 1);
                if (second == std::string::npos) throw std::invalid_argument(value);
                io::PvdEntry e{std::stod(value.substr(0, space)), value.substr(second + 1)};
                e.part = std::stoi(value.substr(space + 1, second - space - 1));
                s.snapshots.push_back(e);
            }
        } catch (const std::exception&) {
            throw CheckpointError(fmt::format("checkpoint {}: its run state is damaged at \"{}\"", source, line));
        }
    }
    return s;
}

// Whether a snapshot file ends with the tag that closes it (</VTKFile>, and a line end).
bool ends_with_closing_tag(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    const std::string tag = "</VTKFile>";
    if (!in.seekg(0, std::ios::end)) return false;
    const auto size = static_cast<long long>(in.tellg());
    const long long tail = std::min<long long>(size, 64);
    std::string end(static_cast<std::size_t>(tail), '\0');
    if (!in.seekg(size - tail) || !in.read(end.data(), tail)) return false;
    while (!end.empty() && (end.back() == '\n' || end.back() == '\r' || end.back() == ' ')) end.pop_back();
    return end.size() >= tag.size() && end.compare(end.size() - tag.size(), tag.size(), tag) == 0;
}

std::uint64_t free_bytes(const fs::path& folder) {
    struct statvfs fs {};
    if (::statvfs(folder.c_str(), &fs) != 0) return std::numeric_limits<std::uint64_t>::max();
    return std::uint64_t(fs.f_bavail) * std::uint64_t(fs.f_frsize);
}

std::uint64_t file_bytes(const fs::path& file) {
    std::error_code ec;
    const auto size = fs::file_size(file, ec);
    return ec ? 0 : size;
}

// The disk a run's outputs will take, from the size of its first snapshot, checked against the
// free space of its folder before the first step. A resumed run passes `kept`, the scheduled
// snapshots already in its folder: they, the history so far and the checkpoint are on the disk
// already, and only what the rest of the run adds must fit.
void check_disk(const Simulation& sim, const SnapshotSchedule& schedule, const fs::path& folder, std::uint64_t snapshot_bytes,
                std::optional<std::size_t> kept = std::nullopt) {
    const Scene& s = sim.scene();
    // Steps: from the first time step to the end time, or max_steps, whichever is fewer.
    double steps = std::numeric_limits<double>::infinity();
    if (s.stop.end_time > 0.0 && sim.next_time_step() > 0.0) steps = std::ceil((s.stop.end_time - sim.time()) / sim.next_time_step());
    if (s.stop.max_steps > 0) steps = std::min(steps, double(s.stop.max_steps - std::min(s.stop.max_steps, sim.steps())));
    // Snapshots: the scheduled ones up to the end time (or the time max_steps reach at the first
    // step's length), at most one per step; on resume, less those written (but the last one).
    double end = s.stop.end_time > 0.0 ? s.stop.end_time : std::numeric_limits<double>::infinity();
    if (s.stop.max_steps > 0) end = std::min(end, sim.time() + steps * sim.next_time_step());
    double snapshots = schedule.planned(end);
    if (kept) snapshots = std::max(snapshots - double(*kept), 1.0);
    if (std::isfinite(steps)) snapshots = std::min(snapshots, steps + 2.0);
    const double rows = std::isfinite(steps) ? steps / double(std::max<std::size_t>(s.output.history_every, 1)) + 2.0 : 0.0;
    // A checkpoint is about the node store and the lists; two exist while one replaces the other
    // (on resume, one of them is there already).
    const double checkpoint = (kept ? 1.0 : 2.0) * (double(sim.nodes().size()) * bytes_per_node_besides_lists(sim.nodes().dim()) / 2.0 +
                                                    4.0 * double(sim.totals().pairs));
    // A history row is about 400 bytes; a gauge row 16 bytes a column.
    double row_bytes = 400.0;
    for (const auto& g : s.gauges) row_bytes += 16.0 * (2.0 + 6.0 * double(g.fields.empty() ? 6 : g.fields.size()));
    const double bytes = snapshots * double(snapshot_bytes) + rows * row_bytes + checkpoint;
    const double available = double(free_bytes(folder));
    if (bytes > available) {
        throw LimitError(fmt::format("{} need an estimated {} of disk ({:.3g} {}snapshots of {} each{}, the "
                                     "history and a checkpoint); the file system of '{}' has {} free",
                                     kept ? "the outputs the rest of the resumed run adds" : "the run's outputs", format_bytes(bytes),
                                     snapshots, kept ? "more " : "", format_bytes(double(snapshot_bytes)),
                                     std::isfinite(steps) && snapshots >= steps ? ", one per step" : "", folder.string(),
                                     format_bytes(available)));
    }
}

void print_report(const Simulation& sim) {
    const auto& t = sim.totals();
    fmt::print("  {} real nodes, {} steps, t = {:.4g} us ({})\n", t.real_nodes, t.step, t.time * 1e6, sim.stop_reason());
    if (t.elements > 0) fmt::print("  {} elements, {} element nodes\n", t.elements, t.element_nodes);
    if (!t.planes.empty()) {
        if (sim.nodes().dim() == 3) {
            fmt::print("  final length {:.4g} mm, footprint diameter {:.4g} mm (the mean width over {} directions, {:.4g} to {:.4g} mm)\n",
                       t.length * 1e3, t.footprint_diameter * 1e3, measure::footprint_directions, t.footprint_narrowest * 1e3,
                       t.footprint_widest * 1e3);
        } else {
            fmt::print("  final length {:.4g} mm, footprint diameter {:.4g} mm\n", t.length * 1e3, t.footprint_diameter * 1e3);
        }
    }
    fmt::print("  plastic work {:.4g} J, viscous work {:.4g} J, boundary work {:.3g} J, energy error {:+.3g} %\n",
               t.plastic_work, t.viscous_work, t.boundary_work, 100.0 * t.energy_error);
    for (std::size_t b = 0; b < sim.scene().bodies.size(); ++b) {
        if (const int copies = symmetry_copies(sim.scene(), b); copies > 1) {
            fmt::print("  body \"{}\" is 1/{} of the whole (symmetry planes): its energies and masses are the model's, its length "
                       "and footprint the whole body's\n",
                       sim.scene().bodies[b].name, copies);
        }
    }
    const int dim = sim.nodes().dim();
    for (const auto& r : t.regions) {
        std::string reaction;
        for (int c = 0; c < dim; ++c) {
            if (r.held[c]) reaction += fmt::format(", reaction {} {:.4g} N", "xyz"[dim == 2 && c == 1 ? 2 : c], r.reaction[c]);
        }
        fmt::print("  prescribed velocity \"{}\": work {:.4g} J{}\n", r.name, r.work, reaction);
    }
    for (const auto& c : io::compare_with_reference(sim)) {
        fmt::print("  {}: {:.4g} against the reference {:.4g} ({:+.2f} %)\n", c.key, c.computed, c.reference,
                   100.0 * c.relative_error);
    }
    if (t.local.measured && t.local.plastic_strain.points > 0) {
        const auto& at = t.local.plastic_strain.position;
        const std::string where = dim == 3 ? fmt::format("(x, y, z) = ({:.3g}, {:.3g}, {:.3g}) mm", at[0] * 1e3, at[1] * 1e3, at[2] * 1e3)
                                           : fmt::format("(x, z) = ({:.3g}, {:.3g}) mm", at[0] * 1e3, at[1] * 1e3);
        fmt::print("  peak plastic strain {:.4g} (mean within {:.3g} mm) at {}, largest single value {:.4g}; peak temperature {:.4g} K\n",
                   t.local.plastic_strain.value, t.local.radius * 1e3, where, t.local.plastic_strain.raw, t.local.temperature.value);
    }
    if (!sim.scene().element_reference.empty()) {
        try {
            const auto ref = io::read_element_reference(sim.scene().element_reference);
            const auto ratios = io::compare_with_reference(io::run_metrics(sim), io::final_outline(sim), ref);
            std::string line;
            for (const auto& [key, label] : std::vector<std::pair<std::string, std::string>>{
                     {"final_length", "L*"}, {"footprint_diameter", "D*"}, {"plastic_work", "PW*"},
                     {"peak_plastic_strain", "peak strain*"}, {"peak_temperature", "peak T*"}}) {
                if (const auto it = ratios.find(key); it != ratios.end()) line += fmt::format("{}{} {:.4f}", line.empty() ? "" : ", ", label, it->second);
            }
            if (const auto it = ratios.find("outline_distance"); it != ratios.end()) {
                line += fmt::format(", outline distance {:.3g} mm", it->second * 1e3);
            }
            if (line.empty()) {
                line = "none of its metrics is measured by this run (length and footprint need a rigid plane, the peaks "
                       "the reference's peak radius)";
            }
            fmt::print("  against the element reference ({}): {}\n", sim.scene().element_reference, line);
        } catch (const InputError& e) {
            fmt::print("  element reference: {}\n", e.what());
        }
    }
}

std::string failure_json(const FailureSite& f) {
    std::string position = "[";
    for (int c = 0; c < f.dim; ++c) position += fmt::format("{}{:.10g}", c ? ", " : "", f.position[c]);
    position += "]";
    const auto quote = [](const std::string& s) {
        std::string out = "\"";
        for (const char c : s) {
            if (c == '"' || c == '\\') out += '\\';
            if (static_cast<unsigned char>(c) >= 0x20) out += c;
        }
        return out + "\"";
    };
    return fmt::format("{{\"step\": {}, \"time_s\": {:.10g}, \"phase\": {}, \"node\": {}, \"body\": {}, \"position_m\": {}, "
                       "\"field\": {}}}",
                       f.step, f.time, quote(f.phase), f.node ? std::to_string(*f.node) : "null", quote(f.body),
                       f.node ? position : "null", quote(f.field));
}

// One run in its folder, from its first step or from a checkpoint.
class Runner {
public:
    Runner(const RunOptions& options, Simulation& sim, io::RunFolder& folder, SceneSource source, RunState state)
        : options_(options), sim_(sim), folder_(folder), source_(std::move(source)), state_(std::move(state)),
          fingerprint_(io::scene_fingerprint(source_.text)), schedule_(sim.scene()), snapshots_(folder.partial(), sim.scene().output.snapshot_format) {}

    // A fresh run: the scene's copy, the history's header, the snapshot at t = 0, the disk check.
    void start() {
        io::write_text_file(folder_.partial() / scene_copy_name, source_.text);
        sim_.measure_bodies();
        history_.emplace(folder_.partial() / "history.csv", sim_.totals(), io::HistoryLayout::of(sim_.scene()));
        history_->write(sim_.totals());
        gauges_.emplace(folder_.partial(), sim_);
        gauges_->write(sim_);
        last_row_ = sim_.steps();
        scheduled_rows_ = history_->mark();
        scheduled_gauge_rows_ = gauges_->marks();
        snapshots_.write(sim_);
        snapshots_.wait();  // its size is the disk estimate's unit
        check_disk(sim_, schedule_, folder_.partial(), file_bytes(folder_.partial() / snapshots_.series().entries()[0].file));
    }

    // A resumed run: its outputs checked and cut back to what they were at the checkpoint.
    // Whatever cannot be continued is refused before anything in the folder changes.
    void resume(std::size_t checkpoint_step) {
        const Scene& scene = sim_.scene();
        const std::size_t every = std::max<std::size_t>(scene.output.history_every, 1);
        const std::string checkpoint = (folder_.partial() / checkpoint_name).string();
        sim_.measure_bodies();
        const fs::path history_file = folder_.partial() / "history.csv";
        const std::string kept_history = io::HistoryWriter::kept_for_resume(history_file, sim_.totals(), io::HistoryLayout::of(scene),
                                                                            checkpoint_step, every, state_.history, checkpoint);
        // Every snapshot the checkpoint lists must be there and whole (a writer's file ends with
        // its closing tag); the .pvd rewritten below lists them all.
        for (const auto& e : state_.snapshots) {
            const fs::path file = folder_.partial() / e.file;
            std::error_code ec;
            const bool present = fs::is_regular_file(file, ec);
            if (!present || !ends_with_closing_tag(file)) {
                throw io::OutputError(fmt::format("'{}' {} (the snapshot of t = {:.6g} us that '{}' lists): the stopped run cannot "
                                                  "be continued from it (start it again with --overwrite)",
                                                  file.string(), present ? "is not whole" : "is missing", e.time * 1e6, checkpoint));
            }
        }
        // The gauges' files are checked, then cut back, before the history is.
        gauges_.emplace(folder_.partial(), sim_, checkpoint_step, every, state_.gauges, checkpoint);
        scheduled_gauge_rows_ = gauges_->marks();
        // Checked: from here on the folder is cut back to the checkpoint.
        history_.emplace(history_file, sim_.totals(), io::HistoryLayout::of(scene), kept_history);
        scheduled_rows_ = history_->mark();
        last_row_ = checkpoint_step;
        schedule_.set_last_slot(state_.snapshot_slot);
        snapshots_.add_seconds(state_.output_seconds);
        // Snapshots written after the checkpoint, and those of the interruption or failure, go.
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(folder_.partial(), ec)) {
            const std::string name = entry.path().filename().string();
            const bool kept = std::any_of(state_.snapshots.begin(), state_.snapshots.end(),
                                          [&](const io::PvdEntry& e) { return e.file == name; });
            // Particle snapshots and, for element bodies, the element part of each snapshot.
            const bool snapshot = (name.rfind("particles_", 0) == 0 && entry.path().extension() == ".vtp") ||
                                  (name.rfind("elements_", 0) == 0 && entry.path().extension() == ".vtu");
            const bool stale = name == "summary.json" || name == "profile.csv" || entry.path().extension() == ".tmp";
            if ((snapshot && !kept) || stale) fs::remove(entry.path(), ec);
        }
        snapshots_.series().restore(state_.snapshots, static_cast<std::size_t>(std::count_if(
                                                          state_.snapshots.begin(), state_.snapshots.end(),
                                                          [](const io::PvdEntry& e) { return e.part == 0; })));
        check_disk(sim_, schedule_, folder_.partial(),
                   state_.snapshots.empty() ? 0 : file_bytes(folder_.partial() / state_.snapshots.front().file),
                   snapshots_.series().scheduled());
    }

    int run() {
        const auto wall_start = std::chrono::steady_clock::now();
        const auto wall = [&] {
            return state_.wall_seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        };
        const Scene& scene = sim_.scene();
        const std::size_t every = std::max<std::size_t>(scene.output.history_every, 1);
        Progress progress(options_.quiet);
        StopRequests stop;
        auto last_checkpoint = std::chrono::steady_clock::now();
        int stop_signal = 0;
        try {
            while (!sim_.finished()) {
                if ((stop_signal = StopRequests::requested()) != 0) break;
                sim_.step();
                if (const auto& t = sim_.totals(); t.collapse_switches > 0 && !options_.quiet) {
                    spdlog::warn("step {}: {} fixed node{} switched to variable connectivity because a lattice cell collapsed; "
                                 "first: {}",
                                 t.step, t.collapse_switches, t.collapse_switches == 1 ? "" : "s", t.first_collapse_switch);
                }
                const bool last = sim_.finished();
                if (last || sim_.steps() % every == 0) write_row();
                if (schedule_.due(sim_.time(), sim_.next_time_step()) || last) snapshots_.write(sim_);
                const auto now = std::chrono::steady_clock::now();
                const bool by_steps = scene.output.checkpoint_every_steps > 0 && sim_.steps() % scene.output.checkpoint_every_steps == 0;
                const bool by_time = scene.output.checkpoint_every_seconds > 0.0 &&
                                     std::chrono::duration<double>(now - last_checkpoint).count() >= scene.output.checkpoint_every_seconds;
                if (!last && (by_steps || by_time)) {
                    write_checkpoint(wall());
                    last_checkpoint = std::chrono::steady_clock::now();
                }
                progress.update(sim_);
            }
            progress.finish(sim_);
            snapshots_.wait();
        } catch (const StepFailure& f) {
            progress.finish(sim_);
            return failed(f.what(), &f.site(), wall());
        } catch (const std::exception& e) {
            progress.finish(sim_);
            return failed(e.what(), nullptr, wall());
        }
        if (stop_signal != 0) return interrupted(stop_signal, wall());
        return finished(wall());
    }

private:
    void write_row() {
        sim_.measure_bodies();  // the summary reports the bodies as of the last row too
        history_->write(sim_.totals());
        gauges_->write(sim_);
        last_row_ = sim_.steps();
        if (sim_.steps() % std::max<std::size_t>(sim_.scene().output.history_every, 1) == 0) {
            scheduled_rows_ = history_->mark();
            scheduled_gauge_rows_ = gauges_->marks();
        }
    }

    void write_checkpoint(double wall_seconds) {
        snapshots_.wait();  // the series on disk is the one the checkpoint lists
        RunState s = state_;
        s.scene_file = source_.label;
        s.overwrite = options_.overwrite || state_.overwrite;
        s.wall_seconds = wall_seconds;
        s.output_seconds = snapshots_.seconds();
        s.snapshot_slot = schedule_.last_slot();
        // The history up to its last scheduled row: a row off the schedule (that of an
        // interruption) is not part of the run a resume continues, and goes when it resumes.
        s.history = scheduled_rows_;
        s.gauges = scheduled_gauge_rows_;
        s.snapshots.clear();
        for (const auto& e : snapshots_.series().entries()) {
            if (e.name.empty()) s.snapshots.push_back(e);
        }
        io::write_checkpoint(folder_.partial() / checkpoint_name, sim_, fingerprint_, encode(s));
    }

    io::RunSummary summary(const std::string& status, const std::string& message, double wall_seconds) {
        io::RunSummary s;
        s.scene_file = state_.scene_file.empty() ? source_.label : state_.scene_file;
        s.status = status;
        s.message = message;
        s.snapshots = snapshots_.series().count();
        s.output_seconds = snapshots_.seconds();
        s.wall_seconds = wall_seconds;
        return s;
    }

    int finished(double wall_seconds) {
        try {
            io::write_profile(folder_.partial() / "profile.csv", sim_);
            io::write_summary(folder_.partial() / "summary.json", sim_, summary("finished", sim_.stop_reason(), wall_seconds));
            std::error_code ec;
            fs::remove(folder_.partial() / checkpoint_name, ec);  // a finished run is not resumed
            folder_.commit();
        } catch (const std::exception& e) {
            return failed(e.what(), nullptr, wall_seconds);
        }
        if (!options_.quiet) {
            const Scene& scene = sim_.scene();
            fmt::print("{}\n", scene.name.empty() ? "run finished" : scene.name);
            print_report(sim_);
            fmt::print("  wall time {:.1f} s on {} thread{}\n", wall_seconds, sim_.threads(), sim_.threads() == 1 ? "" : "s");
        }
        fmt::print("output: {} (open particles.pvd in ParaView; history.csv, summary.json)\n", folder_.final_path().string());
        return 0;
    }

    int interrupted(int signo, double wall_seconds) {
        const char* name = signo == SIGTERM ? "SIGTERM" : "SIGINT";
        std::string problem;
        try {
            snapshots_.wait();
            if (last_row_ != sim_.steps()) write_row();
            snapshots_.write_marked(sim_, fmt::format("interrupted_step{:07d}", sim_.steps()),
                                    fmt::format("interrupted at step {}", sim_.steps()));
            write_checkpoint(wall_seconds);
            io::write_summary(folder_.partial() / "summary.json", sim_,
                              summary("interrupted",
                                      fmt::format("stopped by {} after step {} at t = {:.6g} us", name, sim_.steps(), sim_.time() * 1e6),
                                      wall_seconds));
        } catch (const std::exception& e) {
            problem = e.what();
        }
        std::string next;
        if (!problem.empty()) next = fmt::format(", and saving it failed: {}", problem);
        else next = fmt::format("; resume it with: gpa run --resume {}", folder_.final_path().string());
        fmt::print(stderr, "gpa: the run was stopped by {} after step {} at t = {:.4g} us{}\n", name, sim_.steps(), sim_.time() * 1e6, next);
        return 128 + signo;
    }

    int failed(const std::string& message, const FailureSite* site, double wall_seconds) {
        std::string also;
        try {
            snapshots_.wait();
        } catch (const std::exception& e) {
            also += fmt::format("; a snapshot could not be written either: {}", e.what());
        }
        try {
            if (last_row_ != sim_.totals().step) write_row();
        } catch (const std::exception&) {
        }
        try {
            if (site) {
                // The failing step as it was when it failed, marked beside the scheduled ones.
                snapshots_.write_marked(sim_, fmt::format("failed_step{:07d}", site->step), fmt::format("failed step {}", site->step));
            }
        } catch (const std::exception& e) {
            also += fmt::format("; the snapshot of the failing step could not be written: {}", e.what());
        }
        try {
            auto s = summary("failed", message, wall_seconds);
            if (site) s.failure_json = failure_json(*site);
            io::write_summary(folder_.partial() / "summary.json", sim_, s);
        } catch (const std::exception& e) {
            also += fmt::format("; summary.json could not be written: {}", e.what());
        }
        const bool resumable = fs::exists(folder_.partial() / checkpoint_name);
        fmt::print(stderr, "gpa: the run failed: {}{}; what was written is in {}{}\n", message, also, folder_.partial().string(),
                   resumable && !site ? fmt::format(" (gpa run --resume {} continues it from its last checkpoint)",
                                                    folder_.final_path().string())
                                      : "");
        return 3;
    }

    const RunOptions& options_;
    Simulation& sim_;
    io::RunFolder& folder_;
    SceneSource source_;
    RunState state_;
    std::string fingerprint_;
    SnapshotSchedule schedule_;
    SnapshotWriter snapshots_;
    std::optional<io::HistoryWriter> history_;
    std::optional<io::GaugeWriter> gauges_;  // gauge_<name>.csv, on the history's schedule
    std::size_t last_row_ = 0;  // the step of the last history row
    io::HistoryWriter::Mark scheduled_rows_;  // history.csv as of its last row on the schedule (steps 0, every, ...)
    std::vector<io::GaugeWriter::Mark> scheduled_gauge_rows_;  // the gauges' files as of the same row
};

int fresh_run(const RunOptions& options) {
    SceneSource source = read_source(options.scene);
    Scene scene = io::parse_scene(source.text, source.name);
    resolve_files(scene, options.scene ? *options.scene : default_scene_file);
    log_scene_warnings(scene, source.name);
    const fs::path output = options.output.value_or(default_output_folder("runs", scene.name));
    Simulation sim(scene, options.threads, options.memory);  // before the folder: an impossible scene leaves nothing behind
    for (const auto& spec : scene.gauges) Gauge(spec, scene, sim.nodes(), sim.real_count());  // so is a gauge with no node
    io::RunFolder folder(output, options.overwrite);
    if (!options.quiet) {
        spdlog::info("{}: {} nodes, {} thread{}, output in {}", scene.name.empty() ? "scene" : scene.name, sim.real_count(),
                     sim.threads(), sim.threads() == 1 ? "" : "s", folder.partial().string());
    }
    RunState state;
    state.scene_file = source.label;
    state.overwrite = options.overwrite;
    Runner runner(options, sim, folder, std::move(source), state);
    try {
        runner.start();
    } catch (...) {
        // Refused before the first step (the disk estimate, an unwritable folder): nothing is kept.
        std::error_code ec;
        fs::remove_all(folder.partial(), ec);
        throw;
    }
    return runner.run();
}

int resumed_run(const RunOptions& options) {
    if (options.output) throw io::OutputError("--resume continues a run in its own folder: give the folder to --resume, not -o");
    io::RunFolder folder(*options.resume, false, io::RunFolder::Mode::Resume);
    const fs::path checkpoint = folder.partial() / checkpoint_name;
    if (!fs::exists(checkpoint)) {
        std::error_code ec;
        if (fs::is_empty(folder.partial(), ec)) {
            throw io::OutputError(fmt::format("'{}' is empty: there is nothing to resume", folder.partial().string()));
        }
        throw io::OutputError(fmt::format("'{}' holds no checkpoint: the run stopped before it wrote one (output.checkpoint_every); "
                                          "start it again",
                                          folder.partial().string()));
    }
    // The scene the run started with: its copy in the folder, or the file given, which must be
    // the same.
    const fs::path copy = folder.partial() / scene_copy_name;
    SceneSource source = options.scene ? read_source(options.scene) : SceneSource{io::read_scene_text(copy), copy.string(), copy.string()};
    const CheckpointInfo info = io::checkpoint_info(checkpoint);
    if (info.scene_fingerprint != io::scene_fingerprint(source.text)) {
        if (!options.scene) {
            // The folder's own copy: the two files came from different runs.
            throw CheckpointError(fmt::format("'{}' and '{}' are not of the same run (the checkpoint was written for another scene): "
                                              "the stopped run cannot be continued from them (start it again with --overwrite)",
                                              checkpoint.string(), copy.string()));
        }
        throw CheckpointError(fmt::format("'{}' is not the scene the run in '{}' started with (its copy is '{}')", source.name,
                                          folder.partial().string(), copy.string()));
    }
    Scene scene = io::parse_scene(source.text, source.name);
    // The files the scene names are relative to the scene file the run started from (the copy in
    // the folder has no such neighbours); one that is no longer there is reported at the end.
    const std::string started_from = decode(info.user_data, checkpoint.string()).scene_file;
    const fs::path original = options.scene ? *options.scene : started_from == builtin_label ? default_scene_file : fs::path(started_from);
    if (!scene.element_reference.empty() && fs::exists(original)) {
        try {
            resolve_files(scene, original);
        } catch (const InputError& e) {
            spdlog::warn("{}", e.what());
        }
    }
    Simulation sim(scene, options.threads, options.memory);
    const std::string user = io::read_checkpoint(checkpoint, sim, io::scene_fingerprint(source.text));
    RunState state = decode(user, checkpoint.string());
    folder.set_overwrite(state.overwrite);
    source.label = state.scene_file;
    if (!options.quiet) {
        spdlog::info("{}: resuming at step {} (t = {:.4g} us), {} nodes, {} thread{}, output in {}", scene.name, info.step,
                     info.time * 1e6, sim.real_count(), sim.threads(), sim.threads() == 1 ? "" : "s", folder.partial().string());
    }
    Runner runner(options, sim, folder, std::move(source), std::move(state));
    runner.resume(info.step);
    return runner.run();
}

}  // namespace

int run_scene(const RunOptions& options) { return options.resume ? resumed_run(options) : fresh_run(options); }

fs::path default_output_folder(const std::string& root, const std::string& scene_name) {
    std::string slug;
    for (char c : scene_name) slug += std::isalnum(static_cast<unsigned char>(c)) ? c : '-';
    if (slug.empty()) slug = "scene";
    const std::time_t now = std::time(nullptr);
    char stamp[32];
    std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", std::localtime(&now));
    return fs::path(root) / fmt::format("{}-{}", slug, stamp);
}

int check_scene(const fs::path& file, const MemoryLimit& memory) {
    std::string warning;
    const Scene scene = io::load_scene(file, &warning);
    // Implausible values first: a unit slip in a size may make the set-up below refuse the scene
    // for its memory, and the user should see why.
    log_scene_warnings(scene, file.string());
    Simulation sim(scene, 1, memory);  // builds the nodes: every check of set-up runs
    // Each gauge placed as the run will place it (a gauge with no node to read is refused here).
    std::vector<Gauge> gauges;
    for (const auto& spec : scene.gauges) gauges.emplace_back(spec, scene, sim.nodes(), sim.real_count());
    fmt::print("{}: OK\n", file.string());
    fmt::print("  {} ({}), {} bod{}, {} real nodes, {} ghost nodes at the start\n", scene.name, name_of(scene.geometry),
               scene.bodies.size(), scene.bodies.size() == 1 ? "y" : "ies", sim.real_count(), sim.totals().ghost_nodes);
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const auto block = body_lattice(scene, b);
        std::size_t count = 0;
        for (std::size_t i = 0; i < sim.real_count(); ++i) count += sim.nodes().body[i] == static_cast<int>(b);
        std::string elements;
        if (const ElementPart* e = sim.elements(); e && scene.bodies[b].discretisation == Discretisation::Elements) {
            count = static_cast<std::size_t>(std::count(e->mesh().nodes.body.begin(), e->mesh().nodes.body.end(), static_cast<int>(b)));
            elements = fmt::format(" ({} elements)", std::count(e->mesh().quads.body.begin(), e->mesh().quads.body.end(), static_cast<int>(b)));
        }
        // Every axis's spacing: x, z in 2D; x, y, z in 3D.
        std::vector<std::string> spacing;
        for (int c = 0; c < dimension_of(scene.geometry); ++c) spacing.push_back(fmt::format("{:.4g}", block.spacing[c] * 1e3));
        fmt::print("  body \"{}\": {}, {} nodes{}, lattice spacing {} mm\n", scene.bodies[b].name, scene.bodies[b].material, count,
                   elements, fmt::join(spacing, " x "));
    }
    // A material derived with `base`: what it changes, constant by constant.
    for (const auto& material : scene.materials) {
        if (material.base.empty()) continue;
        const materials::Material* base = nullptr;
        for (const auto& other : scene.materials) {
            if (&other != &material && other.name == material.base) base = &other;
        }
        if (!base) base = io::find_builtin_material(material.base);
        if (!base) continue;  // (the reader found it; a scene made in code may name anything)
        const auto changes = io::material_changes(material, *base);
        fmt::print("  material \"{}\": base \"{}\"{}{}\n", material.name, base->name,
                   changes.empty() ? " unchanged" : ", with ", fmt::join(changes, ", "));
    }
    for (std::size_t k = 0; k < scene.prescribed_velocities.size(); ++k) {
        const auto& r = scene.prescribed_velocities[k];
        std::string held;
        const int dim = dimension_of(scene.geometry);
        for (int c = 0; c < dim; ++c) {
            if (r.velocity[c]) held += fmt::format("{}{} = {:g} m/s", held.empty() ? "" : ", ", "xyz"[dim == 2 && c == 1 ? 2 : c], *r.velocity[c]);
        }
        fmt::print("  prescribed velocity \"{}\": {} nodes of body \"{}\" at {}{}\n", r.name, sim.totals().regions[k].nodes, r.body, held,
                   r.ramp > 0.0 ? fmt::format(" after a {:.4g} us ramp", r.ramp * 1e6) : std::string());
    }
    // The gauges and their nodes.
    for (const Gauge& gauge : gauges) {
        const GaugeSpec& spec = gauge.spec();
        const auto& ids = gauge.node_ids();
        const std::string listed = ids.size() <= 8 ? fmt::format("{}", fmt::join(ids, ", "))
                                                   : fmt::format("{}, ... {}", fmt::join(ids.begin(), ids.begin() + 4, ", "), ids.back());
        fmt::print("  gauge \"{}\": {} node{} (id{} {}), {} columns in {}\n", spec.name, ids.size(), ids.size() == 1 ? "" : "s",
                   ids.size() == 1 ? "" : "s", listed, gauge.columns().size() + 2, io::GaugeWriter::file_name(spec.name));
    }
    fmt::print("  first time step {:.3g} ns; phases: {}\n", sim.next_time_step() * 1e9, fmt::join(sim.phases(), ", "));
    if (!warning.empty()) fmt::print("  warning: {}\n", warning);
    return 0;
}

namespace {

std::string eos_summary(const materials::EquationOfState& eos) {
    if (const auto* linear = std::get_if<materials::LinearEos>(&eos)) {
        return fmt::format("linear EOS K {:.4g} GPa{}", linear->bulk_modulus / 1e9, linear->logarithmic ? " (logarithmic)" : "");
    }
    if (const auto* poly = std::get_if<materials::PolynomialEos>(&eos)) {
        return fmt::format("polynomial EOS K1 {:.4g} GPa, Gamma0 {}", poly->k1 / 1e9, poly->gruneisen);
    }
    if (const auto* mg = std::get_if<materials::MieGruneisenEos>(&eos)) {
        return fmt::format("Mie-Grueneisen EOS c0 {} m/s, s {}, Gamma0 {}", mg->sound_speed, mg->slope, mg->gruneisen);
    }
    return "an equation of state";
}

std::string failure_summary(const materials::Failure& f) {
    std::string out;
    if (f.johnson_cook) {
        out = fmt::format("Johnson-Cook fracture D1-D5 {}, {}, {}, {}, {}", f.johnson_cook->d1, f.johnson_cook->d2, f.johnson_cook->d3,
                          f.johnson_cook->d4, f.johnson_cook->d5);
    }
    if (f.spall_pressure) out += fmt::format("{}spall at {:.4g} GPa", out.empty() ? "" : "; ", *f.spall_pressure / 1e9);
    return out.empty() ? "no failure model" : out;
}

}  // namespace

void log_scene_warnings(const Scene& scene, std::string_view label) {
    for (const std::string& odd : scene_warnings(scene)) spdlog::warn("{}: {}", label, odd);
}

int list_materials(const std::vector<std::string>& names) {
    if (!names.empty()) {
        // Every name is checked before anything is printed.
        std::vector<const materials::Material*> chosen;
        for (const auto& name : names) chosen.push_back(&io::builtin_material(name));
        for (std::size_t k = 0; k < chosen.size(); ++k) {
            fmt::print("{}# {}: built-in material (materials/data/library.toml). A scene uses it by name, derives from it\n"
                       "# with base = \"{}\" and changes only what differs, or copies this table and edits it.\n{}",
                       k > 0 ? "\n" : "", chosen[k]->name, chosen[k]->name, io::material_as_toml(*chosen[k]));
        }
        return 0;
    }
    for (const auto& m : io::builtin_materials()) {
        fmt::print("{}\n  density {} kg/m^3, shear modulus {:.4g} GPa, specific heat {} J/(kg K), melt {} K\n", m.name,
                   m.density, m.shear_modulus / 1e9, m.specific_heat, m.melt_temperature);
        if (const auto* jc = std::get_if<materials::JohnsonCookStrength>(&m.strength)) {
            fmt::print("  Johnson-Cook A {:.4g} MPa, B {:.4g} MPa, n {}, C {}, m {}\n", jc->a / 1e6, jc->b / 1e6, jc->n, jc->c, jc->m);
        }
        fmt::print("  {}; {}\n", eos_summary(m.eos), failure_summary(m.failure));
        fmt::print("  source: {}\n", m.source);
    }
    fmt::print("\nEvery constant of one, as a table a scene can use: gpa materials \"NAME\"\n");
    return 0;
}

}  // namespace gpa::app
