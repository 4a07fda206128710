#include "gpa/io/run_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <fstream>
#include <future>
#include <iterator>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/statvfs.h>

#include "gpa/engine/elements.hpp"
#include "gpa/engine/gauges.hpp"
#include "gpa/engine/measure.hpp"
#include "gpa/engine/state_io.hpp"
#include "gpa/io/checkpoint.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/reference.hpp"
#include "gpa/io/scene_file.hpp"

namespace gpa::io {

// The run loop's pieces (internal; a named namespace because RunLoop::Impl holds them).
namespace run_loop_detail {

namespace fs = std::filesystem;

constexpr const char* checkpoint_name = checkpoint_file_name;
constexpr const char* scene_copy_name = "scene.toml";

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
        pending_ = std::async(std::launch::async, [this, snapshot = take_snapshot(sim)] {
            const auto t0 = std::chrono::steady_clock::now();
            series_.write(snapshot);
            seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        });
    }
    // A snapshot outside the schedule, written now (the run stops after it).
    std::string write_marked(const Simulation& sim, const std::string& label, const std::string& mark) {
        wait();
        const auto names = series_.write_marked(take_snapshot(sim), label, mark);
        return names.empty() ? std::string() : names.front();
    }
    void wait() {
        if (pending_.valid()) pending_.get();
    }
    SnapshotSeries& series() { return series_; }
    double seconds() const { return seconds_; }
    void add_seconds(double s) { seconds_ += s; }

private:
    SnapshotSeries series_;
    std::future<void> pending_;
    double seconds_ = 0.0;
};

// What a checkpoint holds for the program besides the simulation (its user data): where the run
// came from and how far its outputs had got.
struct RunState {
    std::string scene_file;
    // The file the scene's own files are found relative to (SceneSource::file): a program's built-in
    // scene is labelled, not named, by scene_file (empty in older checkpoints: scene_file then).
    std::string resolve_from;
    bool overwrite = false;
    double wall_seconds = 0.0, output_seconds = 0.0;
    double snapshot_slot = 0.0;
    std::vector<PvdEntry> snapshots;  // the scheduled ones, in order
    HistoryWriter::Mark history;      // history.csv as it was (not recorded by older checkpoints)
    std::vector<GaugeWriter::Mark> gauges;  // each gauge_<name>.csv as it was, in the scene's gauge order
    std::string program_data;  // RunHooks::checkpoint_data's bytes (any), hex-encoded in the file
    std::string surfaces;      // surfaces_digest of the scene the run started with (empty: none)
};

// A digest (FNV-1a, 64 bits, in hex) of the surfaces of the scene's surface bodies and the nodes of
// its imported bodies, as read from their STL and node files: the checkpoint's scene fingerprint
// covers the scene's text only, and a changed file would otherwise resume another body. Empty
// without such bodies. (Kept under the run state's key "surfaces", which predates node files.)
std::string surfaces_digest(const Scene& scene) {
    std::uint64_t h = 1469598103934665603ull;
    bool any = false;
    const auto add = [&](const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t k = 0; k < bytes; ++k) h = (h ^ p[k]) * 1099511628211ull;
    };
    const auto add_all = [&](const auto& values) { add(values.data(), values.size() * sizeof(values[0])); };
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        const BodySpec& body = scene.bodies[b];
        if (!body.surface && !body.node_set) continue;
        any = true;
        add(&b, sizeof b);
        if (body.surface) {
            add_all(body.surface->triangles().vertices);
            add_all(body.surface->triangles().triangles);
        } else {
            add_all(body.node_set->set().positions);
            add_all(body.node_set->set().sizes);
        }
    }
    return any ? fmt::format("{:016x}", h) : std::string();
}

std::string to_hex(const std::string& bytes) {
    static constexpr char digits[] = "0123456789abcdef";
    std::string out;
    out.reserve(2 * bytes.size());
    for (const unsigned char c : bytes) {
        out += digits[c >> 4];
        out += digits[c & 15];
    }
    return out;
}

std::string from_hex(const std::string& hex) {
    if (hex.size() % 2 != 0) throw std::invalid_argument(hex);
    const auto nibble = [](char c) {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        throw std::invalid_argument(std::string(1, c));
    };
    std::string out;
    out.reserve(hex.size() / 2);
    for (std::size_t k = 0; k < hex.size(); k += 2) out += static_cast<char>(nibble(hex[k]) * 16 + nibble(hex[k + 1]));
    return out;
}

std::string encode(const RunState& s) {
    std::string scene = s.scene_file;
    std::replace(scene.begin(), scene.end(), '\n', '?');
    std::string resolve_from = s.resolve_from;
    std::replace(resolve_from.begin(), resolve_from.end(), '\n', '?');
    std::string out = "gpa-run-state 1\n";
    if (!resolve_from.empty()) out += fmt::format("resolve_from={}\n", resolve_from);
    out += fmt::format("scene_file={}\noverwrite={}\nwall_seconds={:.17g}\noutput_seconds={:.17g}\nsnapshot_slot={:.17g}\n",
                       scene, s.overwrite ? 1 : 0, s.wall_seconds, s.output_seconds, s.snapshot_slot);
    for (const auto& e : s.snapshots) out += fmt::format("snapshot={:.17g} {} {}\n", e.time, e.part, e.file);
    out += fmt::format("history={} {:016x}\n", s.history.bytes, s.history.digest);
    for (const auto& g : s.gauges) out += fmt::format("gauge={} {:016x}\n", g.bytes, g.digest);
    if (!s.program_data.empty()) out += fmt::format("program_data={}\n", to_hex(s.program_data));
    if (!s.surfaces.empty()) out += fmt::format("surfaces={}\n", s.surfaces);
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
            else if (key == "resolve_from") s.resolve_from = value;
            else if (key == "program_data") s.program_data = from_hex(value);
            else if (key == "surfaces") s.surfaces = value;
            else if (key == "overwrite") s.overwrite = value == "1";
            else if (key == "wall_seconds") s.wall_seconds = std::stod(value);
            else if (key == "output_seconds") s.output_seconds = std::stod(value);
            else if (key == "snapshot_slot") s.snapshot_slot = std::stod(value);
            else if (key == "history" || key == "gauge") {
                const auto space = value.find(' ');
                if (space == std::string::npos) throw std::invalid_argument(value);
                RowFile::Mark mark;
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
                PvdEntry e{std::stod(value.substr(0, space)), value.substr(second + 1)};
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


void warn(const RunSettings& settings, std::vector<std::string>& kept, const std::string& message) {
    if (settings.warning) settings.warning(message);
    else kept.push_back(message);
}

}  // namespace run_loop_detail

using namespace run_loop_detail;

SceneSource SceneSource::from_file(const fs::path& file) {
    return {read_scene_text(file), file.string(), file.string(), file};
}

struct RunLoop::Impl {
    RunSettings settings;
    SceneSource source;
    std::optional<Simulation> sim;
    std::optional<RunFolder> folder;
    RunState state;
    std::string fingerprint;
    std::optional<SnapshotSchedule> schedule;
    std::optional<SnapshotWriter> snapshots;
    std::optional<HistoryWriter> history;
    std::optional<GaugeWriter> gauges;  // gauge_<name>.csv, on the history's schedule
    std::size_t last_row = 0;           // the step of the last history row
    HistoryWriter::Mark scheduled_rows;  // history.csv as of its last row on the schedule (steps 0, every, ...)
    std::vector<GaugeWriter::Mark> scheduled_gauge_rows;  // the gauges' files as of the same row
    std::optional<std::size_t> resumed_at;  // the checkpoint's step, for a resumed run
    std::function<std::string()> checkpoint_data;  // the run's RunHooks::checkpoint_data
    bool ran = false;
    std::vector<std::string> warnings;

    void warning(const std::string& message) { warn(settings, warnings, message); }

    // Resolves the files a scene names relative to `file` and says when one is not there
    // (resolve_scene_files).
    void resolve_files(Scene& scene, const fs::path& file) {
        if (const std::string w = resolve_scene_files(scene, file, settings.memory); !w.empty()) warning(w);
    }

    void prepare_outputs() {
        fingerprint = scene_fingerprint(source.text);
        schedule.emplace(sim->scene());
        snapshots.emplace(folder->partial(), sim->scene().output.snapshot_format);
    }

    // A fresh run: the scene's copy, the history's header, the snapshot at t = 0, the disk check.
    void start() {
        write_text_file(folder->partial() / scene_copy_name, source.text);
        sim->measure_bodies();
        history.emplace(folder->partial() / "history.csv", sim->totals(), HistoryLayout::of(sim->scene()));
        history->write(sim->totals());
        gauges.emplace(folder->partial(), *sim);
        gauges->write(*sim);
        last_row = sim->steps();
        scheduled_rows = history->mark();
        scheduled_gauge_rows = gauges->marks();
        snapshots->write(*sim);
        snapshots->wait();  // its size is the disk estimate's unit
        check_disk(*sim, *schedule, folder->partial(), file_bytes(folder->partial() / snapshots->series().entries()[0].file));
    }

    // A resumed run: its outputs checked and cut back to what they were at the checkpoint.
    // Whatever cannot be continued is refused before anything in the folder changes.
    void resume(std::size_t checkpoint_step) {
        const Scene& scene = sim->scene();
        const std::size_t every = std::max<std::size_t>(scene.output.history_every, 1);
        const std::string checkpoint = (folder->partial() / checkpoint_name).string();
        sim->measure_bodies();
        const fs::path history_file = folder->partial() / "history.csv";
        const std::string kept_history = HistoryWriter::kept_for_resume(history_file, sim->totals(), HistoryLayout::of(scene),
                                                                        checkpoint_step, every, state.history, checkpoint);
        // Every snapshot the checkpoint lists must be there and whole (a writer's file ends with
        // its closing tag); the .pvd rewritten below lists them all.
        for (const auto& e : state.snapshots) {
            const fs::path file = folder->partial() / e.file;
            std::error_code ec;
            const bool present = fs::is_regular_file(file, ec);
            if (!present || !ends_with_closing_tag(file)) {
                throw OutputError(fmt::format("'{}' {} (the snapshot of t = {:.6g} us that '{}' lists): the stopped run cannot "
                                              "be continued from it (start it again with --overwrite)",
                                              file.string(), present ? "is not whole" : "is missing", e.time * 1e6, checkpoint));
            }
        }
        // The disk the rest of the run needs, from the snapshots it lists (those of part 0 are the
        // scheduled ones).
        const auto scheduled_snapshots = static_cast<std::size_t>(
            std::count_if(state.snapshots.begin(), state.snapshots.end(), [](const PvdEntry& e) { return e.part == 0; }));
        check_disk(*sim, *schedule, folder->partial(),
                   state.snapshots.empty() ? 0 : file_bytes(folder->partial() / state.snapshots.front().file), scheduled_snapshots);
        // The gauges' files are checked, then cut back, before the history is.
        gauges.emplace(folder->partial(), *sim, checkpoint_step, every, state.gauges, checkpoint);
        scheduled_gauge_rows = gauges->marks();
        // Checked: from here on the folder is cut back to the checkpoint.
        history.emplace(history_file, sim->totals(), HistoryLayout::of(scene), kept_history);
        scheduled_rows = history->mark();
        last_row = checkpoint_step;
        schedule->set_last_slot(state.snapshot_slot);
        snapshots->add_seconds(state.output_seconds);
        // Snapshots written after the checkpoint, and those of the interruption or failure, go.
        std::error_code ec;
        for (const auto& entry : fs::directory_iterator(folder->partial(), ec)) {
            const std::string name = entry.path().filename().string();
            const bool kept = std::any_of(state.snapshots.begin(), state.snapshots.end(),
                                          [&](const PvdEntry& e) { return e.file == name; });
            // Particle snapshots and, for element bodies, the element part of each snapshot.
            const bool snapshot = (name.rfind("particles_", 0) == 0 && entry.path().extension() == ".vtp") ||
                                  (name.rfind("elements_", 0) == 0 && entry.path().extension() == ".vtu");
            const bool stale = name == "summary.json" || name == "profile.csv" || entry.path().extension() == ".tmp";
            if ((snapshot && !kept) || stale) fs::remove(entry.path(), ec);
        }
        snapshots->series().restore(state.snapshots, scheduled_snapshots);
    }

    RunResult run(const RunHooks& hooks) {
        const auto wall_start = std::chrono::steady_clock::now();
        const auto wall = [&] {
            return state.wall_seconds + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
        };
        const Scene& scene = sim->scene();
        const std::size_t every = std::max<std::size_t>(scene.output.history_every, 1);
        auto last_checkpoint = std::chrono::steady_clock::now();
        StopRequest stop;
        checkpoint_data = hooks.checkpoint_data;
        // The progress display's last call, also when the run fails; what it throws then is dropped
        // (the run's own failure is the one to report).
        const auto last_progress = [&] {
            try {
                if (hooks.progress) hooks.progress(*sim, true);
            } catch (...) {
            }
        };
        try {
            while (!sim->finished()) {
                if (hooks.stop_requested && (stop = hooks.stop_requested()).code != 0) break;
                sim->step();
                if (const auto& t = sim->totals(); t.collapse_switches > 0) {
                    const std::string message =
                        fmt::format("step {}: {} fixed node{} switched to variable connectivity because a lattice cell collapsed; "
                                    "first: {}",
                                    t.step, t.collapse_switches, t.collapse_switches == 1 ? "" : "s", t.first_collapse_switch);
                    if (hooks.step_warning) hooks.step_warning(message);
                    else warning(message);
                }
                if (hooks.after_step) hooks.after_step(*sim);
                const bool last = sim->finished();
                if (last || sim->steps() % every == 0) write_row();
                if (schedule->due(sim->time(), sim->next_time_step()) || last) snapshots->write(*sim);
                const auto now = std::chrono::steady_clock::now();
                const bool by_steps = scene.output.checkpoint_every_steps > 0 && sim->steps() % scene.output.checkpoint_every_steps == 0;
                const bool by_time = scene.output.checkpoint_every_seconds > 0.0 &&
                                     std::chrono::duration<double>(now - last_checkpoint).count() >= scene.output.checkpoint_every_seconds;
                if (!last && (by_steps || by_time)) {
                    write_checkpoint(wall());
                    last_checkpoint = std::chrono::steady_clock::now();
                }
                if (hooks.progress) hooks.progress(*sim, false);
            }
            if (hooks.progress) hooks.progress(*sim, true);
            snapshots->wait();
        } catch (const StepFailure& f) {
            last_progress();
            return failed(f.what(), &f.site(), wall());
        } catch (const std::exception& e) {
            last_progress();
            return failed(e.what(), nullptr, wall());
        } catch (...) {
            last_progress();
            return failed("a hook threw an exception that is not a std::exception", nullptr, wall());
        }
        if (stop.code != 0) return interrupted(stop, wall());
        return finished(wall());
    }

    void write_row() {
        sim->measure_bodies();  // the summary reports the bodies as of the last row too
        history->write(sim->totals());
        gauges->write(*sim);
        last_row = sim->steps();
        if (sim->steps() % std::max<std::size_t>(sim->scene().output.history_every, 1) == 0) {
            scheduled_rows = history->mark();
            scheduled_gauge_rows = gauges->marks();
        }
    }

    void write_checkpoint(double wall_seconds) {
        snapshots->wait();  // the series on disk is the one the checkpoint lists
        RunState s = state;
        if (checkpoint_data) s.program_data = checkpoint_data();
        s.wall_seconds = wall_seconds;
        s.output_seconds = snapshots->seconds();
        s.snapshot_slot = schedule->last_slot();
        // The history up to its last scheduled row: a row off the schedule (that of an
        // interruption) is not part of the run a resume continues, and goes when it resumes.
        s.history = scheduled_rows;
        s.gauges = scheduled_gauge_rows;
        s.snapshots.clear();
        for (const auto& e : snapshots->series().entries()) {
            if (e.name.empty()) s.snapshots.push_back(e);
        }
        io::write_checkpoint(folder->partial() / checkpoint_name, *sim, fingerprint, encode(s));
    }

    RunSummary summary(const std::string& status, const std::string& message, double wall_seconds) {
        RunSummary s;
        s.scene_file = state.scene_file;
        s.status = status;
        s.message = message;
        s.snapshots = snapshots->series().count();
        s.output_seconds = snapshots->seconds();
        s.wall_seconds = wall_seconds;
        return s;
    }

    RunResult finished(double wall_seconds) {
        try {
            write_profile(folder->partial() / "profile.csv", *sim);
            write_summary(folder->partial() / "summary.json", *sim, summary("finished", sim->stop_reason(), wall_seconds));
            std::error_code ec;
            fs::remove(folder->partial() / checkpoint_name, ec);  // a finished run is not resumed
            folder->commit();
        } catch (const std::exception& e) {
            return failed(e.what(), nullptr, wall_seconds);
        }
        RunResult r;
        r.status = RunStatus::Finished;
        r.message = sim->stop_reason();
        r.folder = folder->final_path();
        r.wall_seconds = wall_seconds;
        return r;
    }

    RunResult interrupted(const StopRequest& stop, double wall_seconds) {
        RunResult r;
        r.status = RunStatus::Interrupted;
        r.stop_code = stop.code;
        r.message = fmt::format("stopped by {} after step {} at t = {:.6g} us", stop.by, sim->steps(), sim->time() * 1e6);
        r.folder = folder->partial();
        r.wall_seconds = wall_seconds;
        try {
            snapshots->wait();
            if (last_row != sim->steps()) write_row();
            snapshots->write_marked(*sim, fmt::format("interrupted_step{:07d}", sim->steps()),
                                    fmt::format("interrupted at step {}", sim->steps()));
            write_checkpoint(wall_seconds);
            write_summary(folder->partial() / "summary.json", *sim, summary("interrupted", r.message, wall_seconds));
        } catch (const std::exception& e) {
            r.problems = e.what();
        }
        r.resumable = fs::exists(folder->partial() / checkpoint_name);
        return r;
    }

    RunResult failed(const std::string& message, const FailureSite* site, double wall_seconds) {
        RunResult r;
        r.status = RunStatus::Failed;
        r.message = message;
        r.folder = folder->partial();
        r.wall_seconds = wall_seconds;
        if (site) r.failure = *site;
        try {
            snapshots->wait();
        } catch (const std::exception& e) {
            r.problems += fmt::format("; a snapshot could not be written either: {}", e.what());
        }
        try {
            if (last_row != sim->totals().step) write_row();
        } catch (const std::exception&) {
        }
        try {
            if (site) {
                // The failing step as it was when it failed, marked beside the scheduled ones.
                snapshots->write_marked(*sim, fmt::format("failed_step{:07d}", site->step), fmt::format("failed step {}", site->step));
            }
        } catch (const std::exception& e) {
            r.problems += fmt::format("; the snapshot of the failing step could not be written: {}", e.what());
        }
        try {
            auto s = summary("failed", message, wall_seconds);
            if (site) s.failure_json = failure_json(*site);
            write_summary(folder->partial() / "summary.json", *sim, s);
        } catch (const std::exception& e) {
            r.problems += fmt::format("; summary.json could not be written: {}", e.what());
        }
        // A failed step is not resumed (it would fail again); a failed output may be, from the
        // last checkpoint.
        r.resumable = !site && fs::exists(folder->partial() / checkpoint_name);
        return r;
    }
};

RunLoop::RunLoop(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

RunLoop::RunLoop(SceneSource source, RunSettings settings) : impl_(std::make_unique<Impl>()) {
    Impl& im = *impl_;
    im.settings = std::move(settings);
    im.source = std::move(source);
    if (im.settings.output.empty()) throw InputError("a run needs an output folder (RunSettings::output is empty)");
    Scene scene = parse_scene(im.source.text, im.source.name);
    im.resolve_files(scene, im.source.file);
    for (const std::string& odd : scene_warnings(scene)) im.warning(fmt::format("{}: {}", im.source.name, odd));
    im.sim.emplace(scene, im.settings.threads, im.settings.memory);  // before the folder: an impossible scene leaves nothing behind
    for (const auto& spec : scene.gauges) Gauge(spec, scene, im.sim->nodes(), im.sim->real_count());  // so is a gauge with no node
    im.folder.emplace(im.settings.output, im.settings.overwrite);
    im.state.scene_file = im.source.label;
    im.state.resolve_from = im.source.file.string();
    im.state.surfaces = surfaces_digest(scene);
    im.state.overwrite = im.settings.overwrite;
    im.prepare_outputs();
}

std::unique_ptr<RunLoop> RunLoop::resume(const fs::path& folder_path, std::optional<SceneSource> given, RunSettings settings) {
    auto im = std::make_unique<Impl>();
    im->settings = std::move(settings);
    im->folder.emplace(folder_path, false, RunFolder::Mode::Resume);
    const fs::path partial = im->folder->partial();
    const fs::path checkpoint = partial / checkpoint_name;
    if (!fs::exists(checkpoint)) {
        std::error_code ec;
        if (fs::is_empty(partial, ec)) throw OutputError(fmt::format("'{}' is empty: there is nothing to resume", partial.string()));
        throw OutputError(fmt::format("'{}' holds no checkpoint: the run stopped before it wrote one (output.checkpoint_every); "
                                      "start it again",
                                      partial.string()));
    }
    // The scene the run started with: its copy in the folder, or the scene given, which must be
    // the same.
    const fs::path copy = partial / scene_copy_name;
    im->source = given ? std::move(*given) : SceneSource{read_scene_text(copy), copy.string(), copy.string(), {}};
    const CheckpointInfo info = checkpoint_info(checkpoint);
    if (info.scene_fingerprint != scene_fingerprint(im->source.text)) {
        if (!given) {
            // The folder's own copy: the two files came from different runs.
            throw CheckpointError(fmt::format("'{}' and '{}' are not of the same run (the checkpoint was written for another scene): "
                                              "the stopped run cannot be continued from them (start it again with --overwrite)",
                                              checkpoint.string(), copy.string()));
        }
        throw CheckpointError(fmt::format("'{}' is not the scene the run in '{}' started with (its copy is '{}')", im->source.name,
                                          partial.string(), copy.string()));
    }
    Scene scene = parse_scene(im->source.text, im->source.name);
    // The files the scene names are relative to the scene file the run started from (the copy in
    // the folder has no such neighbours); one that is no longer there is reported at the end.
    const RunState started = decode(info.user_data, checkpoint.string());
    const fs::path original = given ? im->source.file
                                    : fs::path(started.resolve_from.empty() ? started.scene_file : started.resolve_from);
    // Bodies of shape "surface" or "nodes" cannot run without their STL or node files, found from
    // there too.
    const bool surfaces = std::any_of(scene.bodies.begin(), scene.bodies.end(), [](const BodySpec& b) {
        return b.shape == ShapeKind::Surface || b.shape == ShapeKind::Nodes;
    });
    std::error_code ec;
    const bool original_there = !original.empty() && fs::exists(original, ec);
    if (surfaces && !original_there) {
        throw InputError(fmt::format("{}: its bodies' STL or node files are found beside the scene file the run started from, '{}', which "
                                     "is not there: give that scene file with the folder to resume",
                                     partial.string(), original.string()));
    }
    if ((surfaces || !scene.element_reference.empty()) && original_there) {
        try {
            im->resolve_files(scene, original);
        } catch (const InputError& e) {
            if (surfaces) throw;
            im->warning(e.what());
        }
    }
    if (surfaces_digest(scene) != started.surfaces) {
        throw CheckpointError(fmt::format("the STL or node files of the imported bodies of '{}' are not those the run in '{}' started with "
                                          "(their contents changed): the stopped run cannot be continued from them (start it again "
                                          "with --overwrite)",
                                          original.string(), partial.string()));
    }
    im->sim.emplace(scene, im->settings.threads, im->settings.memory);
    im->state = decode(read_checkpoint(checkpoint, *im->sim, scene_fingerprint(im->source.text)), checkpoint.string());
    im->folder->set_overwrite(im->state.overwrite);
    im->resumed_at = info.step;
    im->prepare_outputs();
    return std::unique_ptr<RunLoop>(new RunLoop(std::move(im)));
}

RunLoop::~RunLoop() = default;

Simulation& RunLoop::simulation() { return *impl_->sim; }
const Simulation& RunLoop::simulation() const { return *impl_->sim; }
const Scene& RunLoop::scene() const { return impl_->sim->scene(); }
const fs::path& RunLoop::partial_folder() const { return impl_->folder->partial(); }
const fs::path& RunLoop::final_folder() const { return impl_->folder->final_path(); }
bool RunLoop::resumed() const { return impl_->resumed_at.has_value(); }
const std::vector<std::string>& RunLoop::warnings() const { return impl_->warnings; }
const std::string& RunLoop::checkpoint_data() const { return impl_->state.program_data; }

RunResult RunLoop::run(const RunHooks& hooks) {
    Impl& im = *impl_;
    if (im.ran) throw std::logic_error("RunLoop::run: a run loop runs once (make another for another run)");
    im.ran = true;
    if (im.resumed_at) {
        im.resume(*im.resumed_at);
    } else {
        try {
            im.start();
        } catch (...) {
            // Refused before the first step (the disk estimate, an unwritable folder): nothing is kept.
            im.snapshots.reset();
            std::error_code ec;
            fs::remove_all(im.folder->partial(), ec);
            throw;
        }
    }
    return im.run(hooks);
}

std::string run_report(const Simulation& sim) {
    std::string out;
    const auto& t = sim.totals();
    fmt::format_to(std::back_inserter(out), "  {} real nodes, {} steps, t = {:.4g} us ({})\n", t.real_nodes, t.step, t.time * 1e6, sim.stop_reason());
    if (t.elements > 0) fmt::format_to(std::back_inserter(out), "  {} elements, {} element nodes\n", t.elements, t.element_nodes);
    if (!t.planes.empty()) {
        if (sim.nodes().dim() == 3) {
            fmt::format_to(std::back_inserter(out), "  final length {:.4g} mm, footprint diameter {:.4g} mm (the mean width over {} directions, {:.4g} to {:.4g} mm)\n",
                       t.length * 1e3, t.footprint_diameter * 1e3, measure::footprint_directions, t.footprint_narrowest * 1e3,
                       t.footprint_widest * 1e3);
        } else {
            fmt::format_to(std::back_inserter(out), "  final length {:.4g} mm, footprint diameter {:.4g} mm\n", t.length * 1e3, t.footprint_diameter * 1e3);
        }
    }
    fmt::format_to(std::back_inserter(out), "  plastic work {:.4g} J, viscous work {:.4g} J, boundary work {:.3g} J, energy error {:+.3g} %\n",
               t.plastic_work, t.viscous_work, t.boundary_work, 100.0 * t.energy_error);
    for (std::size_t b = 0; b < sim.scene().bodies.size(); ++b) {
        if (const int copies = symmetry_copies(sim.scene(), b); copies > 1) {
            fmt::format_to(std::back_inserter(out), "  body \"{}\" is 1/{} of the whole (symmetry planes): its energies and masses are the model's, its length "
                       "and footprint the whole body's\n",
                       sim.scene().bodies[b].name, copies);
        }
    }
    const int dim = sim.nodes().dim();
    for (const auto& r : t.regions) {
        std::string reaction;
        for (int c = 0; c < dim; ++c) {
            if (r.held[c]) reaction += fmt::format(", reaction {} {:.4g} N", axis_letter(c, dim), r.reaction[c]);
        }
        fmt::format_to(std::back_inserter(out), "  prescribed velocity \"{}\": work {:.4g} J{}\n", r.name, r.work, reaction);
    }
    for (const auto& c : compare_with_reference(sim)) {
        fmt::format_to(std::back_inserter(out), "  {}: {:.4g} against the reference {:.4g} ({:+.2f} %)\n", c.key, c.computed, c.reference,
                   100.0 * c.relative_error);
    }
    if (t.local.measured && t.local.plastic_strain.has_peak()) {
        const auto& at = t.local.plastic_strain.position;
        const std::string where = dim == 3 ? fmt::format("(x, y, z) = ({:.3g}, {:.3g}, {:.3g}) mm", at[0] * 1e3, at[1] * 1e3, at[2] * 1e3)
                                           : fmt::format("(x, z) = ({:.3g}, {:.3g}) mm", at[0] * 1e3, at[1] * 1e3);
        fmt::format_to(std::back_inserter(out), "  peak plastic strain {:.4g} (mean within {:.3g} mm) at {}, largest single value {:.4g}; peak temperature {:.4g} K\n",
                   t.local.plastic_strain.value, t.local.radius * 1e3, where, t.local.plastic_strain.raw, t.local.temperature.value);
    }
    if (t.local.measured && t.local.plastic_strain.alone > 0) {
        // Nodes with no other point of their body within the radius (debris) have no neighbourhood
        // mean: left out of the peaks, counted in the largest single values.
        fmt::format_to(std::back_inserter(out), "  {} of {} material points alone within {:.3g} mm (debris): not in the peaks{}\n",
                       t.local.plastic_strain.alone, t.local.plastic_strain.points, t.local.radius * 1e3,
                       t.local.plastic_strain.has_peak() ? "" : fmt::format(" (none has a neighbourhood: no peak; largest single value {:.4g})",
                                                                            t.local.plastic_strain.raw));
    }
    if (!sim.scene().element_reference.empty()) {
        try {
            const auto ref = read_element_reference(sim.scene().element_reference);
            const auto ratios = compare_with_reference(run_metrics(sim), final_outline(sim), ref);
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
            fmt::format_to(std::back_inserter(out), "  against the element reference ({}): {}\n", sim.scene().element_reference, line);
        } catch (const InputError& e) {
            fmt::format_to(std::back_inserter(out), "  element reference: {}\n", e.what());
        }
    }
    return out;
}

}  // namespace gpa::io
