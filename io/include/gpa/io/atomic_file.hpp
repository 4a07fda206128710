#pragma once
// Files that are either the old version or the whole new one: written to FILE.tmp, then renamed.

#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string_view>

namespace gpa::io {

// A file or folder of a run's output could not be written.
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Opens file.tmp (binary, truncated), lets `body` write into it, and renames it to `file`.
// Throws OutputError naming the file when opening, writing or renaming fails.
void write_file_atomically(const std::filesystem::path& file, const std::function<void(std::ofstream&)>& body);

// write_file_atomically with `text` as the whole content.
void write_text_file(const std::filesystem::path& file, std::string_view text);

}  // namespace gpa::io
