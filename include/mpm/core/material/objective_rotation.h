// Objective integration of the Jaumann rate: the stress is rotated by the
// Hughes-Winget rotation Q = (I - dW/2)^-1 (I + dW/2), which is exactly orthogonal,
// so stress invariants survive any rigid rotation to round-off.
#pragma once

#include <mpm/core/small_tensor.h>

namespace mpm
{
  // dW: spin increment (skew part of the velocity gradient times dt).
  template <typename Real>
  MPM_HOST_DEVICE inline SymTensor<Real> rotate_jaumann(const SymTensor<Real> &stress,
                                                        const Mat3<Real>      &dW)
  {
    // Spin about z only (every 2D step: plane strain keeps row and column z of L zero):
    // with Omega = dW/2 = [[0, w], [-w, 0]], Q = (I - Omega)^-1 (I + Omega) is the rotation
    // [[c, s], [-s, c]], c = (1 - w^2)/(1 + w^2), s = 2w/(1 + w^2), in closed form. The same
    // Q as below up to round-off, at a fraction of the cost (no 3x3 inverse and products).
    if (dW.a[0][2] == Real(0) && dW.a[2][0] == Real(0) && dW.a[1][2] == Real(0) && dW.a[2][1] == Real(0) &&
        dW.a[0][0] == Real(0) && dW.a[1][1] == Real(0) && dW.a[2][2] == Real(0) && dW.a[1][0] == -dW.a[0][1])
      {
        const Real w = Real(0.5) * dW.a[0][1], w2 = w * w, inv = Real(1) / (Real(1) + w2);
        const Real c = (Real(1) - w2) * inv, s = Real(2) * w * inv;
        const Real cc = c * c, ss = s * s, cs = c * s;
        SymTensor<Real> r;
        r[0] = cc * stress[0] + Real(2) * cs * stress[3] + ss * stress[1];
        r[1] = ss * stress[0] - Real(2) * cs * stress[3] + cc * stress[1];
        r[2] = stress[2];
        r[3] = cs * (stress[1] - stress[0]) + (cc - ss) * stress[3];
        r[4] = c * stress[4] - s * stress[5]; // yz
        r[5] = c * stress[5] + s * stress[4]; // xz
        return r;
      }
    Mat3<Real> a = Mat3<Real>::identity(), b = Mat3<Real>::identity();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        {
          a.a[i][j] -= Real(0.5) * dW.a[i][j];
          b.a[i][j] += Real(0.5) * dW.a[i][j];
        }
    const Mat3<Real> Q = multiply(inverse(a), b);
    return symmetric_part(multiply(multiply(Q, to_matrix(stress)), transpose(Q)));
  }
} // namespace mpm
