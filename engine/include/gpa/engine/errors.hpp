#pragma once
// Errors the engine reports to its caller. Every message says what was wrong and where
// (which node, which option), so that a user can find it in their scene.

#include <array>
#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>

namespace gpa {

// Impossible input: a node, an option or a call that the method cannot work with.
class InputError : public std::invalid_argument {
public:
    using std::invalid_argument::invalid_argument;
};

// An input error in one entry of a list of a scene ([[prescribed_velocity]], [[gauge]]): its
// index says which entry, so that a scene reader can name the line of its table.
class EntryError : public InputError {
public:
    EntryError(const std::string& message, std::size_t index) : InputError(message), index_(index) {}
    std::size_t index() const { return index_; }

private:
    std::size_t index_;
};

// A state the method reached and cannot continue from (a node left its neighbourhood, a
// non-finite value appeared during a run). A kernel that knows the node and the field at fault
// names them here too, so that the run's report can add the node's body and position.
class NumericalError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
    NumericalError(const std::string& message, std::size_t node, std::string field)
        : std::runtime_error(message), node_(node), field_(std::move(field)) {}
    std::optional<std::size_t> node() const { return node_; }
    const std::string& field() const { return field_; }

private:
    std::optional<std::size_t> node_;
    std::string field_;
};

// Something computed from the input (nodes, neighbour lists, files) would need more memory or
// disk than the limit allows. what() is one line with the estimate and the limit.
class LimitError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Where a step of a run failed (Simulation::step): the step's number (the first step is 1),
// the time it had reached, the phase that threw, and, where one is known, the node at fault
// with its body, position (the node's own, first dim components) and the field.
struct FailureSite {
    std::size_t step = 0;
    double time = 0.0;
    std::string phase;
    std::optional<std::size_t> node;   // its index in the node arrays at the time
    std::optional<std::size_t> id;     // its id (NodeStore::id: stable through the run)
    std::string body;
    std::array<double, 3> position{0, 0, 0};
    int dim = 2;
    std::string field;
    std::string cause;  // the message of the error the phase threw
};

// A step that failed, whatever its phase threw (a NumericalError, a LimitError, an InputError
// from a check on the nodes, std::bad_alloc): what() is one line naming step, time, phase, body,
// node, position and field (those that are known) and the cause. Unless it is the energy guard
// (phase "energy balance", which checks a whole step), the state is half-updated.
class StepFailure : public std::runtime_error {
public:
    StepFailure(const std::string& message, FailureSite site) : std::runtime_error(message), site_(std::move(site)) {}
    const FailureSite& site() const { return site_; }

private:
    FailureSite site_;
};

}  // namespace gpa
