// Sums several arrays over the ranks in one round of messages, with deal.II's Partitioner.
//
// The grid's Partitioner exchanges one array per call: an exchange of the seven nodal arrays
// of MUSL's first P2G sends seven messages to each neighbour, twice (ghost values to their
// owners, sums back). Here the arrays travel interleaved (entry k of local index i at
// i * count + k) through a Partitioner over count times as many indices, built once per
// count from the grid's: one message per neighbour and direction. Only the ghost entries and
// the owned entries other ranks hold as ghosts are copied; the sums are added in the same
// order as the one-array exchange, so the results are the same to the bit.
#pragma once

#include <deal.II/base/partitioner.h>

#include <map>
#include <memory>
#include <vector>

namespace mpm
{
  class InterleavedExchange
  {
  public:
    // arrays[k] (k < count) laid out as `base`'s local storage (owned entries, then ghosts):
    // every owned entry gets the sum over the ranks of its owned and ghost copies, every
    // ghost entry its owner's sum. Collective: every rank calls it with the same count.
    template <typename Real>
    void sum(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &base, Real *const *arrays,
             int count);

    // The local indices that the exchange reads and writes, in the order of sum_packed: the
    // owned entries other ranks hold as ghosts (each once, ascending), then the ghosts.
    static std::vector<unsigned int> packed_indices(const dealii::Utilities::MPI::Partitioner &base);

    // The same sums for an owner of the arrays that packs only those entries, entry by
    // entry (the GPU engine: one copy each way): values[j * count + k] is array k at
    // packed_indices(base)[j]. The ghosts' part is handed to MPI as it is, only the owned
    // entries are copied (into the owned scratch and back); the results are those of sum()
    // to the bit.
    template <typename Real>
    void sum_packed(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &base, Real *values,
                    int count);

  private:
    // Follows a new base partitioner (a repartition: new numbering, new neighbours).
    void set_base(const std::shared_ptr<const dealii::Utilities::MPI::Partitioner> &base);
    // The Partitioner's import (ghosts added into their owners' entries) and export (the sums
    // copied into the ghosts) on interleaved owned and ghost storage.
    template <typename Real>
    void import_and_export(const dealii::Utilities::MPI::Partitioner &p, Real *owned, Real *ghost, int count);

    // The interleaved partitioners of `base`, by count (built collectively on first use).
    const dealii::Utilities::MPI::Partitioner &interleaved(int count);

    std::shared_ptr<const dealii::Utilities::MPI::Partitioner>               base;
    std::map<int, std::unique_ptr<const dealii::Utilities::MPI::Partitioner>> by_count;
    std::vector<unsigned int> import_local;  // base's import indices, one per exchanged entry
    std::vector<unsigned int> import_unique; // the same, each once, ascending

    // Interleaved scratch: owned entries (only the import positions are read or written),
    // ghosts, the Partitioner's import buffer. Owned scratch is not zero-filled.
    template <typename Real>
    struct Buffers
    {
      std::unique_ptr<Real[]> owned;
      std::size_t             owned_size = 0;
      std::vector<Real>       ghost, temp;
    };
    Buffers<double> doubles;
    Buffers<float>  floats;
    template <typename Real>
    Buffers<Real> &buffers();
    std::vector<MPI_Request> requests;
  };
} // namespace mpm
