#pragma once
// Private to io/: reading the solver options of the engine's table (gpa/engine/solver_options.hpp)
// from a scene file's [solver] table and from the key=value settings of `gpa study` variants,
// through the same code, so that both accept the same words, units and numbers.

#include <string>
#include <string_view>

#include "gpa/engine/solver_options.hpp"
#include "toml_reading.hpp"

namespace gpa::io::detail {

// The io dimension of a table row's unit kind.
Dimension dimension_of(OptionUnit unit);

// Reads the row's key from `reader` into its member of `s`; leaves `s` alone when the key is
// absent. Fails through the reader (file, line, key) on a wrong type, unit or word. Ranges are
// not checked here: option_error (validate_scene) does that.
void read_solver_option(const TableReader& reader, const SolverOption& option, SolverOptions& s);

// Reads a variant's setting `option.key=value` into `s` as a scene file would read the same
// value: "0.2" and "true" as TOML would (a number, a boolean), anything else ("sph-nsf",
// "10 ns") as a string. Messages start with `source`, e.g. "--variant 'x:cfl=2'", then name
// solver.KEY. Throws SceneError.
void read_solver_option_text(const SolverOption& option, std::string_view value, const std::string& source,
                             SolverOptions& s);

}  // namespace gpa::io::detail
