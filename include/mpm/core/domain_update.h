// How a cpGIMP point's domain follows its deformation gradient F: the scale of each of
// its axis-aligned half-lengths against the initial ones. A plain function of the
// point's F, shared by the CPU and CUDA backends.
//   det F:   (det F)^(1/dim) on every axis (volume right, shape not);
//   F_ii:    |F_ii| on axis i (exact for stretch along the axes; a rotation by 90 degrees
//            drives F_ii to zero and the domain vanishes);
//   U:       U_ii, the diagonal of the right stretch tensor U = sqrt(F^T F) of the polar
//            decomposition F = R U (the stretch without the rotation: a rigid rotation
//            leaves the domain as it was, stretch along the axes gives F_ii).
#pragma once

#include <mpm/core/config.h>
#include <mpm/core/material/symmetric_eigen.h>
#include <mpm/core/small_tensor.h>

#include <cmath>

namespace mpm
{
  enum class DomainUpdate : int
  {
    none    = 0, // uGIMP: the domain keeps its initial size
    det_F   = 1, // cpGIMP: half-lengths scaled by (det F)^(1/dim)
    stretch = 2, // cpGIMP: half-length i scaled by |F_ii| (axes stretch only, not rotation)
    U       = 3  // cpGIMP: half-length i scaled by U_ii, U the right stretch tensor
  };

  // The diagonal of U = sqrt(C), C = F^T F, for the dim x dim F stored row-major in f.
  // 2D: U = (C + sqrt(det C) I) / sqrt(tr C + 2 sqrt(det C)) (Cayley-Hamilton, exact);
  // 3D: from the eigenpairs of C, U_ii = sum_k sqrt(c_k) v_ik^2.
  template <int dim, typename Real>
  MPM_HOST_DEVICE inline void right_stretch_diagonal(const Real *f, Real u[dim])
  {
    if constexpr (dim == 2)
      {
        const Real c00 = f[0] * f[0] + f[2] * f[2];
        const Real c11 = f[1] * f[1] + f[3] * f[3];
        const Real s   = std::fabs(f[0] * f[3] - f[1] * f[2]); // sqrt(det C) = |det F|
        const Real n   = std::sqrt(c00 + c11 + Real(2) * s);
        // F = 0 (a point crushed to nothing, which the step's checks report): U = 0, not 0/0
        u[0] = n > Real(0) ? (c00 + s) / n : Real(0);
        u[1] = n > Real(0) ? (c11 + s) / n : Real(0);
      }
    else
      {
        SymTensor<Real> c;
        const int       row[6] = {0, 1, 2, 0, 1, 0}, col[6] = {0, 1, 2, 1, 2, 2};
        for (int k = 0; k < 6; ++k)
          {
            Real sum = 0;
            for (int m = 0; m < 3; ++m)
              sum += f[m * 3 + row[k]] * f[m * 3 + col[k]];
            c[k] = sum;
          }
        Real       values[3];
        Mat3<Real> vectors;
        symmetric_eigen(c, values, vectors);
        for (int i = 0; i < 3; ++i)
          {
            Real sum = 0;
            for (int k = 0; k < 3; ++k)
              sum += std::sqrt(values[k] > Real(0) ? values[k] : Real(0)) * vectors.a[i][k] * vectors.a[i][k];
            u[i] = sum;
          }
      }
  }

  // scale[d]: the factor on the initial half-length along axis d; j = det F. with_u = false
  // leaves U's eigen decomposition out of the compiled code (the device's standard kernels,
  // step.h's DevicePhysics; explicit_step refuses U there).
  template <int dim, bool with_u = true, typename Real>
  MPM_HOST_DEVICE inline void gimp_domain_scale(const DomainUpdate update, const Real *f, const Real j,
                                                Real scale[dim])
  {
    if constexpr (with_u)
      if (update == DomainUpdate::U)
        {
          right_stretch_diagonal<dim>(f, scale);
          return;
        }
    const Real iso = dim == 2 ? std::sqrt(j) : std::cbrt(j);
    for (int d = 0; d < dim; ++d)
      scale[d] = update == DomainUpdate::det_F ? iso :
                 update == DomainUpdate::stretch ? std::fabs(f[d * dim + d]) : Real(1);
  }
} // namespace mpm
