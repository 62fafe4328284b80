// Small fixed-size vectors and matrices for per-point physics (host and device).
#pragma once

#include <mpm/core/config.h>

#include <cmath>

namespace mpm
{
  // Symmetric 3x3 tensor in Voigt order xx, yy, zz, xy, yz, xz (no factor 2 on shear).
  template <typename Real>
  struct SymTensor
  {
    Real c[n_voigt];

    MPM_HOST_DEVICE Real &operator[](int i) { return c[i]; }
    MPM_HOST_DEVICE Real operator[](int i) const { return c[i]; }

    MPM_HOST_DEVICE static SymTensor zero()
    {
      SymTensor t;
      for (int i = 0; i < n_voigt; ++i)
        t.c[i] = Real(0);
      return t;
    }

    // Entry (i,j) of the full 3x3 matrix.
    MPM_HOST_DEVICE Real operator()(int i, int j) const
    {
      if (i == j)
        return c[i];
      const int k = i + j; // 0+1 -> xy, 1+2 -> yz, 0+2 -> xz
      return k == 1 ? c[3] : (k == 3 ? c[4] : c[5]);
    }
  };

  template <typename Real>
  MPM_HOST_DEVICE inline Real trace(const SymTensor<Real> &t)
  {
    return t[0] + t[1] + t[2];
  }

  // Full 3x3 matrix, row-major.
  template <typename Real>
  struct Mat3
  {
    Real a[3][3];

    MPM_HOST_DEVICE static Mat3 zero()
    {
      Mat3 m;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          m.a[i][j] = Real(0);
      return m;
    }
    MPM_HOST_DEVICE static Mat3 identity()
    {
      Mat3 m = zero();
      for (int i = 0; i < 3; ++i)
        m.a[i][i] = Real(1);
      return m;
    }
  };

  template <typename Real>
  MPM_HOST_DEVICE inline Mat3<Real> to_matrix(const SymTensor<Real> &t)
  {
    Mat3<Real> m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        m.a[i][j] = t(i, j);
    return m;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline SymTensor<Real> symmetric_part(const Mat3<Real> &m)
  {
    SymTensor<Real> t;
    t[0] = m.a[0][0];
    t[1] = m.a[1][1];
    t[2] = m.a[2][2];
    t[3] = Real(0.5) * (m.a[0][1] + m.a[1][0]);
    t[4] = Real(0.5) * (m.a[1][2] + m.a[2][1]);
    t[5] = Real(0.5) * (m.a[0][2] + m.a[2][0]);
    return t;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Mat3<Real> multiply(const Mat3<Real> &x, const Mat3<Real> &y)
  {
    Mat3<Real> r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        {
          Real s = 0;
          for (int k = 0; k < 3; ++k)
            s += x.a[i][k] * y.a[k][j];
          r.a[i][j] = s;
        }
    return r;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Mat3<Real> transpose(const Mat3<Real> &x)
  {
    Mat3<Real> r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.a[i][j] = x.a[j][i];
    return r;
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Real determinant(const Mat3<Real> &m)
  {
    return m.a[0][0] * (m.a[1][1] * m.a[2][2] - m.a[1][2] * m.a[2][1]) -
           m.a[0][1] * (m.a[1][0] * m.a[2][2] - m.a[1][2] * m.a[2][0]) +
           m.a[0][2] * (m.a[1][0] * m.a[2][1] - m.a[1][1] * m.a[2][0]);
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Mat3<Real> inverse(const Mat3<Real> &m)
  {
    const Real d = determinant(m);
    Mat3<Real> r;
    r.a[0][0] = (m.a[1][1] * m.a[2][2] - m.a[1][2] * m.a[2][1]) / d;
    r.a[0][1] = (m.a[0][2] * m.a[2][1] - m.a[0][1] * m.a[2][2]) / d;
    r.a[0][2] = (m.a[0][1] * m.a[1][2] - m.a[0][2] * m.a[1][1]) / d;
    r.a[1][0] = (m.a[1][2] * m.a[2][0] - m.a[1][0] * m.a[2][2]) / d;
    r.a[1][1] = (m.a[0][0] * m.a[2][2] - m.a[0][2] * m.a[2][0]) / d;
    r.a[1][2] = (m.a[0][2] * m.a[1][0] - m.a[0][0] * m.a[1][2]) / d;
    r.a[2][0] = (m.a[1][0] * m.a[2][1] - m.a[1][1] * m.a[2][0]) / d;
    r.a[2][1] = (m.a[0][1] * m.a[2][0] - m.a[0][0] * m.a[2][1]) / d;
    r.a[2][2] = (m.a[0][0] * m.a[1][1] - m.a[0][1] * m.a[1][0]) / d;
    return r;
  }

  // Invariants used by tests and plasticity: mean stress and J2.
  template <typename Real>
  MPM_HOST_DEVICE inline Real mean_stress(const SymTensor<Real> &s)
  {
    return trace(s) / Real(3);
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Real second_deviatoric_invariant(const SymTensor<Real> &s)
  {
    const Real p = mean_stress(s);
    const Real dx = s[0] - p, dy = s[1] - p, dz = s[2] - p;
    return Real(0.5) * (dx * dx + dy * dy + dz * dz) + s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
  }

  template <typename Real>
  MPM_HOST_DEVICE inline Real third_invariant(const SymTensor<Real> &s)
  {
    return determinant(to_matrix(s));
  }
} // namespace mpm
