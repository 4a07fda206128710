#pragma once
// Log-log line plots written as SVG text, without a plotting library: one or more panels side by
// side, each with decade ticks and labels on both axes, one polyline with markers per series,
// and a legend shared by the panels (series k has the same colour and marker in every panel).

#include <filesystem>
#include <string>
#include <vector>

namespace gpa::io {

struct PlotPoint {
    double x = 0.0, y = 0.0;
    std::string tip;  // shown when the pointer rests on the marker (an SVG <title>); may be empty
};

struct PlotPanel {
    std::string title;
    std::string x_label, y_label;
    // series[k] belongs to legend entry k; points are joined in the order given. Points with a
    // coordinate that is not finite and positive cannot be drawn on log axes and are left out.
    std::vector<std::vector<PlotPoint>> series;
    std::string note;  // a line under the panel (e.g. which series have no points)
};

struct LogLogFigure {
    std::string title;
    std::vector<std::string> legend;
    std::vector<PlotPanel> panels;
};

// The figure as a complete SVG document.
std::string loglog_svg(const LogLogFigure& figure);

// Writes loglog_svg(figure) to `file` (through a temporary name); throws OutputError.
void write_loglog_svg(const std::filesystem::path& file, const LogLogFigure& figure);

}  // namespace gpa::io
