#include <lacerta/base/archive.h>
#include <lacerta/cut/sweep_search.h>
#include <lacerta/physics/particle_system.h>

#include <algorithm>

namespace lacerta::cut
{
  namespace
  {
    /// Whether the segment [a, b] meets a face of the cell with corners @p p.
    bool
    segment_meets_faces(const std::array<Point, 4> &p, const Point &a, const Point &b)
    {
      double s;
      for (const auto &fv : mesh::TetMesh::face_vertices)
        if (segment_hits_triangle(a, b, p[fv[0]], p[fv[1]], p[fv[2]], s))
          return true;
      return false;
    }

    /// Whether @p x lies in the closed cell with corners @p p.
    bool
    contains(const std::array<Point, 4> &p, const Point &x)
    {
      const auto l = barycentric(p[0], p[1], p[2], p[3], x);
      return std::min({l[0], l[1], l[2], l[3]}) >= 0;
    }
  } // namespace


  SweepSearch::SweepSearch(const mesh::TetMesh           &mesh_in,
                           const physics::ParticleSystem &system_in)
      : mesh(mesh_in)
      , system(system_in)
  {
    tree.build(mesh, system.position.data());
    tet_stamp.assign(mesh.n_tets(), 0);
    edge_stamp.assign(mesh.n_edges(), 0);
  }


  void
  SweepSearch::reserve(const std::size_t n_tets, const std::size_t n_edges)
  {
    tet_stamp.reserve(n_tets);
    edge_stamp.reserve(n_edges);
  }


  void
  SweepSearch::refit()
  {
    tree.refit(mesh, system.position.data());
  }


  Point
  SweepSearch::position(const unsigned int v) const
  {
    return system.current_position(v);
  }


  bool
  SweepSearch::tet_meets(const unsigned int t, const SweptTriangles &swept) const
  {
    const std::array<Point, 4> p = corners(t);
    double                     s;
    for (const auto &tri : swept)
    {
      for (const auto &e : tet_edge_vertices)
        if (segment_hits_triangle(p[e[0]], p[e[1]], tri[0], tri[1], tri[2], s))
          return true;
      for (unsigned int k = 0; k < 3; ++k)
        if (segment_meets_faces(p, tri[k], tri[(k + 1) % 3]))
          return true;
      if (contains(p, tri[0]))
        return true;
    }
    return false;
  }


  bool
  SweepSearch::blade_in_tet(const unsigned int t, const Blade &b) const
  {
    const std::array<Point, 4> p = corners(t);
    return segment_meets_faces(p, b.tail, b.head) || contains(p, b.tail);
  }


  std::array<Point, 4>
  SweepSearch::corners(const unsigned int t) const
  {
    const mesh::Tet     &tet = mesh.tet(t);
    std::array<Point, 4> p;
    for (unsigned int i = 0; i < 4; ++i)
      p[i] = position(tet[i]);
    return p;
  }


  void
  SweepSearch::find(const SweptTriangles &swept, const Blade &end)
  {
    tet_stamp.resize(mesh.n_tets(), 0);
    edge_stamp.resize(mesh.n_edges(), 0);
    ++stamp;
    met.clear();
    next_active.clear();
    queue.clear();
    const auto push = [&](const unsigned int t)
    {
      if (t < mesh.n_tets() && tet_stamp[t] != stamp)
      {
        tet_stamp[t] = stamp;
        queue.push_back(t);
      }
    };
    for (const unsigned int t : active_cells)
      push(t);
    // First contact: the swept triangles against the boundary faces, through the tree.
    hits.clear();
    tree.query(mesh, system.position.data(), swept, hits);
    for (const auto &f : hits)
    {
      const auto tri = BoundaryFaceTree::triangle(f, system.position.data());
      if (triangles_intersect(tri, swept[0]) || triangles_intersect(tri, swept[1]))
        push(f.tet);
    }
    // Propagation: through the cells around every intersected edge (each edge tested
    // once per sweep), no global search.
    for (std::size_t q = 0; q < queue.size(); ++q)
    {
      const unsigned int t = queue[q];
      if (!tet_meets(t, swept))
        continue;
      met.push_back(t);
      bool crossed_edge = false;
      for (unsigned int e = 0; e < 6; ++e)
      {
        const unsigned int id = mesh.tet_edges(t)[e];
        if (edge_stamp[id] == stamp)
          continue;
        edge_stamp[id]       = stamp;
        const unsigned int a = mesh.tet(t)[tet_edge_vertices[e][0]];
        const unsigned int b = mesh.tet(t)[tet_edge_vertices[e][1]];
        double             s;
        if (segment_hits_triangle(
              position(a), position(b), swept[0][0], swept[0][1], swept[0][2], s)
            || segment_hits_triangle(
              position(a), position(b), swept[1][0], swept[1][1], swept[1][2], s))
        {
          crossed_edge = true;
          around.clear();
          mesh.tets_around_edge(a, b, around);
          for (const unsigned int n : around)
            push(n);
        }
      }
      // The surface can enter a cell through a face without crossing its edges (a
      // small sweep inside one cell): look across the faces then.
      if (!crossed_edge)
        for (unsigned int f = 0; f < 4; ++f)
          push(mesh.neighbor(t, f));
      if (blade_in_tet(t, end))
        next_active.push_back(t);
    }
    active_cells.swap(next_active);
  }


  void
  SweepSearch::follow_replacement(const std::vector<unsigned int> &removed,
                                  const std::vector<unsigned int> &added,
                                  const Blade                     &end)
  {
    for (const unsigned int t : added)
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(t, f) == mesh::invalid_index)
          tree.add_face(mesh, t, f);
    // The active cells: those that stay, and the new ones the blade is in.
    sorted_removed.assign(removed.begin(), removed.end());
    std::sort(sorted_removed.begin(), sorted_removed.end());
    active_cells.erase(std::remove_if(active_cells.begin(),
                                      active_cells.end(),
                                      [&](unsigned int t) {
                                        return std::binary_search(sorted_removed.begin(),
                                                                  sorted_removed.end(),
                                                                  t);
                                      }),
                       active_cells.end());
    // A new cell whose box is farther from the blade's than a tenth of its own size
    // does not contain the blade, and the exact test's rounding moves its answer by
    // far less than that (blade_in_tet() ignores faces within 1e-14 rad of the
    // blade's direction): only the cells near the blade are tested.
    Box blade_box;
    blade_box.extend(end.tail);
    blade_box.extend(end.head);
    for (const unsigned int t : added)
    {
      Box cell;
      for (const unsigned int v : mesh.tet(t))
        cell.extend(position(v));
      cell.inflate(0.1 * cell.size());
      if (cell.overlaps(blade_box) && blade_in_tet(t, end))
        active_cells.push_back(t);
    }
  }


  void
  SweepSearch::serialize(Archive &archive)
  {
    archive.section("sweep search");
    archive(tree, active_cells);
  }
} // namespace lacerta::cut
