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
