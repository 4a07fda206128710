// The one translation unit that compiles the toml++ parser into gpa_io. Every other file of io/
// includes toml++ with TOML_HEADER_ONLY=0 (set in io/CMakeLists.txt), so the parser is compiled
// once, and gpa_io needs no toml++ library at link time (nor does any program that links gpa_io).
#define TOML_IMPLEMENTATION
#include "toml_include.hpp"
