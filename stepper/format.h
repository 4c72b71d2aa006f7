// Numbers as the stepper prints them: the shortest decimal that reads back
// as the same float (so a printed value is the value, not a rounding of it),
// vectors in parentheses.
#pragma once

#include <cstdint>
#include <string>

#include <glm/glm.hpp>

namespace prast::stepper {

std::string num(float v);
std::string num(double v);
std::string vec(const glm::vec2& v);
std::string vec(const glm::vec3& v);
std::string vec(const glm::vec4& v);
std::string hex16(std::uint32_t mask);  // a 16-lane mask as 0x%04x

} // namespace prast::stepper
