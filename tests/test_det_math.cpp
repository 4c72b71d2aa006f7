// scene/det_math.h: the project's own elementary functions, which the pixels
// use instead of the C library's so that every CPU and libm gives the same
// bits. Checked against the C library's long double versions (a reference
// more precise than the double result, on x86-64's 80-bit long double) over
// seeded random arguments on the ranges prast uses, at the special values,
// and for the float overloads (the double result rounded once).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "scene/det_math.h"

using namespace prast;

namespace {

// |a - ref| in units in the last place of double at ref.
double ulps(double a, long double ref) {
    const double r = double(ref);
    if (a == r) return 0.0;
    const double ulp = std::nextafter(std::fabs(r), HUGE_VAL) - std::fabs(r);
    return double(std::fabs((long double)a - ref) / (long double)ulp);
}

template <class F, class R>
double worst_ulps(double lo, double hi, F f, R ref, int n = 100000) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> d(lo, hi);
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        const double x = d(rng);
        worst = std::max(worst, ulps(f(x), ref((long double)x)));
    }
    return worst;
}

} // namespace

TEST_SUITE("det_math") {
TEST_CASE("within a few ulps of double on the ranges prast uses") {
    CHECK(worst_ulps(-20.0, 20.0, [](double x) { return det::sin(x); }, [](long double x) { return sinl(x); }) <= 4.0);
    CHECK(worst_ulps(-20.0, 20.0, [](double x) { return det::cos(x); }, [](long double x) { return cosl(x); }) <= 4.0);
    // tan away from its poles (|cos| > 0.01).
    CHECK(worst_ulps(-1.56, 1.56, [](double x) { return det::tan(x); }, [](long double x) { return tanl(x); }) <= 8.0);
    CHECK(worst_ulps(-50.0, 50.0, [](double x) { return det::atan(x); }, [](long double x) { return atanl(x); }) <= 4.0);
    CHECK(worst_ulps(-1.0, 1.0, [](double x) { return det::acos(x); }, [](long double x) { return acosl(x); }) <= 6.0);
    CHECK(worst_ulps(-1.0, 1.0, [](double x) { return det::asin(x); }, [](long double x) { return asinl(x); }) <= 8.0);
    CHECK(worst_ulps(-60.0, 60.0, [](double x) { return det::exp(x); }, [](long double x) { return expl(x); }) <= 6.0);
    CHECK(worst_ulps(-60.0, 60.0, [](double x) { return det::exp2(x); }, [](long double x) { return exp2l(x); }) <= 6.0);
    CHECK(worst_ulps(1e-6, 1e6, [](double x) { return det::log(x); }, [](long double x) { return logl(x); }) <= 4.0);
    CHECK(worst_ulps(1e-6, 1e6, [](double x) { return det::log2(x); }, [](long double x) { return log2l(x); }) <= 4.0);
    CHECK(worst_ulps(1e-3, 10.0, [](double x) { return det::pow(x, 2.4); }, [](long double x) { return powl(x, (long double)2.4); }) <= 32.0);
    // atan2 in all four quadrants, y from x's own generator.
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> d(-5.0, 5.0);
    double worst = 0.0;
    for (int i = 0; i < 100000; ++i) {
        const double y = d(rng), x = d(rng);
        worst = std::max(worst, ulps(det::atan2(y, x), atan2l((long double)y, (long double)x)));
    }
    CHECK(worst <= 6.0);
}

TEST_CASE("special values") {
    CHECK(det::sin(0.0) == 0.0);
    CHECK(det::cos(0.0) == 1.0);
    CHECK(det::tan(0.0) == 0.0);
    CHECK(det::atan(0.0) == 0.0);
    CHECK(det::atan2(0.0, 1.0) == 0.0);
    CHECK(det::atan2(0.0, -1.0) == doctest::Approx(det::kPi).epsilon(1e-16));
    CHECK(det::atan2(1.0, 0.0) == doctest::Approx(det::kPi / 2).epsilon(1e-16));
    CHECK(det::atan2(-1.0, 0.0) == doctest::Approx(-det::kPi / 2).epsilon(1e-16));
    CHECK(det::acos(1.0) == 0.0);
    CHECK(det::acos(2.0) == 0.0);  // clamped
    CHECK(det::acos(-1.0) == doctest::Approx(det::kPi).epsilon(1e-16));
    CHECK(det::exp(0.0) == 1.0);
    CHECK(det::exp(-1000.0) == 0.0);
    CHECK(det::exp(1000.0) == HUGE_VAL);
    CHECK(det::exp2(10.0) == 1024.0);
    CHECK(det::exp2(-0.25) == doctest::Approx(0.8408964152537145).epsilon(1e-15));
    CHECK(det::log2(1024.0) == 10.0);
    CHECK(det::log(1.0) == 0.0);
    CHECK(det::log(0.0) == -HUGE_VAL);
    CHECK(std::isnan(det::log(-1.0)));
    CHECK(det::pow(-2.0, 2.0) == 0.0);  // prast takes powers of positive bases only
    const double nan = std::numeric_limits<double>::quiet_NaN();
    for (double v : {det::sin(nan), det::cos(nan), det::tan(nan), det::atan(nan), det::acos(nan), det::exp(nan),
                     det::exp2(nan), det::sin(HUGE_VAL), det::atan2(nan, 1.0)})
        CHECK(std::isnan(v));
    CHECK(det::atan(HUGE_VAL) == doctest::Approx(det::kPi / 2).epsilon(1e-16));
}

TEST_CASE("the float overloads round the double result once") {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<float> d(0.001f, 1.5f);
    for (int i = 0; i < 20000; ++i) {
        const float x = d(rng);
        CHECK(det::tan(x) == float(det::tan(double(x))));
        CHECK(det::sin(x) == float(det::sin(double(x))));
        CHECK(det::acos(x / 1.5f) == float(det::acos(double(x / 1.5f))));
        CHECK(det::pow(x, 2.4f) == float(det::pow(double(x), double(2.4f))));
    }
    // The camera's half angle at 60 degrees, where the C library's tanf (on
    // x86-64) is an ulp from the correctly rounded 0.57735026.
    const float half = 60.0f * 0.017453292519943295f / 2.0f;
    CHECK(det::tan(half) == float(tanl((long double)half)));
}
}
