// The value syntaxes the tools share: whole-string numbers (strtod and strtol
// alone would take "1.5abc", "nan" and "inf"), X,Y,Z triples, WxH sizes and
// comma lists. Small and inline, so a header such as apps/render_options.h
// can use them without the flags library.
#pragma once

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace prast::cli {

inline std::string lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return s;
}

inline bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// "a,b,,c" -> {"a", "b", "", "c"}; "" -> {""}.
inline std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> parts;
    std::size_t begin = 0;
    for (;;) {
        std::size_t end = s.find(sep, begin);
        parts.push_back(s.substr(begin, end == std::string::npos ? std::string::npos : end - begin));
        if (end == std::string::npos) return parts;
        begin = end + 1;
    }
}

// A whole string as a finite number that fits a float.
inline bool parse_finite(const std::string& s, double& out) {
    if (s.empty() || s.find_first_of(" \t\n") != std::string::npos) return false;
    errno = 0;
    char* end = nullptr;
    double v = std::strtod(s.c_str(), &end);
    if (end != s.c_str() + s.size() || errno == ERANGE || !std::isfinite(v)) return false;
    // Values beyond float range would become inf once stored.
    if (std::fabs(v) > 3.0e38) return false;
    out = v;
    return true;
}

// A whole string as a decimal integer.
inline bool parse_integer(const std::string& s, long& out) {
    if (s.empty() || s.find_first_of(" \t\n") != std::string::npos) return false;
    errno = 0;
    char* end = nullptr;
    long v = std::strtol(s.c_str(), &end, 10);
    if (end != s.c_str() + s.size() || errno == ERANGE) return false;
    out = v;
    return true;
}

// A decimal integer in [lo, hi].
inline bool parse_integer_in(const std::string& s, long lo, long hi, long& out) {
    long v;
    if (!parse_integer(s, v) || v < lo || v > hi) return false;
    out = v;
    return true;
}

// X,Y,Z: three finite numbers.
inline bool parse_vec3(const std::string& s, glm::vec3& out) {
    std::vector<std::string> parts = split(s, ',');
    if (parts.size() != 3) return false;
    for (int i = 0; i < 3; ++i) {
        double v;
        if (!parse_finite(parts[std::size_t(i)], v)) return false;
        out[i] = float(v);
    }
    return true;
}

inline bool non_negative(const glm::vec3& v) { return v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f; }

// WxH (the x in either case): two integers, not range-checked.
inline bool parse_size(const std::string& s, long& w, long& h) {
    std::size_t x = lower(s).find('x');
    return x != std::string::npos && parse_integer(s.substr(0, x), w) && parse_integer(s.substr(x + 1), h);
}

// A comma list of integers, each accepted by ok(n).
template <class Ok>
bool parse_int_list(const std::string& s, std::vector<int>& out, Ok ok) {
    std::vector<int> v;
    for (const std::string& item : split(s, ',')) {
        long n;
        if (!parse_integer(item, n) || !ok(n)) return false;
        v.push_back(int(n));
    }
    out = v;
    return true;
}

} // namespace prast::cli
