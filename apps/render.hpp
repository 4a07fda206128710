#pragma once
// The `gpa render` command: a PNG picture of one snapshot of a run folder coloured by a field
// (gpa/io/render.hpp draws it), or with --list the snapshots and fields there are.

#include <filesystem>
#include <optional>
#include <string>

namespace gpa::app {

struct RenderCommandOptions {
    std::filesystem::path run;     // a run's output folder, or its .pvd
    std::string field = "velocity";
    std::optional<std::filesystem::path> output;  // none: <run>/<field>-<snapshot label>.png
    std::string snapshot;          // "N", "last" or "" (the last)
    std::string time;              // "40 us", "4e-5": the snapshot nearest to it
    std::string size;              // "WxH", as typed
    std::optional<int> width;      // --width; none: the default
    std::string range;             // "MIN:MAX", either side may be empty (the field's own)
    bool mirror = false, no_mirror = false;
    std::string view;              // 3D: "+y", "-z", ...
    std::string region;            // "LEFT:RIGHT,BOTTOM:TOP", lengths with units or plain metres
    std::string frame = "snapshot";  // "snapshot": fitted to the snapshot; "run": one frame for every snapshot
    bool no_failed_marks = false;  // no black dot on failed nodes
    std::string geometry;          // override: axisymmetric, plane-strain, 3d
    bool list = false;
    bool quiet = false;
};

// Returns the exit code: 0 written (or listed). Bad options, a folder or file that cannot be
// read, an unknown field throw gpa::InputError (exit 2 in main); a picture that cannot be
// written throws gpa::io::OutputError.
int render_run(const RenderCommandOptions& options);

}  // namespace gpa::app
