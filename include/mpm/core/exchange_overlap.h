// Which points can add into the entries that ranks exchange (several ranks). A P2G pass
// over those points first, then the exchange of the sums, while a second pass adds the
// other points' contributions: the other points cannot touch an exchanged entry, so the
// sums that travel are complete, and nothing written during the second pass is sent or
// overwritten by the unpacked sums (DeviceEngine on several ranks, explicit_step).
//
// Between two MPI re-sorts a point stays less than safe_distance_outside_home_cell of its
// home cell (migration.h), so its stencil lies in the home cell's vertices and the ring
// of nodes around them: lattice nodes c - 1 .. c + 2 per direction for home cell c. The node
// window below also holds a point at exactly its safe distance (c + 3 then) and has a layer
// to spare below. The cell its pressure averaging adds into is where the step moved it: the
// cell window holds a point up to its safe distance out (a cell for linear shapes) moved by
// up to one more cell in the step.
#pragma once

#include <cstdint>
#include <vector>

namespace mpm
{
  // Offsets, per direction, from a home cell's index of the nodes and cells that its points
  // may add into (see above).
  constexpr int overlap_node_window_lower = -2, overlap_node_window_upper = 3;
  constexpr int overlap_cell_window_lower = -3, overlap_cell_window_upper = 3;

  namespace overlap_detail
  {
    // marks[i] = max of marks[i + o], o in [lower, upper] along direction d (inside the
    // array), for an array of sizes[0] x ... x sizes[dim-1] entries, the first fastest.
    template <int dim>
    void dilate(std::vector<std::uint8_t> &marks, const long sizes[dim], const int d, const int lower,
                const int upper)
    {
      long stride = 1;
      for (int e = 0; e < d; ++e)
        stride *= sizes[e];
      const long n = sizes[d], outer = static_cast<long>(marks.size()) / (stride * n);
      std::vector<std::uint8_t> line(n);
      for (long o = 0; o < outer; ++o)
        for (long s = 0; s < stride; ++s)
          {
            const long first = o * stride * n + s;
            for (long i = 0; i < n; ++i)
              line[i] = marks[first + i * stride];
            // Running count of marks in the window (the window slides by one entry).
            long in_window = 0;
            for (long j = lower; j <= upper; ++j)
              if (j >= 0 && j < n)
                in_window += line[j];
            for (long i = 0; i < n; ++i)
              {
                marks[first + i * stride] = in_window > 0 ? 1 : 0;
                if (const long leaving = i + lower; leaving >= 0 && leaving < n)
                  in_window -= line[leaving];
                if (const long entering = i + upper + 1; entering >= 0 && entering < n)
                  in_window += line[entering];
              }
          }
    }
  } // namespace overlap_detail

  // For each lattice cell (index i + n_x (j + n_y k)), 1 where points whose home cell it
  // is may add into an exchanged node or cell: some exchanged node (lattice node index)
  // within the node window, or exchanged cell (lattice cell index) within the cell window.
  template <int dim>
  std::vector<std::uint8_t> cells_reaching_exchange(const int n_cells[dim], const std::vector<long> &exchanged_nodes,
                                                    const std::vector<long> &exchanged_cells)
  {
    long node_sizes[dim], cell_sizes[dim], n_nodes = 1, n_lattice_cells = 1;
    for (int d = 0; d < dim; ++d)
      {
        node_sizes[d] = n_cells[d] + 1;
        cell_sizes[d] = n_cells[d];
        n_nodes *= node_sizes[d];
        n_lattice_cells *= cell_sizes[d];
      }
    std::vector<std::uint8_t> nodes(n_nodes, 0), cells(n_lattice_cells, 0);
    for (const long l : exchanged_nodes)
      if (l >= 0 && l < n_nodes)
        nodes[l] = 1;
    for (const long c : exchanged_cells)
      if (c >= 0 && c < n_lattice_cells)
        cells[c] = 1;
    for (int d = 0; d < dim; ++d)
      {
        overlap_detail::dilate<dim>(nodes, node_sizes, d, overlap_node_window_lower, overlap_node_window_upper);
        overlap_detail::dilate<dim>(cells, cell_sizes, d, overlap_cell_window_lower, overlap_cell_window_upper);
      }
    // Cell c's lowest node has the same lattice coordinates as c.
    for (long c = 0; c < n_lattice_cells; ++c)
      {
        long rest = c, node = 0, stride = 1;
        for (int d = 0; d < dim; ++d)
          {
            node += (rest % n_cells[d]) * stride;
            rest /= n_cells[d];
            stride *= node_sizes[d];
          }
        cells[c] = cells[c] || nodes[node] ? 1 : 0;
      }
    return cells;
  }
} // namespace mpm
