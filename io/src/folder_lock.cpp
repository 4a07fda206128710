#include "gpa/io/folder_lock.hpp"

#include <cerrno>
#include <cstring>
#include <string>

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gpa/io/atomic_file.hpp"

namespace gpa::io {

namespace {

std::string holder_of(int fd) {
    char buffer[32] = {};
    const ssize_t n = ::pread(fd, buffer, sizeof buffer - 1, 0);
    std::string pid = n > 0 ? std::string(buffer, static_cast<std::size_t>(n)) : std::string();
    while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
    return pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos ? "another process"
                                                                                  : "process " + pid;
}

}  // namespace

FolderLock::FolderLock(const std::filesystem::path& folder) {
    auto base = folder;
    if (base.filename().empty()) base = base.parent_path();  // "out/" -> "out"
    file_ = base;
    file_ += ".lock";
    if (!file_.parent_path().empty()) {
        std::error_code ec;
        std::filesystem::create_directories(file_.parent_path(), ec);
    }
    for (int attempt = 0; attempt < 100; ++attempt) {
        const int fd = ::open(file_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (fd < 0) throw OutputError(fmt::format("cannot create the lock file '{}': {}", file_.string(), std::strerror(errno)));
        if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
            const int error = errno;
            const std::string holder = holder_of(fd);
            ::close(fd);
            if (error == EWOULDBLOCK) {
                throw OutputError(fmt::format("output folder '{}' is in use by another gpa run ({}, lock file '{}'); "
                                              "wait for it to end or choose another folder with -o",
                                              base.string(), holder, file_.string()));
            }
            throw OutputError(fmt::format("cannot lock '{}': {}", file_.string(), std::strerror(error)));
        }
        // The run that held the lock before may have removed the file between our open and our
        // lock: then we hold a lock on a file no one else sees, and must take the new one.
        struct stat mine {}, named {};
        if (::fstat(fd, &mine) == 0 && ::stat(file_.c_str(), &named) == 0 && mine.st_dev == named.st_dev &&
            mine.st_ino == named.st_ino) {
            const std::string pid = fmt::format("{}\n", ::getpid());
            if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
                // The lock holds without the process id; only the message of a refused run misses it.
            }
            fd_ = fd;
            return;
        }
        ::close(fd);
    }
    throw OutputError(fmt::format("cannot lock '{}': it keeps being replaced", file_.string()));
}

FolderLock::FolderLock(FolderLock&& other) noexcept : file_(std::move(other.file_)), fd_(other.fd_) { other.fd_ = -1; }

FolderLock::~FolderLock() {
    if (fd_ < 0) return;
    // Removed while still locked, so that no one can lock this file after us and believe it
    // owns the folder (a taker that opened it before the removal sees that it is gone).
    ::unlink(file_.c_str());
    ::close(fd_);
}

}  // namespace gpa::io
