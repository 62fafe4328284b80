// mpm::cuda::DeviceEngine with Grid/Nodes = near material: the nodes within the blocks near
// the points, chosen on the device, and their download for output.
#include "engine_state.cuh"

namespace mpm
{
  namespace cuda
  {
    namespace
    {
      // The indices i < n with marks[i] != 0, in no fixed order, and their count.
      __global__ void marked_indices_kernel(const long n, const std::uint8_t *marks, int *list, int *count)
      {
        const long i = blockIdx.x * static_cast<long>(blockDim.x) + threadIdx.x;
        if (i < n && marks[i] != 0)
          list[atomicAdd(count, 1)] = static_cast<int>(i);
      }

      // table[at[k]] = k (to_slot) or -1, k < m: a block table's entries set or cleared.
      __global__ void set_table_entries_kernel(const int m, const long *at, int *table, const bool to_slot)
      {
        const int k = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
        if (k < m)
          table[at[k]] = to_slot ? k : -1;
      }
    } // namespace

    template <int dim, typename Real>
    int DeviceEngine<dim, Real>::keep_nodes_near_points(const int block_cells, const FaceConditions<dim> &faces)
    {
      impl->finish_pending_averaging(); // its cell sums live in the arrays replaced below
      // On the device: every point's current cell becomes its home cell (upload order), and
      // the blocks holding a point's cell are marked; only the marks come to the host.
      const int                   n = impl->points.size();
      const PointsView<dim, Real> p = impl->points.view();
      const GridView<dim, Real>   g = impl->grid.view();
      impl->home_cells.resize(n);
      impl->block_marks.resize(n_blocks<dim>(g.n_cells, block_cells));
      impl->block_marks.fill_bytes(0);
      long               *home     = impl->home_cells.data();
      std::uint8_t       *marks    = impl->block_marks.data();
      const int          *original = impl->order.original_index(); // slot -> upload order
      if (n > 0)
        impl->backend.for_each_node(n, [=] MPM_HOST_DEVICE(const int i) {
          Real x[dim];
          for (int d = 0; d < dim; ++d)
            x[d] = p.position[d][i];
          const long cell   = lattice_cell_containing<dim>(g.origin, g.h, g.n_cells, x);
          home[original[i]] = cell;
          if (p.material[i] >= 0)
            marks[block_of_cell<dim>(cell, g.n_cells, block_cells)] = 1; // the same value from every writer
        });
      impl->home_by_slot_stale = true;
      // The marked blocks listed on the device; only the list comes to the host.
      const long n_cell_blocks = n_blocks<dim>(g.n_cells, block_cells);
      impl->holding_list.resize(std::max<long>(std::min<long>(n_cell_blocks, n), 1));
      impl->holding_count.resize(1);
      impl->holding_count.fill_bytes(0);
      const cudaStream_t stream = impl->backend.get_stream();
      if (n > 0)
        {
          marked_indices_kernel<<<static_cast<unsigned int>((n_cell_blocks + 255) / 256), 256, 0, stream>>>(
            n_cell_blocks, marks, impl->holding_list.data(), impl->holding_count.data());
          MPM_CUDA_CHECK_LAUNCH();
        }
      int n_holding = 0;
      MPM_CUDA_CHECK(
        cudaMemcpyAsync(&n_holding, impl->holding_count.data(), sizeof(int), cudaMemcpyDeviceToHost, stream));
      MPM_CUDA_CHECK(cudaStreamSynchronize(stream));
      std::vector<int> holding_ints(n_holding);
      if (n_holding > 0)
        MPM_CUDA_CHECK(cudaMemcpy(holding_ints.data(), impl->holding_list.data(), n_holding * sizeof(int),
                                  cudaMemcpyDeviceToHost));
      if (!impl->chooser)
        impl->chooser = std::make_unique<NodeBlockChooser<dim>>(g.n_cells, block_cells);
      NodeBlockChooser<dim> &chooser = *impl->chooser;
      chooser.choose(std::vector<long>(holding_ints.begin(), holding_ints.end()));
      NodeBox<dim>           box;
      const bool             as_box = box_of_kept_blocks<dim>(g.n_cells, block_cells, chooser.kept_blocks(), box);
      const NodeBlocks<dim> &blocks = chooser.nodes();
      const std::vector<long> box_lattice = as_box ? lattice_of_box_nodes<dim>(g.n_cells, box) : std::vector<long>();
      const std::vector<long> &lattice_of_node = as_box ? box_lattice : blocks.lattice_of_node;
      const long               n_nodes         = static_cast<long>(lattice_of_node.size());
      if (n_nodes > std::numeric_limits<int>::max())
        throw std::length_error("DeviceEngine: more nodes near the points than an int can count");
      std::vector<std::uint8_t> node_fixed, node_friction;
      kept_node_boundary_masks<dim>(faces, g.n_cells, lattice_of_node, node_fixed, node_friction);
      if (as_box)
        impl->grid.set_box(box.lower, box.nodes, node_fixed, node_friction);
      else
        {
          // The device's table: the entries set last cleared, the kept node blocks set to
          // their slots; allocated (every entry -1) at the first use.
          DeviceArray<int> &table = impl->grid.block_slot;
          if (table.size() == 0)
            {
              table.resize(blocks.block_slot.size());
              table.fill_bytes(0xff); // -1
            }
          auto set_entries = [&](const std::vector<long> &at, const bool to_slot) {
            if (at.empty())
              return;
            impl->table_entries.upload(at);
            set_table_entries_kernel<<<static_cast<unsigned int>((at.size() + 255) / 256), 256, 0, stream>>>(
              static_cast<int>(at.size()), impl->table_entries.data(), table.data(), to_slot);
            MPM_CUDA_CHECK_LAUNCH();
            MPM_CUDA_CHECK(cudaStreamSynchronize(stream)); // before the buffer is filled again
          };
          set_entries(impl->table_entries_set, false);
          set_entries(chooser.kept_node_blocks(), true);
          impl->table_entries_set = chooser.kept_node_blocks();
          impl->grid.use_blocks(blocks.block_cells, blocks.node_blocks, node_fixed, node_friction);
        }
      impl->numbered_by_blocks = !as_box;
      impl->cell_sums_at_nodes = true;
      if (impl->cell_volume.size() > 0)
        {
          impl->cell_volume.resize(n_nodes);
          impl->cell_pressure_volume.resize(n_nodes);
        }
      return static_cast<int>(n_nodes);
    }

    template <int dim, typename Real>
    GridView<dim, double> DeviceEngine<dim, Real>::download_kept_nodes(HostGrid<dim, double> &nodes,
                                                                 std::vector<long>     &lattice_of_node) const
    {
      impl->backend.synchronize();
      const DeviceGrid<dim, Real> &dg = impl->grid;
      nodes.h                         = dg.h;
      for (int d = 0; d < dim; ++d)
        {
          nodes.origin[d]  = dg.origin[d];
          nodes.n_cells[d] = dg.n_cells[d];
        }
      std::vector<Real> staging;
      auto              download = [&](const DeviceArray<Real> &from, std::vector<double> &to) {
        from.download(staging);
        to.assign(staging.begin(), staging.end());
      };
      download(dg.mass, nodes.mass);
      for (int d = 0; d < dim; ++d)
        download(dg.velocity[d], nodes.velocity[d]);
      const bool as_box = !impl->numbered_by_blocks;
      lattice_of_node   = as_box ? lattice_of_box_nodes<dim>(dg.n_cells, impl->node_box()) :
                                   impl->chooser->nodes().lattice_of_node;
      GridView<dim, double> view = make_grid_view<dim, double>(nodes);
      view.lattice_to_node       = nullptr;
      if (as_box)
        for (int d = 0; d < dim; ++d)
          {
            view.box_lower[d] = dg.box_lower[d];
            view.box_nodes[d] = dg.box_nodes[d];
          }
      else
        {
          const NodeBlocks<dim> &blocks = impl->chooser->nodes(); // valid until the next choice
          view.set_block_table(blocks.block_slot.data(), blocks.block_cells, blocks.node_blocks);
        }
      return view;
    }

    template <int dim, typename Real>
    bool DeviceEngine<dim, Real>::kept_nodes_are_box() const
    {
      return impl->grid.lattice_order;
    }

#define MPM_INSTANTIATE(dim, Real) \
  template int DeviceEngine<dim, Real>::keep_nodes_near_points(const int, const FaceConditions<dim> &); \
  template GridView<dim, double> DeviceEngine<dim, Real>::download_kept_nodes(HostGrid<dim, double> &, std::vector<long> &) const; \
  template bool DeviceEngine<dim, Real>::kept_nodes_are_box() const;

    MPM_DEVICE_ENGINE_TYPES(MPM_INSTANTIATE)
#undef MPM_INSTANTIATE
  } // namespace cuda
} // namespace mpm
