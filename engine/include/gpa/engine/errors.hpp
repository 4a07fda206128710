#pragma once
// Errors the engine reports to its caller. Every message says what was wrong and where
// (which node, which option), so that a user can find it in their scene.

#include <stdexcept>
#include <string>

namespace gpa {

// Impossible input: a node, an option or a call that the method cannot work with.
class InputError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

// A state the method reached and cannot continue from (a node left its neighbourhood, a
// non-finite value appeared during a run).
class NumericalError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

}  // namespace gpa
