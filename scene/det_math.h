// Elementary functions that give the same bits on every compiler, CPU and C
// library: double precision, written with +, -, *, /, sqrt, floor, frexp and
// ldexp only (each exact or correctly rounded by IEEE 754), so with
// -ffp-contract=off nothing in them can round differently anywhere. glibc's
// own differ by an ulp between its FMA and non-FMA code paths and between
// x86-64 and aarch64 (tanf, atanf, acosf, exp2, pow, sin, cos...), which moved
// pixels (docs/conventions.md, "Same bytes everywhere"). Accurate to a few
// ulps of double, far below a float's; not for hot loops.
#pragma once

#include <cmath>

namespace prast::det {

constexpr double kPi = 3.14159265358979323846;
constexpr double kLn2 = 0.69314718055994530942;

// e^x.
inline double exp(double x) {
    if (x != x) return x;
    if (!(x > -745.0)) return 0.0;
    if (x > 709.0) return HUGE_VAL;
    const double k = std::floor(x * 1.4426950408889634 + 0.5);
    const double r = (x - k * 0.693145751953125) - k * 1.4286068203094173e-06;  // ln 2 in two parts
    double term = 1.0, sum = 1.0;
    for (int i = 1; i <= 14; ++i) {
        term = term * r / double(i);
        sum += term;
    }
    return std::ldexp(sum, int(k));
}

// ln x for x > 0 and finite (NaN below 0, -inf at 0).
inline double log(double x) {
    if (!(x > 0.0)) return x == 0.0 ? -HUGE_VAL : std::nan("");
    if (x == HUGE_VAL) return x;
    int e = 0;
    double m = std::frexp(x, &e);  // m in [0.5, 1)
    if (m < 0.70710678118654752) {
        m *= 2.0;
        --e;
    }
    const double t = (m - 1.0) / (m + 1.0), t2 = t * t;  // |t| <= 0.1716
    double term = t, sum = 0.0;
    for (int i = 0; i < 12; ++i) {
        sum += term / double(2 * i + 1);
        term *= t2;
    }
    return 2.0 * sum + double(e) * kLn2;
}

// x^y for x > 0 (0 otherwise).
inline double pow(double x, double y) { return x > 0.0 ? det::exp(y * det::log(x)) : 0.0; }

// 2^x, its integer part exact.
inline double exp2(double x) {
    if (x != x) return x;
    if (!(x > -1074.0)) return 0.0;
    if (x > 1023.0) return HUGE_VAL;
    const double k = std::floor(x + 0.5);
    return std::ldexp(det::exp((x - k) * kLn2), int(k));
}

inline double log2(double x) {
    if (!(x > 0.0) || x == HUGE_VAL) return det::log(x);
    int e = 0;
    double m = std::frexp(x, &e);
    if (m < 0.70710678118654752) {
        m *= 2.0;
        --e;
    }
    return double(e) + det::log(m) * 1.44269504088896340736;
}

namespace detail {
// sin and cos of |r| <= pi/4 by their Taylor series (the r^19 term is below 1e-19).
inline double sin_kernel(double r) {
    const double r2 = r * r;
    double sum = 0.0, term = r;
    for (int i = 1; i <= 19; i += 2) {
        sum += term;
        term = -term * r2 / double((i + 1) * (i + 2));
    }
    return sum;
}
inline double cos_kernel(double r) {
    const double r2 = r * r;
    double sum = 0.0, term = 1.0;
    for (int i = 0; i <= 18; i += 2) {
        sum += term;
        term = -term * r2 / double((i + 1) * (i + 2));
    }
    return sum;
}
// x = k pi/2 + r, |r| <= pi/4 (about; pi/2 in three parts, exact for
// |x| < 2^20 pi/2 or so, which is every angle prast takes).
inline double reduce(double x, long& quadrant) {
    const double k = std::floor(x * 0.63661977236758134308 + 0.5);
    quadrant = long(k) & 3;
    return ((x - k * 1.57079632673412561417e+00) - k * 6.07710050630396597660e-11) - k * 2.02226624879595063154e-21;
}
} // namespace detail

inline double sin(double x) {
    if (!(std::fabs(x) < 1e9)) return x - x;  // NaN for inf and NaN; prast's angles are small
    long q = 0;
    const double r = detail::reduce(x, q);
    switch (q) {
    case 0: return detail::sin_kernel(r);
    case 1: return detail::cos_kernel(r);
    case 2: return -detail::sin_kernel(r);
    default: return -detail::cos_kernel(r);
    }
}

inline double cos(double x) {
    if (!(std::fabs(x) < 1e9)) return x - x;
    long q = 0;
    const double r = detail::reduce(x, q);
    switch (q) {
    case 0: return detail::cos_kernel(r);
    case 1: return -detail::sin_kernel(r);
    case 2: return -detail::cos_kernel(r);
    default: return detail::sin_kernel(r);
    }
}

inline double tan(double x) {
    if (!(std::fabs(x) < 1e9)) return x - x;
    long q = 0;
    const double r = detail::reduce(x, q);
    const double s = detail::sin_kernel(r), c = detail::cos_kernel(r);
    return (q & 1) ? -c / s : s / c;
}

// atan x: atan(-x) = -atan x, atan x = pi/2 - atan(1/x) beyond 1, and
// atan x = pi/4 + atan((x - 1) / (x + 1)) above tan(pi/8), leaving |t| <=
// 0.4143 for the series (the t^47 term is below 1e-19).
inline double atan(double x) {
    if (x != x) return x;
    const bool negative = x < 0.0;
    double a = negative ? -x : x;
    double base = 0.0;
    bool invert = false;
    if (a > 1.0) {
        a = 1.0 / a;
        invert = true;
    }
    if (a > 0.41421356237309504880) {
        a = (a - 1.0) / (a + 1.0);
        base = kPi / 4.0;
    }
    const double a2 = a * a;
    double sum = 0.0, term = a;
    for (int i = 0; i < 24; ++i) {
        sum += term / double(2 * i + 1);
        term = -term * a2;
    }
    double r = base + sum;
    if (invert) r = kPi / 2.0 - r;
    return negative ? -r : r;
}

// The angle of (x, y), in [-pi, pi], as std::atan2 for finite arguments.
inline double atan2(double y, double x) {
    if (x != x || y != y) return x + y;
    if (x == 0.0 && y == 0.0) return std::signbit(x) ? (std::signbit(y) ? -kPi : kPi) : y;
    if (std::fabs(x) >= std::fabs(y)) {
        const double a = det::atan(y / x);
        if (x > 0.0) return a;
        return std::signbit(y) ? a - kPi : a + kPi;
    }
    const double a = det::atan(x / y);
    return y > 0.0 ? kPi / 2.0 - a : -kPi / 2.0 - a;
}

// acos and asin for |x| <= 1 (clamped), from atan2: no cancellation near 1.
inline double acos(double x) {
    if (x != x) return x;
    if (x > 1.0) x = 1.0;
    if (x < -1.0) x = -1.0;
    return det::atan2(std::sqrt((1.0 - x) * (1.0 + x)), x);
}
inline double asin(double x) {
    if (x != x) return x;
    if (x > 1.0) x = 1.0;
    if (x < -1.0) x = -1.0;
    return det::atan2(x, std::sqrt((1.0 - x) * (1.0 + x)));
}

// Float arguments give float results, as <cmath>'s overloads do: the double
// result rounded once.
inline float exp(float x) { return float(det::exp(double(x))); }
inline float log(float x) { return float(det::log(double(x))); }
inline float pow(float x, float y) { return float(det::pow(double(x), double(y))); }
inline float exp2(float x) { return float(det::exp2(double(x))); }
inline float log2(float x) { return float(det::log2(double(x))); }
inline float sin(float x) { return float(det::sin(double(x))); }
inline float cos(float x) { return float(det::cos(double(x))); }
inline float tan(float x) { return float(det::tan(double(x))); }
inline float atan(float x) { return float(det::atan(double(x))); }
inline float atan2(float y, float x) { return float(det::atan2(double(y), double(x))); }
inline float acos(float x) { return float(det::acos(double(x))); }
inline float asin(float x) { return float(det::asin(double(x))); }

} // namespace prast::det
