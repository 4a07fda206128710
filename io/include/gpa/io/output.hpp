#pragma once
// What a run leaves in its output folder: ParaView snapshots with a time-series index, a CSV
// history of global quantities, and a JSON summary. The folder is written as DIR.partial and
// renamed to DIR when the run ends, so that a folder named DIR is always a finished run.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/gauges.hpp"
#include "gpa/engine/simulation.hpp"
#include "gpa/io/atomic_file.hpp"
#include "gpa/io/folder_lock.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::io {

// The checkpoint a stopped run leaves in its folder.partial: while it is there, the run can be
// resumed (gpa run --resume).
inline constexpr const char* checkpoint_file_name = "checkpoint.gpack";

class RunFolder {
public:
    // Fresh: refuses an existing, non-empty `folder` unless overwrite is set (OutputError naming
    // it); clears a stale `folder.partial` left by an earlier failed run and creates a fresh one.
    // A `folder.partial` that holds a checkpoint (a run that can be resumed) is cleared only
    // when overwrite is set; otherwise OutputError naming --resume and --overwrite, and the
    // folder is left as it is.
    // Resume: `folder` (or `folder.partial`) names a run that was stopped; its folder.partial
    // must exist and is kept as it is.
    // Either way the folder's lock (folder.lock, FolderLock) is taken first and held until the
    // RunFolder is destroyed: a second run on the same folder is refused before it touches it.
    enum class Mode { Fresh, Resume };
    RunFolder(std::filesystem::path folder, bool overwrite, Mode mode = Mode::Fresh);
    const std::filesystem::path& partial() const { return partial_; }
    const std::filesystem::path& final_path() const { return final_; }
    // Renames folder.partial to folder (replacing an old folder only now, when overwriting).
    void commit();
    // Whether commit() may replace an existing folder (a resumed run takes it from its checkpoint).
    void set_overwrite(bool overwrite) { overwrite_ = overwrite; }

private:
    std::filesystem::path final_, partial_;
    bool overwrite_;
    std::optional<FolderLock> lock_;
};

// A CSV file written a row at a time, each row reaching the file whole or not at all: a write
// that fails (disk full) is cut back to the rows before it and reported as OutputError, so the
// file always ends with a complete line. history.csv and the gauges' files are such files.
class RowFile {
public:
    // How far the file had got when a checkpoint was written: its length and the digest of those
    // bytes (bytes == 0: not recorded, as in checkpoints written before it was).
    struct Mark {
        long long bytes = 0;
        std::uint64_t digest = 0;
    };
    // A fresh file holding `header` (a whole line).
    RowFile(const std::filesystem::path& file, const std::string& header);
    // A resumed run: the file rewritten (atomically) to `kept` (kept_for_resume), and appended to.
    RowFile(const std::filesystem::path& file, const std::string& kept, bool resumed);
    // For a resumed run from a checkpoint at step `last_step`, what of the file it keeps: the file
    // as it was at the checkpoint (its first at.bytes bytes, which must have the recorded digest;
    // what follows goes) with the rows of steps 0, every, 2 every, ... up to last_step, which must
    // all be there (a row's step is its column `step_column`, counted from 0). Reads the file and
    // changes nothing: OutputError naming the file (and `checkpoint`) when it is missing, its
    // header is not `header`, it is shorter than at the checkpoint, it differs from the one the
    // checkpoint recorded, or a row is missing.
    static std::string kept_for_resume(const std::filesystem::path& file, const std::string& header, std::size_t step_column,
                                       std::size_t last_step, std::size_t every, Mark at, const std::string& checkpoint);
    ~RowFile();
    RowFile(const RowFile&) = delete;
    RowFile& operator=(const RowFile&) = delete;
    // Appends whole lines.
    void append(const std::string& text);
    // The file as it is now (for the checkpoint).
    Mark mark() const { return {size_, digest_}; }

private:
    int fd_ = -1;
    long long size_ = 0;  // bytes of whole lines in the file
    std::uint64_t digest_ = 14695981039346656037ull;  // history_digest of those bytes (of none so far)
    std::filesystem::path path_;
};

// Which columns history.csv gives a scene.
struct HistoryLayout {
    int dim = 2;             // components of vectors (x, z or x, y, z)
    bool per_metre = false;  // plane strain: energies, momenta, forces and impulses per metre of thickness (unit suffix _per_m)
    bool specimen = true;    // a rigid plane to measure a specimen on: length, footprint, base height, face roughness
    static HistoryLayout of(const Scene& scene);
};

// history.csv: one row per call, with a header naming every column and its unit (a column without
// a unit is a count, a strain or a flag). total_energy_error_percent is the energy balance's
// error in per cent, as the console prints it.
class HistoryWriter {
public:
    using Mark = RowFile::Mark;
    HistoryWriter(const std::filesystem::path& file, const Totals& first, const HistoryLayout& layout);
    // RowFile::kept_for_resume for history.csv as this run writes it.
    static std::string kept_for_resume(const std::filesystem::path& file, const Totals& first, const HistoryLayout& layout,
                                       std::size_t last_step, std::size_t every, Mark at, const std::string& checkpoint);
    // A resumed run: the file rewritten (atomically) to `kept` (kept_for_resume), and appended to.
    HistoryWriter(const std::filesystem::path& file, const Totals& first, const HistoryLayout& layout, const std::string& kept);
    void write(const Totals& t);
    // The file as it is now (for the checkpoint).
    Mark mark() const { return file_.mark(); }

private:
    RowFile file_;
    HistoryLayout layout_;
    std::size_t planes_;
    std::vector<bool> friction_;  // per plane: it has friction (a friction-work column)
    std::vector<std::array<bool, 3>> regions_;  // the held components of each prescribed-velocity region
};

// The gauges of a run (gauges.hpp), each written to gauge_<name>.csv in the run's folder: a row
// per call, time_s, step, then the gauge's columns (Gauge::columns), on the history's schedule.
class GaugeWriter {
public:
    using Mark = RowFile::Mark;
    // Places the scene's gauges on the run's nodes and starts their files; nothing without gauges.
    GaugeWriter(const std::filesystem::path& folder, const Simulation& sim);
    // A resumed run: each file cut back to its checkpoint's mark (RowFile::kept_for_resume; the
    // marks in the scene's gauge order), checked for every gauge before any file changes.
    GaugeWriter(const std::filesystem::path& folder, const Simulation& sim, std::size_t last_step, std::size_t every,
                const std::vector<Mark>& at, const std::string& checkpoint);
    void write(const Simulation& sim);
    std::vector<Mark> marks() const;
    std::size_t size() const { return gauges_.size(); }
    // The file name of a gauge.
    static std::string file_name(const std::string& gauge) { return "gauge_" + gauge + ".csv"; }

private:
    std::vector<Gauge> gauges_;
    std::vector<std::unique_ptr<RowFile>> files_;
};

// The digest a history Mark records (64-bit FNV-1a), carried on from `digest` over `bytes`;
// history_digest({}) is the digest of nothing.
std::uint64_t history_digest(std::string_view bytes, std::uint64_t digest = 14695981039346656037ull);

// What one snapshot shows, copied out of a run so that it can be written while the run goes on:
// the real particle nodes and the element bodies.
struct Snapshot {
    double time = 0.0;
    NodeStore particles{GeometryKind::Axisymmetric};
    std::optional<ElementMesh> elements;
};
Snapshot take_snapshot(const Simulation& sim);

// particles_NNNNN.vtp (particle bodies), elements_NNNNN.vtu (element bodies) and particles.pvd,
// the time series of both, in a folder; the index is rewritten after every snapshot so that it
// always lists the snapshots on disk.
class SnapshotSeries {
public:
    // `format`: the arrays and float width of every file (the scene's [output] fields and precision).
    explicit SnapshotSeries(std::filesystem::path folder, std::string stem = "particles",
                            SnapshotFormat format = {default_snapshot_fields(), SnapshotPrecision::Float64});
    // Writes the snapshot's particles (if any) and element bodies (if any) as the parts of the next
    // scheduled time step (particles_NNNNN.vtp, elements_NNNNN.vtu); returns the file names.
    std::vector<std::string> write(const Snapshot& snapshot);
    // Particle nodes [0, count) alone at time t as the next scheduled step; returns the file name.
    std::string write(const NodeStore& nodes, std::size_t count, double time);
    // A snapshot outside the schedule, <stem>_<label>.vtp and elements_<label>.vtu, marked `mark`
    // in the .pvd (e.g. label "failed_step00027", mark "failed step 27").
    std::vector<std::string> write_marked(const Snapshot& snapshot, const std::string& label, const std::string& mark);
    std::size_t count() const { return entries_.size(); }  // files listed in the .pvd
    std::size_t scheduled() const { return scheduled_; }   // scheduled time steps written
    const std::vector<PvdEntry>& entries() const { return entries_; }
    // A resumed run carries on a series: its entries so far, `scheduled` time steps of them on the
    // schedule (the .pvd is rewritten to list exactly these).
    void restore(std::vector<PvdEntry> entries, std::size_t scheduled);

private:
    std::vector<std::string> write_parts(const Snapshot& snapshot, const std::string& suffix, const std::string& mark);
    std::filesystem::path folder_;
    std::string stem_;
    SnapshotFormat format_;
    std::vector<PvdEntry> entries_;
    std::size_t scheduled_ = 0;
};

// The summary of a finished (or failed) run.
struct RunSummary {
    std::string scene_file;
    std::string status = "finished";  // "finished", "failed" or "interrupted"
    std::string message;              // the stop reason, or the error
    std::string failure_json;         // a failed step: {"step": ..., "phase": ..., ...} (a JSON object), or empty
    double wall_seconds = 0.0;
    double output_seconds = 0.0;
    std::size_t snapshots = 0;
};

// summary.json: the scene's name and geometry, the final totals (lengths, energies, energy
// balance), the reference answers of the scene beside the run's values with their errors, node
// and step counts, threads, wall time per phase, and node-steps per second.
void write_summary(const std::filesystem::path& file, const Simulation& sim, const RunSummary& run);

// profile.csv: the outline of the bodies seen from the first rigid plane, for comparing a
// Taylor specimen with its measured outline (axisymmetric: radius x; otherwise the distance from
// the vertical through the nodes' centroid), by the rules of measure.hpp. Particle bodies: for
// bins of height above the plane (one mean node diameter wide), the largest radial extent plus
// d/2. Element bodies: the outline of the mesh's boundary, the largest radius of the boundary
// edges at each boundary node's height. Both end with (top, 0). Heights and radii in m. Does
// nothing without a rigid plane.
void write_profile(const std::filesystem::path& file, const Simulation& sim);

// The scene's reference answers compared with the run: key -> {reference, computed, relative error}.
struct ReferenceComparison {
    std::string key;
    double reference = 0.0, computed = 0.0, relative_error = 0.0;
};
std::vector<ReferenceComparison> compare_with_reference(const Simulation& sim);

// The metrics of a run that a reference may state: plastic_work; final_length and
// footprint_diameter when the scene has a rigid plane to measure them on; peak_plastic_strain and
// peak_temperature once measure_bodies() has measured them.
std::map<std::string, double> run_metrics(const Simulation& sim);

// The summary's "element_reference" object (JSON) when the scene names an element reference: for
// each of its metrics the reference, the computed value and their ratio (L*, D*, PW*, ...), and the
// outline distance; empty when the scene names none.
std::string element_reference_json(const Simulation& sim);

}  // namespace gpa::io
