/**
 * @file
 * The 64-bit FNV-1a hash over raw bytes: cache keys and checksums of files.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace lacerta
{
  /**
   * The 64-bit FNV-1a hash of the bytes added so far: enough to tell a damaged file
   * from a whole one, or to key a cache by its inputs; not cryptographic.
   */
  class FnvHash
  {
  public:
    /// Adds @p bytes bytes from @p data.
    void
    add(const void *data, const std::size_t bytes)
    {
      const auto *p = static_cast<const unsigned char *>(data);
      for (std::size_t i = 0; i < bytes; ++i)
        value = (value ^ p[i]) * 1099511628211ull;
    }

    /// Adds the bytes of the elements of @p v.
    template <typename T>
    void
    add_vector(const std::vector<T> &v)
    {
      add(v.data(), v.size() * sizeof(T));
    }

    /// The hash of everything added.
    std::uint64_t value = 14695981039346656037ull;
  };
} // namespace lacerta
