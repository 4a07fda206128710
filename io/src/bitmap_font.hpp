#pragma once
// Private to io/: a bitmap font of the printable ASCII characters drawn for gpa, 5 x 9 pixels
// (capitals and digits 7 high above the baseline, 2 rows of descenders), and text drawn with it
// into an RGB image at a whole-number scale.

#include <cstdint>
#include <string_view>

namespace gpa::io::detail {

inline constexpr int glyph_width = 5, glyph_height = 9;
inline constexpr int glyph_advance = glyph_width + 1;  // one column between characters
inline constexpr int line_height = glyph_height + 3;   // rows from one line of text to the next

// Whether pixel (column, row) of character c is set; characters outside ' '..'~' draw as '?'.
bool glyph_pixel(char c, int column, int row);

// Width and height in pixels of `text` on one line at `scale`.
inline int text_width(std::string_view text, int scale) {
    return text.empty() ? 0 : static_cast<int>(text.size()) * glyph_advance * scale - scale;
}
inline int text_height(int scale) { return glyph_height * scale; }

}  // namespace gpa::io::detail
