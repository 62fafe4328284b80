# Sourced by the counter scripts: NCU_STEP_METRICS, the Nsight Compute metrics of one step's launches
# (benchmarks/gpu-lab/ncu_step_table.py reads them back).
M=gpu__time_duration.sum,dram__bytes_read.sum,dram__bytes_write.sum
M=$M,dram__throughput.avg.pct_of_peak_sustained_elapsed,lts__throughput.avg.pct_of_peak_sustained_elapsed
M=$M,l1tex__throughput.avg.pct_of_peak_sustained_elapsed,sm__throughput.avg.pct_of_peak_sustained_elapsed
M=$M,smsp__issue_active.avg.pct_of_peak_sustained_elapsed,lts__t_sectors_op_red.sum,lts__t_sectors_op_atom.sum
M=$M,lts__t_sector_hit_rate.pct,l1tex__t_sectors_pipe_lsu_mem_local_op_ld.sum,l1tex__t_sectors_pipe_lsu_mem_local_op_st.sum
NCU_STEP_METRICS=$M,sm__warps_active.avg.pct_of_peak_sustained_active,launch__registers_per_thread
