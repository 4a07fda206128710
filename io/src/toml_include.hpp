#pragma once
// Private to io/: the one way io/ includes toml++.
//
// toml++ 3.3 checks some of its parser's internal invariants with assert(), and in release
// builds turns the same checks into compiler assumptions (clang: __builtin_assume). Malformed
// input can break one of them (for example `v = [}]`): a debug build then aborts, and an
// assumption that does not hold is undefined behaviour. With the checks off, as in a GCC release
// build, the parser reports such input as a syntax error, which is what a scene reader must do.
// So io/ switches them off in every build type and in every file that includes toml++ (the same
// definitions everywhere).
#include <toml++/impl/preprocessor.h>
#undef TOML_ASSERT
#define TOML_ASSERT(expr) static_assert(true)
#undef TOML_ASSERT_ASSUME
#define TOML_ASSERT_ASSUME(expr) static_assert(true)
#include <toml++/toml.h>
