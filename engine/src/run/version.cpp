#include "gpa/engine/version.hpp"

#include <fmt/format.h>

namespace gpa {

std::string build_id() {
    return fmt::format("gpa {} (commit {}, {})", version(), source_commit(), build_configuration());
}

}  // namespace gpa
