// What every member of the shape-function family (shape_family.h) declares. A member is a
// struct of constants and static functions:
//   name, description                  its prm name (Solver/Shape function) and a clause for
//                                      the entry's documentation
//   owner                              always, or test (in the prm only after register_test_shapes())
//   tensor_product, n_per_direction    tensor product of 1D weights over n nodes per direction;
//                                      non-tensor members (CPDI) give domain_values<dim> instead
//   weights_1d(s, lp, first, w, dw)    MPM_HOST_DEVICE: the stencil's first node and its weights
//                                      and derivatives along one direction, in cell units
//   folds_boundary                     fold_boundary moves ghost-node weights onto the lattice
//   tracks_corners                     the domain's corners are state variables (CPDI2q)
//   point_domain                       GIMP-like half-lengths, which Solver/GIMP domain update moves
//   safe_distance_outside_home_cell    how far (cell units, max-norm) a point may leave the cell it
//                                      was sorted into while its stencil stays within that cell's
//                                      nodes and the ring around them (migration.h); below 0 or a
//                                      non-tensor stencil: the member runs on one MPI rank
//   apic, apic_inertia_over_h2         APIC's B D^-1 runs with it; its constant D_p / h^2, 0 where
//                                      B D^-1 is the gradient form (linear weights)
//   in_3d                              it exists in three dimensions
#pragma once

namespace mpm
{
  enum class ShapeOwner : int
  {
    always, // in every program's prm
    test    // a test's member: in the prm only where register_test_shapes() is called
  };
} // namespace mpm
