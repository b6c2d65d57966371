/**
 * @file
 * The springs of the particle system as flat arrays.
 */
#pragma once

#include <cstddef>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  /**
   * Springs as a structure of arrays: spring s joins particles a[s] and b[s], has
   * stiffness[s] (N/m) and rest_length[s] (m). The hot loop reads these arrays
   * sequentially.
   */
  struct SpringSet
  {
    std::vector<unsigned int> a;
    std::vector<unsigned int> b;
    std::vector<double>       stiffness;
    std::vector<double>       rest_length;

    /// Number of springs.
    std::size_t
    size() const
    {
      return a.size();
    }

    /// Appends a spring.
    void
    push_back(unsigned int first, unsigned int second, double k, double length)
    {
      a.push_back(first);
      b.push_back(second);
      stiffness.push_back(k);
      rest_length.push_back(length);
    }

    /// Makes room for @p n springs, so that appending up to that many reallocates
    /// nothing.
    void
    reserve(std::size_t n)
    {
      a.reserve(n);
      b.reserve(n);
      stiffness.reserve(n);
      rest_length.reserve(n);
    }

    /// Removes spring @p to by moving the last spring into its slot (as the mesh
    /// retires an edge); removes the last spring if @p to is the last.
    void
    retire(const std::size_t to)
    {
      a[to]           = a.back();
      b[to]           = b.back();
      stiffness[to]   = stiffness.back();
      rest_length[to] = rest_length.back();
      a.pop_back();
      b.pop_back();
      stiffness.pop_back();
      rest_length.pop_back();
    }

    /// Removes all springs.
    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

    void
    clear()
    {
      a.clear();
      b.clear();
      stiffness.clear();
      rest_length.clear();
    }
  };
} // namespace lacerta::physics
