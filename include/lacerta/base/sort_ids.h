/**
 * @file
 * Sorting lists of ids (particles, springs, cells) by a radix sort.
 */
#pragma once

#include <array>
#include <vector>

namespace lacerta
{
  /**
   * Sorts the ids @p ids in increasing order, by digits of 8 bits from the lowest (a
   * radix sort: a few passes over them instead of a comparison sort's mispredicted
   * branches), with @p scratch as room. Only the digits up to the highest bit set in
   * any id are passed over.
   */
  inline void
  sort_ids(std::vector<unsigned int> &ids, std::vector<unsigned int> &scratch)
  {
    unsigned int bits = 0;
    for (const unsigned int id : ids)
      bits |= id;
    scratch.resize(ids.size());
    for (unsigned int shift = 0; shift < 32 && (bits >> shift) != 0; shift += 8)
    {
      std::array<unsigned int, 257> start{};
      for (const unsigned int id : ids)
        ++start[((id >> shift) & 0xFFu) + 1];
      for (unsigned int d = 1; d < 257; ++d)
        start[d] += start[d - 1];
      for (const unsigned int id : ids)
        scratch[start[(id >> shift) & 0xFFu]++] = id;
      ids.swap(scratch);
    }
  }
} // namespace lacerta
