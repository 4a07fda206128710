#include "gpa/io/svg_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "gpa/io/atomic_file.hpp"

namespace gpa::io {

namespace {

// Panel geometry in SVG user units (pixels).
constexpr double panel_width = 380.0, panel_height = 330.0;
constexpr double margin_left = 66.0, margin_right = 18.0, margin_top = 38.0, margin_bottom = 62.0;
constexpr double title_height = 34.0;
constexpr int panels_per_row = 3;

// Colours that stay apart for common colour blindness, and markers that stay apart in grey.
constexpr const char* colours[] = {"#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#000000", "#999933"};
constexpr int colour_count = sizeof colours / sizeof colours[0];
constexpr int marker_count = 6;

std::string escaped(const std::string& text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

bool drawable(const PlotPoint& p) { return std::isfinite(p.x) && std::isfinite(p.y) && p.x > 0.0 && p.y > 0.0; }

// Whole decades [lo, hi] (as powers of ten) that hold every value; at least one decade wide.
struct Decades {
    int lo = 0, hi = 1;
};

Decades decades_of(double min, double max) {
    Decades d;
    d.lo = static_cast<int>(std::floor(std::log10(min) + 1e-12));
    d.hi = static_cast<int>(std::ceil(std::log10(max) - 1e-12));
    if (d.hi <= d.lo) d.hi = d.lo + 1;
    return d;
}

// A decade's label: plain decimals when every decade of the axis lies between 0.01 and 1000,
// otherwise 10 with a raised exponent (one style per axis, so that labels compare at a glance).
std::string decade_label(int k, const Decades& axis) {
    if (axis.lo >= -2 && axis.hi <= 3) {
        return k >= 0 ? fmt::format("{}", static_cast<long>(std::lround(std::pow(10.0, k)))) : fmt::format("{:.{}f}", std::pow(10.0, k), -k);
    }
    return fmt::format("10<tspan dy=\"-6\" font-size=\"9\">{}</tspan>", k);
}

std::string marker(int kind, double x, double y, const char* colour) {
    const double s = 4.0;
    switch (kind % marker_count) {
        case 0: return fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.1f}\" fill=\"{}\"/>", x, y, s, colour);
        case 1:
            return fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\"/>", x - s, y - s,
                               2 * s, 2 * s, colour);
        case 2:
            return fmt::format("<path d=\"M{:.2f},{:.2f} L{:.2f},{:.2f} L{:.2f},{:.2f} Z\" fill=\"{}\"/>", x, y - 1.2 * s,
                               x + 1.1 * s, y + 0.8 * s, x - 1.1 * s, y + 0.8 * s, colour);
        case 3:
            return fmt::format("<path d=\"M{:.2f},{:.2f} L{:.2f},{:.2f} L{:.2f},{:.2f} L{:.2f},{:.2f} Z\" fill=\"{}\"/>", x,
                               y - 1.3 * s, x + 1.3 * s, y, x, y + 1.3 * s, x - 1.3 * s, y, colour);
        case 4:
            return fmt::format("<path d=\"M{:.2f},{:.2f} L{:.2f},{:.2f} L{:.2f},{:.2f} Z\" fill=\"{}\"/>", x, y + 1.2 * s,
                               x + 1.1 * s, y - 0.8 * s, x - 1.1 * s, y - 0.8 * s, colour);
        default:
            return fmt::format("<path d=\"M{0:.2f},{1:.2f} L{2:.2f},{3:.2f} M{0:.2f},{3:.2f} L{2:.2f},{1:.2f}\" stroke=\"{4}\" "
                               "stroke-width=\"2\" fill=\"none\"/>",
                               x - s, y - s, x + s, y + s, colour);
    }
}

// One panel with its top-left corner at (x0, y0).
std::string panel_svg(const PlotPanel& panel, double x0, double y0) {
    std::string s;
    const double left = x0 + margin_left, top = y0 + margin_top;
    const double width = panel_width - margin_left - margin_right, height = panel_height - margin_top - margin_bottom;
    s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"13\" font-weight=\"bold\">{}</text>\n",
                     left + width / 2, y0 + 22, escaped(panel.title));
    s += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"none\" stroke=\"#444\"/>\n", left,
                     top, width, height);
    double x_min = INFINITY, x_max = 0.0, y_min = INFINITY, y_max = 0.0;
    for (const auto& series : panel.series) {
        for (const auto& p : series) {
            if (!drawable(p)) continue;
            x_min = std::min(x_min, p.x);
            x_max = std::max(x_max, p.x);
            y_min = std::min(y_min, p.y);
            y_max = std::max(y_max, p.y);
        }
    }
    const auto axis_label = [&] {
        s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"12\">{}</text>\n", left + width / 2,
                         top + height + 36, escaped(panel.x_label));
        s += fmt::format("<text x=\"{0:.1f}\" y=\"{1:.1f}\" text-anchor=\"middle\" font-size=\"12\" "
                         "transform=\"rotate(-90 {0:.1f} {1:.1f})\">{2}</text>\n",
                         x0 + 16, top + height / 2, escaped(panel.y_label));
        if (!panel.note.empty()) {
            s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"10\" fill=\"#555\">{}</text>\n",
                             left + width / 2, top + height + 52, escaped(panel.note));
        }
    };
    if (!(x_max > 0.0) || !(y_max > 0.0)) {
        s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"12\" fill=\"#555\">no points to "
                         "draw</text>\n",
                         left + width / 2, top + height / 2);
        axis_label();
        return s;
    }
    const Decades dx = decades_of(x_min, x_max), dy = decades_of(y_min, y_max);
    const auto px = [&](double x) { return left + (std::log10(x) - dx.lo) / (dx.hi - dx.lo) * width; };
    const auto py = [&](double y) { return top + height - (std::log10(y) - dy.lo) / (dy.hi - dy.lo) * height; };
    // Grid, ticks and labels: every decade labelled, the 2..9 multiples ticked while the axis
    // spans few enough decades for them to stay apart.
    for (int k = dx.lo; k <= dx.hi; ++k) {
        const double x = px(std::pow(10.0, k));
        s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.1f}\" x2=\"{0:.2f}\" y2=\"{2:.1f}\" stroke=\"#ddd\"/>\n", x, top, top + height);
        s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.1f}\" x2=\"{0:.2f}\" y2=\"{2:.1f}\" stroke=\"#444\"/>\n", x, top + height,
                         top + height + 6);
        s += fmt::format("<text x=\"{:.2f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"11\">{}</text>\n", x,
                         top + height + 19, decade_label(k, dx));
        if (k < dx.hi && dx.hi - dx.lo <= 6) {
            for (int m = 2; m <= 9; ++m) {
                const double xm = px(m * std::pow(10.0, k));
                s += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.1f}\" x2=\"{0:.2f}\" y2=\"{2:.1f}\" stroke=\"#444\"/>\n", xm,
                                 top + height, top + height + 3);
            }
        }
    }
    for (int k = dy.lo; k <= dy.hi; ++k) {
        const double y = py(std::pow(10.0, k));
        s += fmt::format("<line x1=\"{1:.1f}\" y1=\"{0:.2f}\" x2=\"{2:.1f}\" y2=\"{0:.2f}\" stroke=\"#ddd\"/>\n", y, left, left + width);
        s += fmt::format("<line x1=\"{1:.1f}\" y1=\"{0:.2f}\" x2=\"{2:.1f}\" y2=\"{0:.2f}\" stroke=\"#444\"/>\n", y, left - 6, left);
        s += fmt::format("<text x=\"{:.1f}\" y=\"{:.2f}\" text-anchor=\"end\" font-size=\"11\">{}</text>\n", left - 9, y + 4,
                         decade_label(k, dy));
        if (k < dy.hi && dy.hi - dy.lo <= 6) {
            for (int m = 2; m <= 9; ++m) {
                const double ym = py(m * std::pow(10.0, k));
                s += fmt::format("<line x1=\"{1:.1f}\" y1=\"{0:.2f}\" x2=\"{2:.1f}\" y2=\"{0:.2f}\" stroke=\"#444\"/>\n", ym,
                                 left - 3, left);
            }
        }
    }
    for (std::size_t k = 0; k < panel.series.size(); ++k) {
        const char* colour = colours[k % colour_count];
        std::string line;
        for (const auto& p : panel.series[k]) {
            if (drawable(p)) line += fmt::format("{}{:.2f},{:.2f}", line.empty() ? "" : " ", px(p.x), py(p.y));
        }
        if (line.empty()) continue;
        s += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.6\"/>\n", line, colour);
        for (const auto& p : panel.series[k]) {
            if (!drawable(p)) continue;
            s += "<g>" + marker(static_cast<int>(k), px(p.x), py(p.y), colour);
            if (!p.tip.empty()) s += "<title>" + escaped(p.tip) + "</title>";
            s += "</g>\n";
        }
    }
    axis_label();
    return s;
}

}  // namespace

std::string loglog_svg(const LogLogFigure& figure) {
    const int count = std::max<int>(1, static_cast<int>(figure.panels.size()));
    const int columns = std::min(count, panels_per_row);
    const int rows = (count + columns - 1) / columns;
    std::size_t longest = 0;
    for (const auto& l : figure.legend) longest = std::max(longest, l.size());
    const double legend_width = figure.legend.empty() ? 0.0 : 40.0 + 6.8 * double(longest);
    const double width = columns * panel_width + legend_width + 10.0;
    const double height = title_height + rows * panel_height + 10.0;
    std::string s = fmt::format(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0:.0f}\" height=\"{1:.0f}\" viewBox=\"0 0 {0:.0f} {1:.0f}\" "
        "font-family=\"Helvetica, Arial, sans-serif\">\n"
        "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n",
        width, height);
    s += fmt::format("<text x=\"{:.1f}\" y=\"22\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">{}</text>\n",
                     columns * panel_width / 2, escaped(figure.title));
    for (std::size_t p = 0; p < figure.panels.size(); ++p) {
        const double x0 = double(p % columns) * panel_width, y0 = title_height + double(p / columns) * panel_height;
        s += panel_svg(figure.panels[p], x0, y0);
    }
    const double lx = columns * panel_width + 4.0, ly = title_height + margin_top;
    for (std::size_t k = 0; k < figure.legend.size(); ++k) {
        const double y = ly + 10.0 + 20.0 * double(k);
        const char* colour = colours[k % colour_count];
        s += fmt::format("<line x1=\"{:.1f}\" y1=\"{:.1f}\" x2=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"{}\" stroke-width=\"1.6\"/>\n", lx,
                         y, lx + 24, y, colour);
        s += marker(static_cast<int>(k), lx + 12, y, colour) + "\n";
        s += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" font-size=\"12\">{}</text>\n", lx + 30, y + 4, escaped(figure.legend[k]));
    }
    s += "</svg>\n";
    return s;
}

void write_loglog_svg(const std::filesystem::path& file, const LogLogFigure& figure) {
    write_text_file(file, loglog_svg(figure));
}

}  // namespace gpa::io
