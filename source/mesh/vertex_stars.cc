#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/vertex_stars.h>

#include <algorithm>

namespace lacerta::mesh
{
  VertexStars::VertexStars(const unsigned int slot_words)
      : slot_words(slot_words)
      , lines_per_slot(slot_words / 16)
  {
    if (slot_words < 16 || slot_words % 16 != 0)
      throw_error("VertexStars: a slot of ",
                  slot_words,
                  " words is not a positive multiple of 16 (a cache line).");
  }


  void
  VertexStars::clear()
  {
    n_vertices = 0;
    lines.clear();
    overflow.clear();
    free_overflow.clear();
  }


  void
  VertexStars::resize(const std::size_t n)
  {
    // Stars of the vertices dropped give their overflow lists back.
    for (std::size_t v = n; v < n_vertices; ++v)
    {
      const unsigned int *s = slot(static_cast<unsigned int>(v));
      if (s[0] > slot_words - 1)
      {
        overflow[s[1]].clear();
        free_overflow.push_back(s[1]);
      }
    }
    // Value-initialised lines: the new stars' counts are zero.
    lines.resize(n * lines_per_slot);
    n_vertices = n;
  }


  void
  VertexStars::reserve(const std::size_t n)
  {
    lines.reserve(n * lines_per_slot);
  }


  void
  VertexStars::insert_overflowing(const unsigned int v, const unsigned int t)
  {
    unsigned int *s = slot(v);
    if (s[0] == slot_words - 1)
    {
      unsigned int index;
      if (free_overflow.empty())
      {
        index = static_cast<unsigned int>(overflow.size());
        overflow.emplace_back();
      }
      else
      {
        index = free_overflow.back();
        free_overflow.pop_back();
      }
      overflow[index].assign(s + 1, s + slot_words);
      s[1] = index;
    }
    overflow[s[1]].push_back(t);
    ++s[0];
  }


  void
  VertexStars::erase(const unsigned int v, const unsigned int t)
  {
    unsigned int *s = slot(v);
    if (s[0] <= slot_words - 1)
    {
      unsigned int *const ids = s + 1, *const end = ids + s[0];
      unsigned int *const at = std::find(ids, end, t);
      if (at == end)
        throw_error("VertexStars::erase: cell ", t, " is not around vertex ", v, ".");
      std::copy(at + 1, end, at);
      --s[0];
      return;
    }
    std::vector<unsigned int> &list = overflow[s[1]];
    const auto                 at   = std::find(list.begin(), list.end(), t);
    if (at == list.end())
      throw_error("VertexStars::erase: cell ", t, " is not around vertex ", v, ".");
    list.erase(at);
    --s[0];
    if (s[0] == slot_words - 1)
    {
      // Back in place: the slot's word 1 (the index) is overwritten by the first id.
      const unsigned int index = s[1];
      std::copy(list.begin(), list.end(), s + 1);
      list.clear();
      free_overflow.push_back(index);
    }
  }


  void
  VertexStars::shrink_overflowing(const unsigned int v)
  {
    unsigned int              *s    = slot(v);
    std::vector<unsigned int> &list = overflow[s[1]];
    s[0]                            = static_cast<unsigned int>(list.size());
    if (s[0] <= slot_words - 1)
    {
      // Back in place: the slot's word 1 (the index) is overwritten by the first id.
      const unsigned int index = s[1];
      std::copy(list.begin(), list.end(), s + 1);
      list.clear();
      free_overflow.push_back(index);
    }
  }


  void
  VertexStars::serialize(Archive &archive)
  {
    archive(slot_words, lines_per_slot, n_vertices, lines, overflow, free_overflow);
  }
} // namespace lacerta::mesh
