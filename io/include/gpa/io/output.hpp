#pragma once
// What a run leaves in its output folder: ParaView snapshots with a time-series index, a CSV
// history of global quantities, and a JSON summary. The folder is written as DIR.partial and
// renamed to DIR when the run ends, so that a folder named DIR is always a finished run.

#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gpa/engine/simulation.hpp"
#include "gpa/io/atomic_file.hpp"
#include "gpa/io/vtk.hpp"

namespace gpa::io {

class RunFolder {
public:
    // Refuses an existing, non-empty `folder` unless overwrite is set (OutputError naming it);
    // clears a stale `folder.partial` left by an earlier failed run and creates a fresh one.
    RunFolder(std::filesystem::path folder, bool overwrite);
    const std::filesystem::path& partial() const { return partial_; }
    const std::filesystem::path& final_path() const { return final_; }
    // Renames folder.partial to folder (replacing an old folder only now, when overwriting).
    void commit();

private:
    std::filesystem::path final_, partial_;
    bool overwrite_;
};

// history.csv: one row per call, with a header naming every column and its unit.
class HistoryWriter {
public:
    HistoryWriter(const std::filesystem::path& file, const Totals& first, int dim);
    ~HistoryWriter();
    HistoryWriter(const HistoryWriter&) = delete;
    HistoryWriter& operator=(const HistoryWriter&) = delete;
    void write(const Totals& t);

private:
    std::FILE* file_ = nullptr;
    std::filesystem::path path_;
    int dim_;
    std::size_t planes_;
};

// particles_NNNNN.vtp and particles.pvd in a folder; the index is rewritten after every
// snapshot so that it always lists the snapshots on disk.
class SnapshotSeries {
public:
    explicit SnapshotSeries(std::filesystem::path folder, std::string stem = "particles");
    // Writes nodes [0, count) at time t; returns the file name.
    std::string write(const NodeStore& nodes, std::size_t count, double time);
    std::size_t count() const { return entries_.size(); }

private:
    std::filesystem::path folder_;
    std::string stem_;
    std::vector<PvdEntry> entries_;
};

// The summary of a finished (or failed) run.
struct RunSummary {
    std::string scene_file;
    std::string status = "finished";  // "finished" or "failed"
    std::string message;              // the stop reason, or the error
    double wall_seconds = 0.0;
    double output_seconds = 0.0;
    std::size_t snapshots = 0;
};

// summary.json: the scene's name and geometry, the final totals (lengths, energies, energy
// balance), the reference answers of the scene beside the run's values with their errors, node
// and step counts, threads, wall time per phase, and node-steps per second.
void write_summary(const std::filesystem::path& file, const Simulation& sim, const RunSummary& run);

// profile.csv: the outline of the bodies seen from the first rigid plane, for comparing a
// Taylor specimen with its measured outline: for bins of height above the plane (one mean node
// diameter wide), the largest radial extent plus d/2 (axisymmetric: the radius x; otherwise the
// distance from the vertical through the nodes' centroid). Heights and radii in m. Does nothing
// without a rigid plane.
void write_profile(const std::filesystem::path& file, const Simulation& sim);

// The scene's reference answers compared with the run: key -> {reference, computed, relative error}.
struct ReferenceComparison {
    std::string key;
    double reference = 0.0, computed = 0.0, relative_error = 0.0;
};
std::vector<ReferenceComparison> compare_with_reference(const Simulation& sim);

}  // namespace gpa::io
