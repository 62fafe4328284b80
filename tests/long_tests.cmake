# Tests that carry the label long: scripts/test.sh (the suite CI runs) leaves them out, --full runs
# them (doc/guards.md, "Test tiers"). Each took over 40 s on the 2-core VM (2026-12-07) and repeats
# what a shorter test checks on fewer ranks than the VM has cores for, in 3D where a 2D twin runs,
# or over a whole collapse; the stability matrix (tests/stability, every cell labelled long there)
# is the record behind doc/methods.md's table.
set(MPM_LONG_TESTS
  prm/mpi/nodes_near_material_np4_cells_partition # 4 ranks on 2 cores; np2 variants stay
  prm/mpi/nodes_near_material_np3                 # 3 ranks; np2 variants stay
  prm/mpi/nodes_near_material_3d_np2              # 3D twin of the np2 2D tests
  prm/nodes_near_material_3d                      # 3D twin of prm/nodes_near_material_*
  prm/collapse_v3_coarse_3d                       # 3D twin of prm/collapse_v3_coarse_2d*
  prm/collapse_v3_2d_pure_flip_disconnected       # a whole V3 collapse (220 s)
  prm/threads_bit_identical_3d                    # 3D twin of prm/threads_bit_identical_2d
  fem/test_prefailure_np4                         # 4 ranks; np1 and np2 stay
)
