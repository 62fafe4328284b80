// Forward-mode dual numbers: a value and its derivatives with respect to N inputs, carried
// through the arithmetic of a plain function. Evaluating a return mapping with Dual<N> instead
// of double gives the derivatives of exactly the algorithm that computed the value, branches
// included: the consistent (algorithmic) tangent of consistent_tangent.h, with no derivation
// by hand to keep in step with the return mapping.
//
// Comparisons look at the value only (they choose the branch); std::sqrt and std::abs are
// reached through argument-dependent lookup (a function written `using std::sqrt; sqrt(x)`
// works for double and Dual alike).
#pragma once

#include <mpm/core/config.h>

#include <cmath>

namespace mpm
{
  template <int N>
  struct Dual
  {
    double value = 0;
    double derivative[N] = {};

    Dual() = default; // host and device alike (a defaulted constructor takes no annotation)
    MPM_HOST_DEVICE Dual(const double v) // a constant: no derivatives
      : value(v)
    {}

    // The k-th input, with value v: d/d(input k) = 1.
    MPM_HOST_DEVICE static Dual variable(const double v, const int k)
    {
      Dual d(v);
      d.derivative[k] = 1;
      return d;
    }

    MPM_HOST_DEVICE Dual &operator+=(const Dual &b)
    {
      value += b.value;
      for (int k = 0; k < N; ++k)
        derivative[k] += b.derivative[k];
      return *this;
    }
    MPM_HOST_DEVICE Dual &operator-=(const Dual &b)
    {
      value -= b.value;
      for (int k = 0; k < N; ++k)
        derivative[k] -= b.derivative[k];
      return *this;
    }
    MPM_HOST_DEVICE Dual &operator*=(const Dual &b)
    {
      for (int k = 0; k < N; ++k)
        derivative[k] = derivative[k] * b.value + value * b.derivative[k];
      value *= b.value;
      return *this;
    }
    MPM_HOST_DEVICE Dual &operator/=(const Dual &b)
    {
      const double q = value / b.value;
      for (int k = 0; k < N; ++k)
        derivative[k] = (derivative[k] - q * b.derivative[k]) / b.value;
      value = q;
      return *this;
    }
  };

  template <int N>
  MPM_HOST_DEVICE inline Dual<N> operator-(Dual<N> a)
  {
    a.value = -a.value;
    for (int k = 0; k < N; ++k)
      a.derivative[k] = -a.derivative[k];
    return a;
  }
  template <int N>
  MPM_HOST_DEVICE inline Dual<N> operator+(Dual<N> a, const Dual<N> &b)
  {
    return a += b;
  }
  template <int N>
  MPM_HOST_DEVICE inline Dual<N> operator-(Dual<N> a, const Dual<N> &b)
  {
    return a -= b;
  }
  template <int N>
  MPM_HOST_DEVICE inline Dual<N> operator*(Dual<N> a, const Dual<N> &b)
  {
    return a *= b;
  }
  template <int N>
  MPM_HOST_DEVICE inline Dual<N> operator/(Dual<N> a, const Dual<N> &b)
  {
    return a /= b;
  }

#define MPM_DUAL_COMPARISON(op)                                                 \
  template <int N>                                                              \
  MPM_HOST_DEVICE inline bool operator op(const Dual<N> &a, const Dual<N> &b)   \
  {                                                                             \
    return a.value op b.value;                                                  \
  }
  MPM_DUAL_COMPARISON(<)
  MPM_DUAL_COMPARISON(<=)
  MPM_DUAL_COMPARISON(>)
  MPM_DUAL_COMPARISON(>=)
  MPM_DUAL_COMPARISON(==)
  MPM_DUAL_COMPARISON(!=)
#undef MPM_DUAL_COMPARISON

  template <int N>
  MPM_HOST_DEVICE inline Dual<N> sqrt(const Dual<N> &a)
  {
    Dual<N> r(std::sqrt(a.value));
    // d sqrt(a) = da / (2 sqrt(a)); at a = 0 the derivative is that of the branch a caller
    // takes there (all the returns guard their divisions by a root), so 0 rather than inf.
    const double scale = r.value > 0 ? 0.5 / r.value : 0.0;
    for (int k = 0; k < N; ++k)
      r.derivative[k] = scale * a.derivative[k];
    return r;
  }

  template <int N>
  MPM_HOST_DEVICE inline Dual<N> abs(const Dual<N> &a)
  {
    return a.value < 0 ? -a : a;
  }

  // The value of a double or of a Dual, for code written for both.
  MPM_HOST_DEVICE inline double value_of(const double x) { return x; }
  template <int N>
  MPM_HOST_DEVICE inline double value_of(const Dual<N> &x)
  {
    return x.value;
  }
} // namespace mpm
