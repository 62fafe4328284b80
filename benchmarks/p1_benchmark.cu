// Benchmark P1 of ../shared/BENCHMARKS.md on the CUDA backend: the 3D slump (ep2-3De's
// performance scene), elastic phase (8 s of ramped gravity), 3D GIMP (cpGIMP, det F),
// MUSL, pure FLIP, 8 points per cell, local damping 0.1, free-slip walls and base.
// Linear elastic (Jaumann) stands in for Drucker-Prager until that model lands.
// Generates the scene itself (no deal.II), runs the same step.h as the CPU, and prints per
// size: points, cells, nodes, steps, wall s, point-updates/s, the bytes a step must move,
// that traffic over the measured device-to-device copy bandwidth, and ep2-3De's MTP_eff.
//
// Usage: p1_benchmark [--fp32] [--sizes 20,160,640,2560] [--steps N] [--profile]
//                     [--table FILE]
//   --sizes   cells across (L_y / h): 20, 160, 640, 2560 give 100,240 ... 12,830,720 points
//   --steps N stop after N steps instead of at 8 s (for sizes too large to run in full)
//   --profile after the timed run, time each launch of 5 more steps (events per launch)
//   --table   append the result rows (markdown) to FILE
//   --order   generated (y-slice, then z rows, then x: the order ep2-3De's setup makes),
//             cell (sorted by cell index, x fastest: what sorting by cell would give),
//             random (shuffled: the worst case for the atomic scatter)
//   --block N threads per block of the point and node loops (default 128)
//   --material elastic|dp|mc   linear elastic stand-in, ep2-3De's Drucker-Prager (default dp), or
//                           Mohr-Coulomb with the same strengths (runs the DevicePhysics::all kernels)
//   --sort-every N          sort the points by stencil on the device every N steps (0: never;
//                           default 20), so that the warp adders reduce runs of shared nodes
//   --shape gimp|linear|bspline2|bspline3|bspline3gimp|cpdi   the shape function (default gimp;
//                                                bspline3gimp: the cubic B-spline GIMP, --domain as for GIMP)
//   --domain detF|Fii|U|none                GIMP's domain update (default detF, P1's own)
//   --fused                 the fused step (step.h, FusedTransfer): each step's kinematics carries
//                           the next step's P2G (the last timed step and the later sections run
//                           unfused); the sanity columns show whether the physics stayed the same
// p1_benchmark_scene_only (MPM_P1_SCENE_ONLY) holds P1's own step alone (3D GIMP, FP64 or FP32, the
// standard kernels) and refuses the options that need others: a build of minutes instead of about 20 on the
// 2-core machine, for trying a kernel change before building everything.
//   --launch-modes N        after the timed run, N steps at a fixed time step three ways: the
//                           reduction read back after every step (as the programs run), never
//                           read back (the host runs ahead), and each step one CUDA graph
#include "p1_scene.h"

#include <mpm/core/backend/cuda_backend.h>
#include <mpm/core/backend/cuda_point_order.h>
#include <mpm/core/backend/cuda_storage.h>
#include <mpm/core/step.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <stdexcept>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

using namespace mpm;
using mpm_bench::P1;

namespace
{
  struct Options
  {
    bool             fp32    = false;
    bool             profile = false;
    long             steps   = -1;
    std::vector<int> sizes   = {20, 160, 640, 2560};
    std::string      table;
    std::string      order = "generated";
    int              block = 128;
    bool             drucker_prager = true;
    bool             mohr_coulomb   = false; // with drucker_prager: Mohr-Coulomb in its place
    int              sort_every     = 20;
    ShapeFunction    shape          = ShapeFunction::gimp;
    DomainUpdate     domain         = DomainUpdate::det_F; // GIMP's; P1's own is det F
    // --transfer tpic|apic: an affine transfer instead of P1's FLIP/PIC blend; --law hencky.
    // Either, or --domain U, runs the step's kernels that hold them (DevicePhysics::all).
    bool             affine   = false;
    AffineMatrix     affine_matrix = AffineMatrix::velocity_gradient;
    bool             hencky   = false;
    bool all_physics() const { return affine || hencky || mohr_coulomb || domain == DomainUpdate::U; }
    long             launch_mode_steps = 0;
    bool             fused             = false;
  };

  // What the host's round trip per step and the launches themselves cost: N steps at a fixed
  // time step (a measurement, not a run: the gravity and the time step stay as they are)
  // (1) reading the step's reduction back as the programs do, (2) not reading it back, so
  // that the host queues launches ahead of the device, (3) each step one CUDA graph,
  // captured again after each sort (the sort swaps the point arrays the kernels hold).
  template <typename StepF, typename SortF>
  void time_launch_modes(CudaBackend &backend, StepF &&step, SortF &&sort_if_due, const double dt, const long n_steps,
                         const int n_points)
  {
    const cudaStream_t stream = backend.get_stream();
    auto timed = [&](auto &&body) {
      backend.synchronize();
      const auto t0 = std::chrono::steady_clock::now();
      body();
      backend.synchronize();
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() * 1e3 / n_steps;
    };
    const double read_back_ms = timed([&] {
      for (long i = 0; i < n_steps; ++i)
        {
          sort_if_due(i);
          step(dt);
        }
    });
    backend.keep_reductions_on_device = true;
    const double ahead_ms = timed([&] {
      for (long i = 0; i < n_steps; ++i)
        {
          sort_if_due(i);
          step(dt);
        }
    });
    cudaGraphExec_t exec     = nullptr;
    int             captures = 0;
    auto            capture  = [&] {
      cudaGraph_t graph;
      MPM_CUDA_CHECK(cudaStreamBeginCapture(stream, cudaStreamCaptureModeThreadLocal));
      step(dt);
      MPM_CUDA_CHECK(cudaStreamEndCapture(stream, &graph));
      if (exec != nullptr)
        MPM_CUDA_CHECK(cudaGraphExecDestroy(exec));
      MPM_CUDA_CHECK(cudaGraphInstantiate(&exec, graph, 0));
      MPM_CUDA_CHECK(cudaGraphDestroy(graph));
      ++captures;
    };
    const double graph_ms = timed([&] {
      for (long i = 0; i < n_steps; ++i)
        {
          if (sort_if_due(i) || exec == nullptr)
            capture();
          MPM_CUDA_CHECK(cudaGraphLaunch(exec, stream));
        }
    });
    backend.keep_reductions_on_device = false;
    if (exec != nullptr)
      MPM_CUDA_CHECK(cudaGraphExecDestroy(exec));
    // The kernels alone: the same step's launches timed with events, 5 steps.
    backend.enable_kernel_timing(true);
    double kernels_ms = 0;
    for (int i = 0; i < 5; ++i)
      {
        step(dt);
        for (const float t : backend.kernel_times_ms())
          kernels_ms += t / 5;
      }
    backend.enable_kernel_timing(false);
    std::printf("  launch modes, %d points, %ld steps each, ms per step: read back every step %.4f, host ahead "
                "%.4f, one graph per step %.4f (%d captures); the launches' own times sum to %.4f\n",
                n_points, n_steps, read_back_ms, ahead_ms, graph_ms, captures, kernels_ms);
    std::fflush(stdout);
  }

  // Reorder every point array by perm (new point i is old point perm[i]).
  template <typename Real>
  void permute(HostPoints<3, Real> &p, const std::vector<int> &perm)
  {
    auto apply = [&](auto &v) {
      auto copy = v;
      for (size_t i = 0; i < perm.size(); ++i)
        v[i] = copy[perm[i]];
    };
    for (int d = 0; d < 3; ++d)
      {
        apply(p.position[d]);
        apply(p.velocity[d]);
        apply(p.domain_half_length[d]);
        apply(p.initial_domain_half_length[d]);
      }
    for (int c = 0; c < n_voigt; ++c)
      {
        apply(p.stress[c]);
        apply(p.strain[c]);
      }
    for (int c = 0; c < 9; ++c)
      apply(p.deformation_gradient[c]);
    apply(p.mass);
    apply(p.volume);
    apply(p.initial_volume);
    apply(p.plastic_strain);
    apply(p.material);
  }

  template <typename Real>
  void reorder(HostPoints<3, Real> &p, const HostGrid<3, Real> &g, const std::string &order)
  {
    if (order == "generated")
      return;
    std::vector<int> perm(p.size());
    for (int i = 0; i < p.size(); ++i)
      perm[i] = i;
    if (order == "random")
      {
        std::mt19937 rng(1);
        std::shuffle(perm.begin(), perm.end(), rng);
      }
    else if (order == "cell")
      {
        std::vector<long> cell(p.size());
        for (int i = 0; i < p.size(); ++i)
          {
            long c = 0;
            for (int d = 2; d >= 0; --d)
              c = c * g.n_cells[d] + static_cast<long>(std::floor((p.position[d][i] - g.origin[d]) / g.h));
            cell[i] = c;
          }
        std::stable_sort(perm.begin(), perm.end(), [&](int a, int b) { return cell[a] < cell[b]; });
      }
    else
      throw std::runtime_error("unknown --order " + order);
    permute(p, perm);
  }

  // Device-to-device copy bandwidth, bytes read + bytes written per second.
  double copy_bandwidth()
  {
    const size_t       bytes = size_t(2) << 30;
    DeviceArray<char>  a(bytes), b(bytes);
    a.fill_bytes(1);
    cudaEvent_t start, stop;
    MPM_CUDA_CHECK(cudaEventCreate(&start));
    MPM_CUDA_CHECK(cudaEventCreate(&stop));
    for (int i = 0; i < 3; ++i)
      MPM_CUDA_CHECK(cudaMemcpyAsync(b.data(), a.data(), bytes, cudaMemcpyDeviceToDevice));
    const int reps = 20;
    MPM_CUDA_CHECK(cudaEventRecord(start));
    for (int i = 0; i < reps; ++i)
      MPM_CUDA_CHECK(cudaMemcpyAsync(i % 2 ? a.data() : b.data(), i % 2 ? b.data() : a.data(), bytes,
                                     cudaMemcpyDeviceToDevice));
    MPM_CUDA_CHECK(cudaEventRecord(stop));
    MPM_CUDA_CHECK(cudaEventSynchronize(stop));
    float ms = 0;
    MPM_CUDA_CHECK(cudaEventElapsedTime(&ms, start, stop));
    MPM_CUDA_CHECK(cudaEventDestroy(start));
    MPM_CUDA_CHECK(cudaEventDestroy(stop));
    return 2.0 * double(bytes) * reps / (ms * 1e-3);
  }

  // Fewest bytes one MUSL step of this implementation must move through device memory:
  // every point array it reads, read once (position, velocity, mass, volume, V0, stress,
  // strain, F, domain half-lengths and their initial values, plastic strain: 37 reals,
  // and the material id), every one it writes, written once (position, velocity, volume,
  // stress, strain, F, half-lengths, plastic strain: 32 reals), and the nodal arrays
  // (mass, momentum, force, velocity: 10 reals) written once and read once, with the
  // boundary mask and the lattice-to-node lookup read once.
  template <typename Real>
  double minimal_bytes_per_step(const double n_points, const double n_nodes)
  {
    return n_points * (69.0 * sizeof(Real) + sizeof(int)) + n_nodes * (20.0 * sizeof(Real) + 5.0);
  }

  const char *musl_launch_names[] = {"reset grid",     "P2G mass+momentum+forces", "grid update",
                                     "G2P velocity + remap P2G", "nodal velocity",
                                     "G2P kinematics+stress", "reduction (dt)"};
  constexpr int n_musl_launches = 7;
  // A fused step's launches: the P2G runs inside the last step's kinematics.
  const char *fused_launch_names[] = {"grid update", "G2P velocity + remap P2G", "nodal velocity",
                                      "reset grid", "G2P kinematics+stress+next P2G", "reduction (dt)"};
  constexpr int n_fused_launches = 6;

  template <typename Real>
  bool run_size(const int n_cells_y, const Options &opt, const double bandwidth, FILE *table)
  {
    // Memory: points, grid, and a margin.
    std::vector<double> xs, zs;
    mpm_bench::p1_slice(xs, zs);
    const double n_points_expected = double(xs.size()) * 2 * n_cells_y;
    const double n_nodes_expected  = double(80 + 2 * P1::ghost + 1) * (n_cells_y + 2 * P1::ghost + 1) * (P1::cells_z + 1);
    const double need = n_points_expected * DevicePoints<3, Real>::bytes_per_point() +
                        n_nodes_expected * (10.0 * sizeof(Real) + 5.0);
    size_t free_bytes = 0, total_bytes = 0;
    MPM_CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total_bytes));
    if (need > 0.95 * double(free_bytes))
      {
        std::printf("| %d cells across: %.0f points need %.1f GB, %.1f GB free: does not fit |\n", n_cells_y,
                    n_points_expected, need / 1e9, free_bytes / 1e9);
        return false;
      }

    const auto          t0 = std::chrono::steady_clock::now();
    HostGrid<3, Real>   grid;
    HostPoints<3, Real> points;
    std::vector<MaterialParameters<Real>> materials;
    mpm_bench::make_p1(n_cells_y, grid, points, materials, opt.drucker_prager, opt.mohr_coulomb);
    reorder(points, grid, opt.order);
    if (opt.affine) // the affine matrices, zero at the start
      points.set_n_state_variables(3 * 3);
    if (opt.hencky)
      for (MaterialParameters<Real> &m : materials)
        m.elastic_law = ElasticLaw::hencky;
    const int  n_points = points.size();
    const long n_cells  = long(grid.n_cells[0]) * grid.n_cells[1] * grid.n_cells[2];
    const int  n_nodes  = static_cast<int>(grid.mass.size());

    DeviceGrid<3, Real>     dgrid;
    DevicePoints<3, Real>   dpoints;
    DeviceMaterials<Real>   dmaterials;
    dgrid.upload(grid);
    dpoints.upload(points);
    dmaterials.upload(materials);
    const double setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    // A stream of its own where a step is captured into a graph (the legacy stream cannot be);
    // blocking, so that it stays ordered with the legacy stream's copies, as the engine's.
    cudaStream_t own_stream = nullptr;
    if (opt.launch_mode_steps > 0)
      MPM_CUDA_CHECK(cudaStreamCreate(&own_stream));
    CudaBackend backend(own_stream);
    backend.block_size = opt.block;
    PointOrder<3, Real> order;
    auto        gv = dgrid.view();
    auto        pv = dpoints.view();
    // Sorting swaps the point arrays: the view is taken again after each sort.
    auto sort_if_due = [&](const long step) {
      if (!(opt.sort_every > 0 && step % opt.sort_every == 0))
        return false;
#if defined(MPM_P1_SCENE_ONLY)
      order.template sort<GimpShape>(backend, gv, dpoints);
#else
      if (opt.shape == ShapeFunction::linear || opt.shape == ShapeFunction::cpdi) // CPDI: by the point's cell
        order.template sort<LinearShape>(backend, gv, dpoints);
      else if (opt.shape == ShapeFunction::bspline3)
        order.template sort<CubicBSplineShape>(backend, gv, dpoints);
      else if (opt.shape == ShapeFunction::bspline3_gimp)
        order.template sort<CubicBSplineGimpShape>(backend, gv, dpoints);
      else // GIMP and the quadratic B-spline share the stencil's first node
        order.template sort<GimpShape>(backend, gv, dpoints);
#endif
      pv = dpoints.view();
      return true;
    };
    StepSettings<3, Real> s = mpm_bench::p1_settings<Real>();
    s.domain_update         = opt.shape == ShapeFunction::gimp || opt.shape == ShapeFunction::bspline3_gimp ?
                                opt.domain :
                                DomainUpdate::none;
    if (opt.affine)
      {
        s.affine_state_variable = 0;
        s.affine_matrix         = opt.affine_matrix;
        s.flip_fraction         = 0;
      }
    const double          c = mpm_bench::p1_wave_speed();
    // fused (--fused): the step's P2G ran in the last step where that one carried it, and this
    // one carries the next one's where fused.carry_next is set.
    FusedTransfer<3, Real> fused;
    auto step = [&](const double dt) {
      FusedTransfer<3, Real> *f = opt.fused ? &fused : nullptr;
#if defined(MPM_P1_SCENE_ONLY)
      return explicit_step<3, GimpShape>(backend, gv, pv, dmaterials.data(), s, Real(dt), NoGridExchange(), nullptr,
                                         f);
#else
      return opt.all_physics() ?
               explicit_step<3, DevicePhysics::all>(backend, opt.shape, gv, pv, dmaterials.data(), s, Real(dt),
                                                    NoGridExchange(), nullptr, f) :
               explicit_step<3>(backend, opt.shape, gv, pv, dmaterials.data(), s, Real(dt), NoGridExchange(),
                                nullptr, f);
#endif
    };
    // Whether the step at time t with time step dt carries the next one's P2G, and with which gravity.
    auto plan_fusion = [&](const double t, const double dt, const bool next_runs) {
      fused.carry_next = opt.fused && next_runs;
      StepSettings<3, Real> next = s;
      mpm_bench::p1_gravity(next, t + dt);
      for (int d = 0; d < 3; ++d)
        fused.next_gravity[d] = next.gravity[d];
    };

    // Warm-up (module load, first launches), then back to the initial state.
    {
      double max_speed = 0, t = 0;
      for (int i = 0; i < 3; ++i)
        {
          sort_if_due(i);
          const double dt = P1::cfl * P1::h / (c + max_speed);
          mpm_bench::p1_gravity(s, t);
          plan_fusion(t, dt, i < 2);
          max_speed = step(dt).max_speed;
          t += dt;
        }
      dgrid.upload(grid);
      dpoints.upload(points);
      pv = dpoints.view();
      order.reset(backend, n_points);
      backend.synchronize();
    }

    cudaEvent_t start, stop;
    MPM_CUDA_CHECK(cudaEventCreate(&start));
    MPM_CUDA_CHECK(cudaEventCreate(&stop));
    double max_speed = 0, t = 0;
    long   steps     = 0;
    const auto wall0 = std::chrono::steady_clock::now();
    MPM_CUDA_CHECK(cudaEventRecord(start, backend.get_stream()));
    while (t < P1::t_end - 1e-9 && (opt.steps < 0 || steps < opt.steps))
      {
        sort_if_due(steps);
        const double dt = P1::cfl * P1::h / (c + max_speed);
        mpm_bench::p1_gravity(s, t);
        plan_fusion(t, dt, t + dt < P1::t_end - 1e-9 && (opt.steps < 0 || steps + 1 < opt.steps));
        max_speed = step(dt).max_speed;
        t += dt;
        ++steps;
      }
    fused.carry_next = false; // the sections below run unfused
    MPM_CUDA_CHECK(cudaEventRecord(stop, backend.get_stream()));
    MPM_CUDA_CHECK(cudaEventSynchronize(stop));
    const double host_wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    float        ms        = 0;
    MPM_CUDA_CHECK(cudaEventElapsedTime(&ms, start, stop));
    MPM_CUDA_CHECK(cudaEventDestroy(start));
    MPM_CUDA_CHECK(cudaEventDestroy(stop));
    const double wall = ms * 1e-3;

    // Sanity of the physics: no point lost or NaN; the deepest vertical stress against
    // the lithostatic rho g H of the 12.2 m column (gravity fully on after 5.33 s).
    HostPoints<3, Real> result;
    dpoints.download(result);
    int    removed = 0, non_finite = 0;
    double min_szz = 0, max_speed_end = 0;
    for (int i = 0; i < n_points; ++i)
      {
        if (result.material[i] < 0)
          ++removed;
        if (!std::isfinite(double(result.stress[2][i])) || !std::isfinite(double(result.position[2][i])))
          ++non_finite;
        min_szz = std::min(min_szz, double(result.stress[2][i]));
        double v2 = 0;
        for (int d = 0; d < 3; ++d)
          v2 += double(result.velocity[d][i]) * result.velocity[d][i];
        max_speed_end = std::max(max_speed_end, std::sqrt(v2));
      }

    std::string label = sizeof(Real) == 8 ? "FP64" : "FP32";
    if (opt.order != "generated")
      label += ", " + opt.order + " order";
    if (opt.block != 128)
      label += ", block " + std::to_string(opt.block);
    label += opt.mohr_coulomb ? ", MC" : opt.drucker_prager ? ", DP" : ", elastic";
    label += opt.shape == ShapeFunction::linear   ? ", linear" :
             opt.shape == ShapeFunction::bspline2 ? ", B-spline" :
             opt.shape == ShapeFunction::bspline3 ? ", cubic B-spline" :
             opt.shape == ShapeFunction::bspline3_gimp ? ", cubic B-spline GIMP" :
             opt.shape == ShapeFunction::cpdi     ? ", CPDI" : "";
    if (opt.shape == ShapeFunction::gimp || opt.shape == ShapeFunction::bspline3_gimp)
      label += opt.domain == DomainUpdate::U ? ", U domains" : opt.domain == DomainUpdate::stretch ? ", F_ii domains" :
               opt.domain == DomainUpdate::none ? ", uGIMP" : ", det F domains";
    if (opt.affine)
      label += opt.affine_matrix == AffineMatrix::b_d_inverse ? ", APIC" : ", TPIC";
    if (opt.hencky)
      label += ", Hencky";
    if (opt.fused)
      label += ", fused";
    label += opt.sort_every > 0 ? ", sorted every " + std::to_string(opt.sort_every) : ", unsorted";
    const double updates  = double(n_points) * steps / wall;
    const double bytes    = minimal_bytes_per_step<Real>(n_points, n_nodes);
    const double fraction = bytes * steps / wall / bandwidth;
    const double n_io     = 2.0 * n_points * (43 + 22 * 64) + 26.0 * n_nodes + 2.0 * n_cells;
    const double mtp_eff  = steps * n_io * sizeof(Real) / (1024.0 * 1024.0 * 1024.0 * wall);
    std::printf("| %s | %d | %ld | %d | %ld | %.3f | %.3e | %.1f | %.1f MB | %.3f | %.0f | %.3f | %.2f | %d | %d | %.3g |\n",
                label.c_str(), n_points, n_cells, n_nodes, steps, wall, updates,
                wall / steps * 1e3, bytes / 1e6, fraction, mtp_eff, host_wall, setup_s, removed, non_finite,
                -min_szz / (P1::rho * P1::gravity * 12.23));
    std::fflush(stdout);
    if (table != nullptr)
      {
        std::fprintf(table, "| %s | %d | %ld | %ld | %.3f | %.2e | %.2f | %.0f | %.3f | %.0f |\n",
                     label.c_str(), n_points, n_cells, steps, wall, updates,
                     wall / steps * 1e3, bytes / n_points, fraction, mtp_eff);
        std::fflush(table);
      }
    if (removed > 0 || non_finite > 0)
      std::printf("WARNING: %d points removed, %d non-finite\n", removed, non_finite);

    if (opt.profile)
      {
        // Fused: one step untimed that carries the next one's P2G, then every timed step carries
        // one too (the gravity as it is: the profile measures, it does not run on).
        const char *const *names = opt.fused ? fused_launch_names : musl_launch_names;
        if (opt.fused)
          {
            fused.carry_next = true;
            for (int d = 0; d < 3; ++d)
              fused.next_gravity[d] = s.gravity[d];
            max_speed = step(P1::cfl * P1::h / (c + max_speed)).max_speed;
          }
        backend.enable_kernel_timing(true);
        const int          n_prof = 5;
        std::vector<double> sum(opt.fused ? n_fused_launches : n_musl_launches, 0.0);
        for (int i = 0; i < n_prof; ++i)
          {
            const double dt = P1::cfl * P1::h / (c + max_speed);
            max_speed = step(dt).max_speed;
            const std::vector<float> times = backend.kernel_times_ms();
            for (size_t k = 0; k < times.size() && k < sum.size(); ++k)
              sum[k] += times[k];
          }
        backend.enable_kernel_timing(false);
        double total = 0;
        for (double v : sum)
          total += v;
        std::printf("  per-launch times, %s, %d points (mean of %d steps; sum %.3f ms/step vs %.3f ms/step timed):\n",
                    sizeof(Real) == 8 ? "FP64" : "FP32", n_points, n_prof, total / n_prof, wall / steps * 1e3);
        for (size_t k = 0; k < sum.size(); ++k)
          std::printf("    %-30s %8.3f ms  %5.1f%%\n", names[k], sum[k] / n_prof, 100 * sum[k] / total);
        if (table != nullptr)
          {
            std::fprintf(table, "\nPer-launch times, %s, %d points, ms per step (mean of %d steps):\n\n",
                         sizeof(Real) == 8 ? "FP64" : "FP32", n_points, n_prof);
            std::fprintf(table, "| launch | ms | share |\n|---|---|---|\n");
            for (size_t k = 0; k < sum.size(); ++k)
              std::fprintf(table, "| %s | %.3f | %.1f%% |\n", names[k], sum[k] / n_prof,
                           100 * sum[k] / total);
            std::fprintf(table, "\n");
          }
        fused.carry_next = false; // the last profiled step carried one: the next step adds no P2G of its own
      }
    if (opt.launch_mode_steps > 0)
      {
        time_launch_modes(backend, step, sort_if_due, P1::cfl * P1::h / (c + max_speed), opt.launch_mode_steps,
                          n_points);
        MPM_CUDA_CHECK(cudaStreamDestroy(own_stream));
      }
    return true;
  }
} // namespace

int main(int argc, char **argv)
{
  Options opt;
  for (int i = 1; i < argc; ++i)
    {
      const std::string a = argv[i];
      if (a == "--fp32")
        opt.fp32 = true;
      else if (a == "--profile")
        opt.profile = true;
      else if (a == "--steps" && i + 1 < argc)
        opt.steps = std::atol(argv[++i]);
      else if (a == "--order" && i + 1 < argc)
        opt.order = argv[++i];
      else if (a == "--material" && i + 1 < argc)
        {
          const std::string m = argv[++i];
          if (m != "dp" && m != "mc" && m != "elastic")
            {
              std::printf("--material: expected dp, mc or elastic, got %s\n", m.c_str());
              return 2;
            }
          opt.drucker_prager = m != "elastic";
          opt.mohr_coulomb   = m == "mc";
        }
      else if (a == "--sort-every" && i + 1 < argc)
        opt.sort_every = std::atoi(argv[++i]);
      else if (a == "--shape" && i + 1 < argc)
        {
          const std::string m = argv[++i];
          if (m != "gimp" && m != "linear" && m != "bspline2" && m != "bspline3" && m != "bspline3gimp" &&
              m != "cpdi")
            {
              std::printf("--shape: expected gimp, linear, bspline2, bspline3, bspline3gimp or cpdi, got %s\n",
                          m.c_str());
              return 2;
            }
          opt.shape = m == "gimp"         ? ShapeFunction::gimp :
                      m == "linear"       ? ShapeFunction::linear :
                      m == "bspline2"     ? ShapeFunction::bspline2 :
                      m == "bspline3gimp" ? ShapeFunction::bspline3_gimp :
                      m == "cpdi"         ? ShapeFunction::cpdi : ShapeFunction::bspline3;
        }
      else if (a == "--domain" && i + 1 < argc)
        {
          const std::string m = argv[++i];
          if (m != "detF" && m != "Fii" && m != "U" && m != "none")
            {
              std::printf("--domain: expected detF, Fii, U or none, got %s\n", m.c_str());
              return 2;
            }
          opt.domain = m == "detF" ? DomainUpdate::det_F : m == "Fii" ? DomainUpdate::stretch :
                       m == "U"    ? DomainUpdate::U : DomainUpdate::none;
        }
      else if (a == "--transfer" && i + 1 < argc)
        {
          const std::string m = argv[++i];
          if (m != "tpic" && m != "apic")
            {
              std::printf("--transfer: expected tpic or apic, got %s\n", m.c_str());
              return 2;
            }
          opt.affine        = true;
          opt.affine_matrix = m == "apic" ? AffineMatrix::b_d_inverse : AffineMatrix::velocity_gradient;
        }
      else if (a == "--law" && i + 1 < argc)
        {
          const std::string m = argv[++i];
          if (m != "hencky" && m != "jaumann")
            {
              std::printf("--law: expected jaumann or hencky, got %s\n", m.c_str());
              return 2;
            }
          opt.hencky = m == "hencky";
        }
      else if (a == "--fused")
        opt.fused = true;
      else if (a == "--launch-modes" && i + 1 < argc)
        opt.launch_mode_steps = std::atol(argv[++i]);
      else if (a == "--block" && i + 1 < argc)
        opt.block = std::atoi(argv[++i]);
      else if (a == "--table" && i + 1 < argc)
        opt.table = argv[++i];
      else if (a == "--sizes" && i + 1 < argc)
        {
          opt.sizes.clear();
          std::string list = argv[++i];
          size_t      pos  = 0;
          while (pos < list.size())
            {
              const size_t next = list.find(',', pos);
              opt.sizes.push_back(std::atoi(list.substr(pos, next - pos).c_str()));
              pos = next == std::string::npos ? list.size() : next + 1;
            }
        }
      else
        {
          std::printf("usage: %s [--fp32] [--sizes 20,160,640,2560] [--steps N] [--profile] [--table FILE]\n"
                      "          [--order generated|cell|random] [--block N] [--material dp|mc|elastic] [--sort-every N]\n"
                      "          [--shape gimp|linear|bspline2|bspline3|bspline3gimp|cpdi] [--domain detF|Fii|U|none]\n"
                      "          [--transfer tpic|apic] [--law jaumann|hencky] [--fused] [--launch-modes N]\n",
                      argv[0]);
          return 2;
        }
    }
  if (opt.affine && opt.affine_matrix == AffineMatrix::b_d_inverse &&
      (opt.shape == ShapeFunction::gimp || opt.shape == ShapeFunction::bspline3_gimp ||
       opt.shape == ShapeFunction::cpdi))
    {
      std::printf("--transfer apic: needs --shape linear, bspline2 or bspline3 (GIMP has no constant D_p; use "
                  "--transfer tpic)\n");
      return 2;
    }
  if (opt.fused && opt.affine)
    {
      std::printf("--fused: not with --transfer tpic|apic (the fused step runs the FLIP/PIC blend only)\n");
      return 2;
    }
#if defined(MPM_P1_SCENE_ONLY)
  if (opt.shape != ShapeFunction::gimp || opt.all_physics())
    {
      std::printf("%s: built for P1's own step only (3D GIMP, --domain detF|Fii|none, the FLIP/PIC blend, "
                  "Jaumann, no Mohr-Coulomb); --shape, --domain U, --transfer, --law hencky and --material mc need "
                  "p1_benchmark\n",
                  argv[0]);
      return 2;
    }
#endif
  if (cuda_device_count() == 0)
    {
      std::printf("p1_benchmark: no CUDA device found\n");
      return 77;
    }
  try
    {
      cudaDeviceProp prop;
      MPM_CUDA_CHECK(cudaGetDeviceProperties(&prop, 0));
      size_t free_bytes = 0, total_bytes = 0;
      MPM_CUDA_CHECK(cudaMemGetInfo(&free_bytes, &total_bytes));
      const double bandwidth = copy_bandwidth();
      std::printf("device: %s, %d SMs, %.1f GB (%.1f GB free), L2 %.0f MB; device-to-device copy %.0f GB/s "
                  "(read + write)\n",
                  prop.name, prop.multiProcessorCount, total_bytes / 1e9, free_bytes / 1e9, prop.l2CacheSize / 1e6,
                  bandwidth / 1e9);
      const double per_point = opt.fp32 ? DevicePoints<3, float>::bytes_per_point() : DevicePoints<3, double>::bytes_per_point();
      std::printf("scene P1 (elastic phase, %s), %s, point order %s, sorted every %d steps, %d threads per block; "
                  "device memory per point %.0f B: about %.0f M points would fit\n",
                  opt.mohr_coulomb   ? "Mohr-Coulomb with Drucker-Prager's strengths" :
                  opt.drucker_prager ? "Drucker-Prager" :
                                       "linear elastic stand-in for Drucker-Prager",
                  opt.fp32 ? "FP32" : "FP64", opt.order.c_str(), opt.sort_every, opt.block, per_point,
                  0.9 * free_bytes / (per_point * 1.1) / 1e6);
      std::printf("| prec | points | cells | nodes | steps | wall s | point-updates/s | ms/step | min bytes/step | "
                  "fraction of copy BW | MTP_eff GB/s | host wall s | setup s | removed | non-finite | "
                  "max|szz|/(rho g 12.23 m) |\n");
      std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
      FILE *table = opt.table.empty() ? nullptr : std::fopen(opt.table.c_str(), "a");
      for (const int n : opt.sizes)
        {
          if (opt.fp32)
            run_size<float>(n, opt, bandwidth, table);
          else
            run_size<double>(n, opt, bandwidth, table);
        }
      if (table != nullptr)
        std::fclose(table);
    }
  catch (const std::exception &e)
    {
      std::printf("p1_benchmark: %s\n", e.what());
      return 1;
    }
  return 0;
}
