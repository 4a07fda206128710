#include "gpa/engine/scene.hpp"

namespace gpa {

// Placeholder until the scene checks land.
void validate_scene(const Scene&) {}

}  // namespace gpa
