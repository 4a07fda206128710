#include "gpa/io/checkpoint.hpp"

#include <fstream>
#include <system_error>

#include <fmt/format.h>

#include "gpa/engine/state_io.hpp"
#include "gpa/io/atomic_file.hpp"

namespace gpa::io {

namespace {

std::uint64_t size_of(const std::filesystem::path& file) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw OutputError(fmt::format("cannot read the checkpoint '{}': {}", file.string(), ec.message()));
    return size;
}

}  // namespace

std::string scene_fingerprint(std::string_view scene_text) {
    Checksum sum;
    sum.add(scene_text.data(), scene_text.size());
    return fmt::format("fnv1a64:{:016x}", sum.value());
}

void write_checkpoint(const std::filesystem::path& file, const Simulation& sim, std::string_view fingerprint,
                      std::string_view user_data) {
    write_file_atomically(file, [&](std::ofstream& out) { sim.save_checkpoint(out, fingerprint, user_data); });
}

std::string read_checkpoint(const std::filesystem::path& file, Simulation& sim, std::string_view fingerprint) {
    const auto size = size_of(file);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw OutputError(fmt::format("cannot open the checkpoint '{}'", file.string()));
    return sim.restore_checkpoint(in, size, fmt::format("'{}'", file.string()), fingerprint);
}

CheckpointInfo checkpoint_info(const std::filesystem::path& file) {
    const auto size = size_of(file);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw OutputError(fmt::format("cannot open the checkpoint '{}'", file.string()));
    return Simulation::checkpoint_info(in, size, fmt::format("'{}'", file.string()));
}

}  // namespace gpa::io
