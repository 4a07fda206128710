#pragma once
// One run per output folder: a lock on DIR.lock, beside the folder, held for as long as a run
// (or study) writes DIR.partial and renames it to DIR. The lock file holds the owner's process
// id. The lock is the kernel's (flock), so it goes with its process however that ends (kill -9
// included) and a lock file left behind is taken over; the file is never removed while its lock
// is held, and a taker checks that the file it locked is still the one at DIR.lock.

#include <filesystem>

namespace gpa::io {

class FolderLock {
public:
    // Takes the lock of `folder` at once or throws OutputError naming the lock file and the
    // process that holds it.
    explicit FolderLock(const std::filesystem::path& folder);
    ~FolderLock();
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;
    FolderLock(FolderLock&& other) noexcept;
    FolderLock& operator=(FolderLock&&) = delete;

    const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
    int fd_ = -1;
};

}  // namespace gpa::io
