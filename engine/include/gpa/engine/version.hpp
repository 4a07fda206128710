#pragma once
// What this build of gpa is: its version, the commit it was built from and how it was compiled.
// Checkpoints carry build_id() and are refused by a different build, because another commit or
// compiler may round differently and a resumed run would no longer match one never stopped.

#include <string>
#include <string_view>

namespace gpa {

// "0.1.0"
std::string_view version();
// `git describe --always --dirty` of the source tree when it was built ("a41dad3c0b7e-dirty"),
// or "unknown" outside a git checkout.
std::string_view source_commit();
// Compiler, its version, build type and architecture flags ("GNU 12.2.0, Release, x86_64").
std::string_view build_configuration();
// All three in one line: "gpa 0.1.0 (commit a41dad3c0b7e, GNU 12.2.0, Release, x86_64)".
std::string build_id();

}  // namespace gpa
