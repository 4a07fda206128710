#include "gpa/engine/limits.hpp"

#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <unistd.h>

#include "gpa/engine/bodies.hpp"
#include "gpa/engine/errors.hpp"

namespace gpa {

std::uint64_t physical_memory_bytes() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    std::uint64_t bytes = pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) : 0;
    // A control group's limit ("max" when there is none).
    std::ifstream cgroup("/sys/fs/cgroup/memory.max");
    std::string word;
    if (cgroup >> word && !word.empty() && word.find_first_not_of("0123456789") == std::string::npos) {
        const std::uint64_t group = std::stoull(word);
        if (group > 0 && (bytes == 0 || group < bytes)) bytes = group;
    }
    return bytes > 0 ? bytes : std::uint64_t{1} << 32;  // unknown: assume 4 GiB
}

std::string format_bytes(double bytes) {
    static const char* units[] = {"B", "kiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    int u = 0;
    while (bytes >= 1024.0 && u < 6) {
        bytes /= 1024.0;
        ++u;
    }
    if (u == 6 && bytes >= 1024.0) return fmt::format("{:.3g} EiB", bytes);
    return u == 0 ? fmt::format("{:.0f} B", bytes) : fmt::format("{:.3g} {}", bytes, units[u]);
}

double bytes_per_node_besides_lists(int dim) { return dim == 3 ? 2.0 * 493.0 + 200.0 : 2.0 * 350.0 + 320.0; }

double list_entries_per_node(int dim) { return dim == 3 ? 56.0 : 21.0; }

double estimated_node_count(const Scene& scene) {
    double nodes = 0.0;
    for (std::size_t b = 0; b < scene.bodies.size(); ++b) {
        if (scene.bodies[b].shape == ShapeKind::Nodes) {
            if (scene.bodies[b].node_set) nodes += double(scene.bodies[b].node_set->size());
            continue;
        }
        const LatticeBlock block = body_lattice(scene, b);
        double cells = 1.0;
        for (int k = 0; k < 3; ++k) cells *= std::max(0.0, double(block.last[k]) - double(block.first[k]));
        nodes += cells;
    }
    return nodes;
}

std::uint64_t limit_bytes(const MemoryLimit& limit) { return limit.bytes > 0 ? limit.bytes : physical_memory_bytes(); }

std::string describe_limit(const MemoryLimit& limit) {
    return fmt::format("the memory limit is {} ({})", format_bytes(double(limit_bytes(limit))),
                       limit.source.empty() ? "the machine's physical memory" : limit.source);
}

void check_scene_memory(const Scene& scene, const MemoryLimit& limit) {
    const int dim = dimension_of(scene.geometry);
    const double nodes = estimated_node_count(scene);
    const double per_node = bytes_per_node_besides_lists(dim) + bytes_per_list_entry * list_entries_per_node(dim);
    const double bytes = nodes * per_node;
    if (nodes > double(0xFFFFFFFFu)) {
        throw LimitError(fmt::format("the scene's bodies need about {:.3g} nodes, more than the 2^32 - 1 a run can hold "
                                     "(an estimated {} of memory; {})",
                                     nodes, format_bytes(bytes), describe_limit(limit)));
    }
    if (bytes > double(limit_bytes(limit))) {
        throw LimitError(fmt::format("the scene's bodies need about {:.3g} nodes, an estimated {} of memory ({} per node); {}",
                                     nodes, format_bytes(bytes), format_bytes(per_node), describe_limit(limit)));
    }
}

}  // namespace gpa
