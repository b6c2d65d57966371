/**
 * @file
 * The cells around every vertex, stored contiguously for local mesh updates.
 */
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mesh
{
  /**
   * For every vertex, the ordered list of the cells around it (its star). Insertion
   * appends and erasure keeps the order of the others, as a vector per vertex would,
   * but a star lives in a fixed-size slot of one array, with its count in front of
   * its ids: reading a star touches one or two adjacent cache lines and adding a vertex
   * allocates nothing. A star larger than its slot moves to an overflow list (and back
   * when it shrinks again).
   */
  class VertexStars
  {
  public:
    /// Words (of 4 bytes) per vertex by default: 3 cache lines, 47 cells in place,
    /// enough for the 32 cells of a vertex of a hexahedron split into five.
    static constexpr unsigned int default_slot_words = 48;

    /// A read-only view of one star: its cells, in order.
    class Star
    {
    public:
      /// The view of @p n ids starting at @p ids.
      Star(const unsigned int *ids, const unsigned int n)
          : ids(ids)
          , n(n)
      {
      }

      /// The first cell.
      const unsigned int *
      begin() const
      {
        return ids;
      }

      /// Past the last cell.
      const unsigned int *
      end() const
      {
        return ids + n;
      }

      /// The number of cells.
      std::size_t
      size() const
      {
        return n;
      }

      /// Whether the star has no cell.
      bool
      empty() const
      {
        return n == 0;
      }

      /// Cell @p i of the star.
      unsigned int
      operator[](const std::size_t i) const
      {
        return ids[i];
      }

      /// The first cell (the star must not be empty).
      unsigned int
      front() const
      {
        return ids[0];
      }

    private:
      const unsigned int *ids;
      unsigned int        n;
    };

    /**
     * No vertex yet; every vertex gets @p slot_words words (a multiple of 16, at
     * least 16), one of them the count: stars of up to slot_words - 1 cells stay in
     * place.
     */
    explicit VertexStars(unsigned int slot_words = default_slot_words);

    /// The number of vertices.
    std::size_t
    size() const
    {
      return n_vertices;
    }

    /// Whether there is no vertex.
    bool
    empty() const
    {
      return n_vertices == 0;
    }

    /// Removes every vertex.
    void
    clear();

    /// Grows or shrinks to @p n vertices; the new ones have empty stars.
    void
    resize(std::size_t n);

    /// Makes room for @p n vertices, so that growing up to it copies nothing.
    void
    reserve(std::size_t n);

    /// The cells of in-place stars (cells more are moved to the overflow list).
    unsigned int
    inline_capacity() const
    {
      return slot_words - 1;
    }

    /// The number of cells around vertex @p v.
    unsigned int
    star_size(const unsigned int v) const
    {
      return slot(v)[0];
    }

    /// The cells around vertex @p v, in order.
    Star
    operator[](const unsigned int v) const
    {
      const unsigned int *s = slot(v);
      return {s[0] <= slot_words - 1 ? s + 1 : overflow[s[1]].data(), s[0]};
    }

    /// Appends cell @p t to the star of vertex @p v.
    void
    insert(const unsigned int v, const unsigned int t)
    {
      unsigned int *s = slot(v);
      if (s[0] < slot_words - 1)
        s[1 + s[0]++] = t;
      else
        insert_overflowing(v, t);
    }

    /// Removes cell @p t (which must be there) from the star of vertex @p v, keeping
    /// the order of the others.
    void
    erase(unsigned int v, unsigned int t);

    /**
     * Removes the cells for which @p marked (t) is true from the star of vertex @p v,
     * keeping the order of the others: the same star as erase() of each of them, in
     * one pass.
     */
    template <typename Marked>
    void
    erase_marked(const unsigned int v, Marked &&marked)
    {
      unsigned int *s = slot(v);
      if (s[0] > slot_words - 1)
      {
        erase_marked_overflowing(v, marked);
        return;
      }
      // Every id is copied and the write position advances past the kept ones only:
      // no branch on which cells are marked, which follows no pattern.
      unsigned int *const ids  = s + 1;
      unsigned int        kept = 0;
      for (unsigned int i = 0; i < s[0]; ++i)
      {
        const unsigned int t = ids[i];
        ids[kept]            = t;
        kept += marked(t) ? 0 : 1;
      }
      s[0] = kept;
    }

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// erase_marked() for a star in the overflow list.
    template <typename Marked>
    void
    erase_marked_overflowing(const unsigned int v, Marked &marked)
    {
      std::vector<unsigned int> &list = overflow[slot(v)[1]];
      list.erase(std::remove_if(list.begin(), list.end(), marked), list.end());
      shrink_overflowing(v);
    }

    /// Moves the star of @p v back in place if its overflow list fits there again.
    void
    shrink_overflowing(unsigned int v);

    /// One cache line; a slot is slot_words / 16 of them.
    struct alignas(64) Line
    {
      unsigned int words[16];
    };

    const unsigned int *
    slot(const unsigned int v) const
    {
      return lines[std::size_t(v) * lines_per_slot].words;
    }

    unsigned int *
    slot(const unsigned int v)
    {
      return lines[std::size_t(v) * lines_per_slot].words;
    }

    /// insert() for a full slot or an overflowing star.
    void
    insert_overflowing(unsigned int v, unsigned int t);

    unsigned int      slot_words;
    unsigned int      lines_per_slot;
    std::size_t       n_vertices = 0;
    std::vector<Line> lines;
    /// Stars too large for their slot: word 1 of the slot is the index here.
    std::vector<std::vector<unsigned int>> overflow;
    /// Overflow lists no star uses (kept with their memory).
    std::vector<unsigned int> free_overflow;
  };
} // namespace lacerta::mesh
