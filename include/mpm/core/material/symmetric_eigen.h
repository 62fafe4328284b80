// Eigen-decomposition of a symmetric 3x3 tensor by cyclic Jacobi rotations: plain,
// branch-light, host and device, accurate to round-off also for repeated eigenvalues
// (where closed-form trigonometric solutions lose digits).
#pragma once

#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  // values[k] and column k of vectors (vectors.a[i][k]) form the k-th eigenpair; sorted so
  // that values[0] >= values[1] >= values[2]; the columns are orthonormal.
  template <typename Real>
  MPM_HOST_DEVICE inline void symmetric_eigen(const SymTensor<Real> &t, Real values[3], Mat3<Real> &vectors)
  {
    Mat3<Real> a = to_matrix(t);
    Mat3<Real> v = Mat3<Real>::identity();
    const Real eps = sizeof(Real) == 4 ? Real(1.2e-7) : Real(2.3e-16);
    for (int sweep = 0; sweep < 50; ++sweep)
      {
        const Real off = a.a[0][1] * a.a[0][1] + a.a[0][2] * a.a[0][2] + a.a[1][2] * a.a[1][2];
        const Real dia = a.a[0][0] * a.a[0][0] + a.a[1][1] * a.a[1][1] + a.a[2][2] * a.a[2][2];
        if (!(off > eps * eps * (dia + off))) // also stops on off == 0 and on NaN
          break;
        for (int pq = 0; pq < 3; ++pq)
          {
            const int p = pq == 2 ? 1 : 0;
            const int q = pq == 0 ? 1 : 2;
            const Real apq = a.a[p][q];
            if (apq == Real(0))
              continue;
            const Real theta = (a.a[q][q] - a.a[p][p]) / (Real(2) * apq);
            const Real at    = std::abs(theta);
            Real tn          = at > Real(1e18) ? Real(0.5) / at : Real(1) / (at + std::sqrt(theta * theta + Real(1)));
            if (theta < Real(0))
              tn = -tn;
            const Real c = Real(1) / std::sqrt(tn * tn + Real(1));
            const Real s = tn * c;
            for (int k = 0; k < 3; ++k) // A <- A J
              {
                const Real akp = a.a[k][p], akq = a.a[k][q];
                a.a[k][p] = c * akp - s * akq;
                a.a[k][q] = s * akp + c * akq;
              }
            for (int k = 0; k < 3; ++k) // A <- J^T A
              {
                const Real apk = a.a[p][k], aqk = a.a[q][k];
                a.a[p][k] = c * apk - s * aqk;
                a.a[q][k] = s * apk + c * aqk;
              }
            a.a[p][q] = a.a[q][p] = Real(0);
            for (int k = 0; k < 3; ++k) // V <- V J
              {
                const Real vkp = v.a[k][p], vkq = v.a[k][q];
                v.a[k][p] = c * vkp - s * vkq;
                v.a[k][q] = s * vkp + c * vkq;
              }
          }
      }
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2 - i; ++j)
        if (a.a[order[j]][order[j]] < a.a[order[j + 1]][order[j + 1]])
          {
            const int tmp = order[j];
            order[j]      = order[j + 1];
            order[j + 1]  = tmp;
          }
    for (int k = 0; k < 3; ++k)
      {
        values[k] = a.a[order[k]][order[k]];
        for (int i = 0; i < 3; ++i)
          vectors.a[i][k] = v.a[i][order[k]];
      }
  }

  // sum_k values[k] v_k v_k^T
  template <typename Real>
  MPM_HOST_DEVICE inline SymTensor<Real> from_principal(const Real values[3], const Mat3<Real> &vectors)
  {
    SymTensor<Real> t = SymTensor<Real>::zero();
    const int       row[6] = {0, 1, 2, 0, 1, 0}, col[6] = {0, 1, 2, 1, 2, 2};
    for (int c = 0; c < n_voigt; ++c)
      for (int k = 0; k < 3; ++k)
        t[c] += values[k] * vectors.a[row[c]][k] * vectors.a[col[c]][k];
    return t;
  }
} // namespace mpm
