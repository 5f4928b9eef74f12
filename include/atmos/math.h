// atmos: small vector math usable on host and device (ATMOS_HD).
//
// Vec3T<T> is a plain aggregate of three components; Vec3d carries planet-scale
// geometry (positions of 6.4e6 m keep sub-millimetre precision in double), Vec3f
// carries colour (RGB radiance, transmittance, coefficients per channel).
#pragma once

#include <math.h>

#include "atmos/platform.h"

namespace atmos {

constexpr double kPi = 3.14159265358979323846;
constexpr float kPiF = 3.14159265358979323846f;

// Overloads of the scalar maths we need, spelled so that nvcc picks the device
// versions and the host picks <math.h>.
ATMOS_HD inline float Sqrt(float x) { return sqrtf(x); }
ATMOS_HD inline double Sqrt(double x) { return sqrt(x); }
ATMOS_HD inline float Exp(float x) { return expf(x); }
ATMOS_HD inline double Exp(double x) { return exp(x); }
ATMOS_HD inline float Pow(float x, float y) { return powf(x, y); }
ATMOS_HD inline double Pow(double x, double y) { return pow(x, y); }
ATMOS_HD inline float Abs(float x) { return fabsf(x); }
ATMOS_HD inline double Abs(double x) { return fabs(x); }
ATMOS_HD inline bool IsFinite(float x) { return isfinite(x); }
ATMOS_HD inline bool IsFinite(double x) { return isfinite(x); }

template <typename T>
ATMOS_HD inline T Min(T a, T b) {
    return a < b ? a : b;
}
template <typename T>
ATMOS_HD inline T Max(T a, T b) {
    return a > b ? a : b;
}
template <typename T>
ATMOS_HD inline T Clamp(T x, T lo, T hi) {
    return x < lo ? lo : (x > hi ? hi : x);
}
// sqrt(max(x, 0)): for discriminants that rounding pushes slightly negative.
template <typename T>
ATMOS_HD inline T SafeSqrt(T x) {
    return Sqrt(x > T(0) ? x : T(0));
}
template <typename T>
ATMOS_HD inline T ClampCosine(T mu) {
    return Clamp(mu, T(-1), T(1));
}

template <typename T>
struct Vec3T {
    T x, y, z;

    ATMOS_HD constexpr Vec3T() : x(0), y(0), z(0) {}
    ATMOS_HD constexpr explicit Vec3T(T v) : x(v), y(v), z(v) {}
    ATMOS_HD constexpr Vec3T(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <typename U>
    ATMOS_HD constexpr explicit Vec3T(const Vec3T<U>& o)
        : x(static_cast<T>(o.x)), y(static_cast<T>(o.y)), z(static_cast<T>(o.z)) {}

    ATMOS_HD T operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
    ATMOS_HD T& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

    ATMOS_HD Vec3T& operator+=(const Vec3T& o) {
        x += o.x;
        y += o.y;
        z += o.z;
        return *this;
    }
    ATMOS_HD Vec3T& operator-=(const Vec3T& o) {
        x -= o.x;
        y -= o.y;
        z -= o.z;
        return *this;
    }
    ATMOS_HD Vec3T& operator*=(const Vec3T& o) {
        x *= o.x;
        y *= o.y;
        z *= o.z;
        return *this;
    }
    ATMOS_HD Vec3T& operator*=(T s) {
        x *= s;
        y *= s;
        z *= s;
        return *this;
    }
};

using Vec3f = Vec3T<float>;
using Vec3d = Vec3T<double>;
// Linear RGB (radiance, transmittance, per-channel coefficients).
using Rgb = Vec3f;

template <typename T>
ATMOS_HD inline Vec3T<T> operator+(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator-(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator-(const Vec3T<T>& a) {
    return {-a.x, -a.y, -a.z};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator*(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {a.x * b.x, a.y * b.y, a.z * b.z};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator/(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {a.x / b.x, a.y / b.y, a.z / b.z};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator*(const Vec3T<T>& a, T s) {
    return {a.x * s, a.y * s, a.z * s};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator*(T s, const Vec3T<T>& a) {
    return {a.x * s, a.y * s, a.z * s};
}
template <typename T>
ATMOS_HD inline Vec3T<T> operator/(const Vec3T<T>& a, T s) {
    return {a.x / s, a.y / s, a.z / s};
}
template <typename T>
ATMOS_HD inline T Dot(const Vec3T<T>& a, const Vec3T<T>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <typename T>
ATMOS_HD inline Vec3T<T> Cross(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <typename T>
ATMOS_HD inline T Length(const Vec3T<T>& a) {
    return Sqrt(Dot(a, a));
}
template <typename T>
ATMOS_HD inline Vec3T<T> Normalize(const Vec3T<T>& a) {
    return a / Length(a);
}
template <typename T>
ATMOS_HD inline Vec3T<T> Exp(const Vec3T<T>& a) {
    return {Exp(a.x), Exp(a.y), Exp(a.z)};
}
template <typename T>
ATMOS_HD inline Vec3T<T> Min(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {Min(a.x, b.x), Min(a.y, b.y), Min(a.z, b.z)};
}
template <typename T>
ATMOS_HD inline Vec3T<T> Max(const Vec3T<T>& a, const Vec3T<T>& b) {
    return {Max(a.x, b.x), Max(a.y, b.y), Max(a.z, b.z)};
}
template <typename T>
ATMOS_HD inline T MaxComponent(const Vec3T<T>& a) {
    return Max(a.x, Max(a.y, a.z));
}
template <typename T>
ATMOS_HD inline T MinComponent(const Vec3T<T>& a) {
    return Min(a.x, Min(a.y, a.z));
}
template <typename T>
ATMOS_HD inline bool IsFinite(const Vec3T<T>& a) {
    return IsFinite(a.x) && IsFinite(a.y) && IsFinite(a.z);
}
// Replaces NaN, infinities and negative values by 0: the last guard before a
// pixel is stored (outputs are never NaN, infinite or negative).
ATMOS_HD inline Rgb SanitizeRadiance(const Rgb& c) {
    Rgb out;
    for (int i = 0; i < 3; ++i) {
        float v = c[i];
        out[i] = (IsFinite(v) && v > 0.0f) ? v : 0.0f;
    }
    return out;
}

template <typename T>
ATMOS_HD inline T Radians(T degrees) {
    return degrees * T(kPi / 180.0);
}

}  // namespace atmos
