#pragma once
// Reading snapshots back: the .pvd time series of a run folder and the VTK XML files it lists
// (.vtp particles, .vtu element bodies), as gpa writes them (vtk.hpp) and as ParaView saves them
// uncompressed: appended raw or base64 data, inline base64 ("binary") or ascii arrays, UInt32 or
// UInt64 block headers, either byte order, integer and floating-point arrays of any width.
// Compressed files are refused with a message that says so.
//
// Every error is a SnapshotError whose message names the file and what is wrong with it.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpa/engine/errors.hpp"
#include "gpa/engine/geometry.hpp"

namespace gpa::io {

class SnapshotError : public InputError {
public:
    using InputError::InputError;
};

// One time step of a .pvd: the files of its parts (0, 1, ...), as paths next to the .pvd.
struct SeriesSnapshot {
    double time = 0.0;
    std::vector<std::filesystem::path> files;
    std::string mark;  // the DataSet's name attribute ("failed step 27"), empty for a scheduled snapshot
};

struct SnapshotIndex {
    std::filesystem::path pvd;
    std::vector<SeriesSnapshot> snapshots;  // in the order the .pvd lists them
};

// Reads a .pvd collection. A DataSet of part 0 (or without a part) starts a new snapshot, a later
// part joins the one before it when its time step is the same. Throws SnapshotError for a missing
// or unreadable file, text that is not a VTK Collection, a DataSet without a file or with a time
// step that is not a number, and a collection without DataSets. The listed files are not opened.
SnapshotIndex read_pvd(const std::filesystem::path& pvd);

// The .pvd of a run folder: particles.pvd, or else the only .pvd in it. A path to a .pvd file is
// returned as it is. Throws SnapshotError when the folder does not exist (naming DIR.partial if
// that is there instead), holds no .pvd, or holds several and none is particles.pvd.
std::filesystem::path find_pvd(const std::filesystem::path& run_folder_or_pvd);

enum class DataLocation { Point, Cell };

struct VtkArrayInfo {
    std::string name;
    int components = 1;
    DataLocation location = DataLocation::Point;
};

// The cells of an UnstructuredGrid: cell c has the points connectivity[offsets[c-1] .. offsets[c])
// (offsets[-1] = 0) and the VTK type types[c] (5 triangle, 7 polygon, 9 quadrilateral, ...).
struct VtkCells {
    std::vector<std::int64_t> connectivity;
    std::vector<std::int64_t> offsets;
    std::vector<std::uint8_t> types;
};

// A VTK XML PolyData (.vtp) or UnstructuredGrid (.vtu) file of one piece. The constructor reads
// the file and checks its header and the place and size of every array; values are decoded on
// request.
class VtkFile {
public:
    explicit VtkFile(std::filesystem::path path);
    // The same from the bytes of a file held in memory; `name` stands for the file in messages.
    VtkFile(std::filesystem::path name, std::string bytes);
    ~VtkFile();
    VtkFile(const VtkFile&);
    VtkFile(VtkFile&&) noexcept;
    VtkFile& operator=(const VtkFile&);
    VtkFile& operator=(VtkFile&&) noexcept;

    const std::filesystem::path& path() const { return path_; }
    const std::string& type() const { return type_; }  // "PolyData" or "UnstructuredGrid"
    std::size_t point_count() const { return points_; }
    std::size_t cell_count() const { return cells_; }  // UnstructuredGrid cells (0 for PolyData)

    // The point and cell data arrays, in the order of the file.
    const std::vector<VtkArrayInfo>& arrays() const { return infos_; }
    const VtkArrayInfo* find(std::string_view name, DataLocation location) const;

    // An array's values, components of one point or cell next to each other (count x components).
    std::vector<double> values(std::string_view name, DataLocation location) const;
    // Point coordinates, three per point.
    std::vector<double> points() const;
    // UnstructuredGrid cells, checked: offsets rise, end at the connectivity's size, and every
    // index names a point. Empty for PolyData.
    VtkCells cells() const;

    struct ArrayRef;  // where an array's values are in the file (snapshot_reader.cpp)

private:
    std::vector<double> decode(const ArrayRef& a, std::size_t tuples) const;
    std::vector<std::int64_t> decode_integers(const ArrayRef& a, std::size_t tuples) const;
    std::vector<unsigned char> block(const ArrayRef& a, std::size_t tuples, std::size_t width) const;
    void parse();
    const ArrayRef& array(std::string_view name, DataLocation location) const;

    std::filesystem::path path_;
    std::string bytes_;
    std::string type_;
    std::size_t points_ = 0, cells_ = 0;
    bool big_endian_ = false;
    std::size_t header_bytes_ = 4;  // of each binary block's length (UInt32 or UInt64)
    std::string appended_encoding_;
    std::size_t appended_start_ = 0;  // first byte after the '_' of <AppendedData>
    std::vector<ArrayRef> refs_;      // point data, cell data, then Points and Cells arrays
    std::vector<VtkArrayInfo> infos_;
};

// The geometry of a run folder and where it was learnt: its scene.toml (the scene the run
// started with), else summary.json; nullopt when neither names one. Throws SnapshotError when
// scene.toml is there but names no geometry gpa knows.
struct RunGeometry {
    GeometryKind geometry = GeometryKind::Axisymmetric;
    std::string source;  // "scene.toml", "summary.json"
};
std::optional<RunGeometry> read_run_geometry(const std::filesystem::path& run_folder);

}  // namespace gpa::io
