#include "gpa/io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <string>
#include <system_error>

#include <fmt/format.h>

namespace gpa::io {

void write_file_atomically(const std::filesystem::path& file, const std::function<void(std::ofstream&)>& body) {
    auto tmp = file;
    tmp += ".tmp";
    // Whatever fails (opening, writing, the body itself, closing, renaming), FILE.tmp goes.
    const auto discard = [&] {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);
    };
    const auto reason = [] { return errno != 0 ? std::string(std::strerror(errno)) : std::string("the disk may be full"); };
    try {
        errno = 0;
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) throw OutputError(fmt::format("cannot open '{}' for writing: {}", tmp.string(), reason()));
        errno = 0;
        body(out);
        out.flush();
        if (!out) throw OutputError(fmt::format("writing '{}' failed: {}", file.string(), reason()));
        out.close();
        if (!out) throw OutputError(fmt::format("writing '{}' failed when closing it: {}", file.string(), reason()));
    } catch (...) {
        discard();
        throw;
    }
    std::error_code ec;
    std::filesystem::rename(tmp, file, ec);
    if (ec) {
        discard();
        throw OutputError(fmt::format("cannot rename '{}' to '{}': {}", tmp.string(), file.string(), ec.message()));
    }
}

void write_text_file(const std::filesystem::path& file, std::string_view text) {
    write_file_atomically(file, [text](std::ofstream& out) { out << text; });
}

}  // namespace gpa::io
