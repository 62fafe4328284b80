# Run times of the longest tests in seconds (2-core development VM, 2026-12-03), handed to ctest
# as COST by mpm_finish_tests (top-level CMakeLists.txt). A fresh build has no timing history, so
# ctest would start these in the order they are declared and some would run alone at the end of
# `ctest -j`; with COST they start first. Only the order changes, never what a test checks.
if(MPM_SANITIZE) # ASan + UBSan at -O1 (scripts/dev/sanitize.sh)
  set(MPM_TEST_COSTS
    core/test_domain_update 177
    core/test_wall_friction 168
    core/test_hold_points 104
    core/test_elastic_column 96
    core/test_local_damping 65
    core/test_manufactured_solution 53
    core/test_transfer_conservation 30
    prm/smoke/column_aspect_ratio_3d 30
    prm/fuzz_mutations_sanitized 22
    prm/mpi/one_rank_start_np12 12
  )
else()
  set(MPM_TEST_COSTS
    prm/collapse_v3_coarse_3d 103
    prm/collapse_v3_2d_pure_flip_disconnected 74
    prm/nodes_near_material_3d 72
    prm/column_v6_reduced 66
    prm/fuzz_mutations 58
    prm/mpi/fuzz_mutations_np2 48
    examples/elastic_slope_handoff 48
    prm/checkpoint/TERM_prefailure_resume 34
    core/test_domain_update 33
    stability/flip_noise/linear 33
    fem/test_prefailure_np4 30
    fem/test_infinite_slope 27
    examples/custom_material 27
    fem/test_prefailure_np2 25
    core/test_wall_friction 21
    study/reduced 20
    prm/collapse_small_2d_flip_velocity_change 19
    prm/collapse_small_2d_float_settled_np1 18
    prm/checkpoint/resume_each_np2 17
    examples/geostatic_column 16
    stability/locking/cpdi2q 16
    stability/flip_noise/cpdi 16
    dealii/fem_state_file 15
    stability/flip_noise/cpgimp_u_hencky 15
    prm/method_auto_v3 14
    prm/prefailure_end_to_end_2d 14
    prm/checkpoint/KILL_np2_resume_np2_and_np1 20
    prm/smoke/granular_collapse_3d 13
    prm/collapse_small_2d_float_settled_np2 13
    prm/mpi/column_v6_friction_np12 13
    stability/flip_noise/ugimp_tpic 13
    stability/flip_noise/bspline2_apic 13
    prm/smoke/slope_strength_reduction_2d 12
    prm/collapse_v3_coarse_2d_tpic 12
    prm/slump_v5_force_norm 12
    prm/collapse_v3_coarse_2d_apic 11
    prm/nodes_near_material_two_bodies_table 11
    prm/checkpoint/TERM_np1_resume_np1 11
    prm/checkpoint/KILL_np1_resume_np1_nodes_near_material 11
    prm/checkpoint/resume_each_np2_float 11
    stability/locking/ugimp_tpic 11
    stability/locking/cpgimp_u_hencky 11
    stability/locking/cpdi 11
    stability/flip_noise/cpgimp_det_f 11
    stability/flip_noise/bspline3 11
    prm/slump_v5_reduced 10
  )
endif()
