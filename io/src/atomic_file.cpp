#include "gpa/io/atomic_file.hpp"

#include <system_error>

#include <fmt/format.h>

namespace gpa::io {

void write_file_atomically(const std::filesystem::path& file, const std::function<void(std::ofstream&)>& body) {
    auto tmp = file;
    tmp += ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw OutputError(fmt::format("cannot open '{}' for writing", tmp.string()));
        body(out);
        out.flush();
        if (!out) throw OutputError(fmt::format("writing '{}' failed (disk full?)", tmp.string()));
    }
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);
    if (ec) throw OutputError(fmt::format("cannot rename '{}' to '{}': {}", tmp.string(), file.string(), ec.message()));
}

void write_text_file(const std::filesystem::path& file, std::string_view text) {
    write_file_atomically(file, [text](std::ofstream& out) { out << text; });
}

}  // namespace gpa::io
