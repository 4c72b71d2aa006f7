// Number formatting; see format.h.
#include "stepper/format.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace prast::stepper {

std::string num(float v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[48];
    for (int digits = 6; digits <= 9; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, double(v));
        if (std::strtof(buf, nullptr) == v) break;
    }
    return buf;
}

std::string num(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[48];
    for (int digits = 6; digits <= 17; ++digits) {
        std::snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (std::strtod(buf, nullptr) == v) break;
    }
    return buf;
}

std::string vec(const glm::vec2& v) { return "(" + num(v.x) + ", " + num(v.y) + ")"; }
std::string vec(const glm::vec3& v) { return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ")"; }
std::string vec(const glm::vec4& v) {
    return "(" + num(v.x) + ", " + num(v.y) + ", " + num(v.z) + ", " + num(v.w) + ")";
}

std::string hex16(std::uint32_t mask) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "0x%04x", mask & 0xFFFFu);
    return buf;
}

} // namespace prast::stepper
