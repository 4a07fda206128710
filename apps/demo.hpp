#pragma once
#include <filesystem>

namespace gpa::app {
// The built-in demonstration of the engine core: runs the kernels on lattices in the three
// geometries and prints what they computed. Writes a snapshot into `output` when it is not empty.
int run_demo(int threads, const std::filesystem::path& output);
}  // namespace gpa::app
