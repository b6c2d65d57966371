#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/mt/multi_triangulation.h>

namespace lacerta::mt
{
  std::size_t
  MultiTriangulation::memory_bytes() const
  {
    return vertices.capacity() * sizeof(mesh::Point3)
           + tets.capacity() * sizeof(mesh::Tet)
           + (creator.capacity() + destroyer.capacity() + fine_begin.capacity()
              + coarse_begin.capacity() + coarse_list.capacity() + node_vertex.capacity()
              + vertex_node.capacity())
               * sizeof(std::uint32_t)
           + replaced.capacity() + cut_pin.capacity()
           + (error.capacity() + own_error.capacity()) * sizeof(double)
           + (ball.capacity() + own_ball.capacity()) * sizeof(std::array<double, 4>);
  }


  std::array<mesh::Point3, 4>
  MultiTriangulation::corners(const unsigned int t) const
  {
    const auto &[a, b, c, d] = tets[t];
    return {{vertices[a], vertices[b], vertices[c], vertices[d]}};
  }


  std::array<double, 4>
  MultiTriangulation::barycentric(const unsigned int t, const mesh::Point3 &p) const
  {
    const auto &[a, b, c, d] = tets[t];
    const double volume =
      mesh::signed_volume(vertices[a], vertices[b], vertices[c], vertices[d]);
    return {{mesh::signed_volume(p, vertices[b], vertices[c], vertices[d]) / volume,
             mesh::signed_volume(vertices[a], p, vertices[c], vertices[d]) / volume,
             mesh::signed_volume(vertices[a], vertices[b], p, vertices[d]) / volume,
             mesh::signed_volume(vertices[a], vertices[b], vertices[c], p) / volume}};
  }


  void
  MultiTriangulation::check(const std::string &source) const
  {
    const std::size_t n = n_nodes();
    if (n == 0 || fine_begin.size() != n + 1 || coarse_begin.size() != n + 1
        || error.size() != n || ball.size() != n || own_error.size() != n
        || own_ball.size() != n || creator.size() != tets.size()
        || destroyer.size() != tets.size() || vertex_node.size() != vertices.size()
        || fine_begin.front() != 0
        // Tets beyond the decimation's ranges are children a cut appended.
        || (replaced.empty() ? fine_begin.back() != tets.size()
                             : fine_begin.back() > tets.size())
        || coarse_begin.front() != 0 || coarse_begin.back() != coarse_list.size()
        || (!cut_fine.empty() && (cut_fine.size() != n || cut_coarse.size() != n))
        || (!replaced.empty() && replaced.size() != tets.size())
        || cut_origin.size() > vertices.size()
        || (!cut_pin.empty() && cut_pin.size() != n))
      throw_error("Multi-Triangulation '", source, "': inconsistent array sizes.");
    for (std::size_t j = 0; j < n; ++j)
    {
      if (fine_begin[j] > fine_begin[j + 1] || coarse_begin[j] > coarse_begin[j + 1])
        throw_error("Multi-Triangulation '", source, "': node ", j, " has bad ranges.");
      for_each_fine(j,
                    [&](const std::uint32_t t)
                    {
                      if (t >= tets.size() || creator[t] != j || !is_live(t))
                        throw_error(
                          "Multi-Triangulation '", source, "': tet ", t, " misplaced.");
                    });
      for_each_coarse(
        j,
        [&](const std::uint32_t t)
        {
          if (t >= tets.size() || destroyer[t] != j || creator[t] >= j || !is_live(t))
            throw_error("Multi-Triangulation '",
                        source,
                        "': node ",
                        j,
                        " removes a tet it does not own or that a later node inserts.");
        });
      if (j > 0 && (node_vertex[j] >= vertices.size() || n_coarse(j) == 0))
        throw_error(
          "Multi-Triangulation '",
          source,
          "': node ",
          j,
          " has no vertex or no coarse tetrahedra (it could never be applied).");
    }
    for (const std::uint32_t t : cut_origin)
      if (t >= tets.size())
        throw_error("Multi-Triangulation '", source, "': a cut vertex has a bad origin.");
    for (std::size_t t = 0; t < tets.size(); ++t)
    {
      for (const unsigned int v : tets[t])
        if (v >= vertices.size())
          throw_error("Multi-Triangulation '", source, "': tet ", t, " bad vertex.");
      if (creator[t] >= n
          || (destroyer[t] != mesh::invalid_index
              && (destroyer[t] >= n || destroyer[t] <= creator[t])))
        throw_error("Multi-Triangulation '", source, "': tet ", t, " bad destroyer.");
      const auto &[a, b, c, d] = tets[t];
      if (!(mesh::signed_volume(vertices[a], vertices[b], vertices[c], vertices[d]) > 0))
        throw_error("Multi-Triangulation '", source, "': tet ", t, " is inverted.");
    }
  }


  void
  MultiTriangulation::serialize(Archive &archive)
  {
    archive.section("multi-triangulation");
    archive(vertices, tets, creator, destroyer, fine_begin, coarse_begin, coarse_list);
    archive(node_vertex, vertex_node, error, ball, cut_fine, cut_coarse, replaced);
    archive(cut_origin, cut_pin, n_cut_updates, own_error, own_ball);
  }
} // namespace lacerta::mt
