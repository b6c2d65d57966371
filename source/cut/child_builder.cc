#include <lacerta/cut/child_builder.h>
#include <lacerta/cut/crossing_decisions.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/exceptions.h>

#include <algorithm>

namespace lacerta::cut
{
  namespace
  {
    /// The local faces of its parent that local node @p n of a child lies on, one bit
    /// per face.
    unsigned int
    parent_faces_of_node(const NodeRef &n)
    {
      switch (n.kind)
      {
        case NodeKind::vertex:
          return 0xFu & ~(1u << n.index);
        case NodeKind::edge_point:
          return 0xFu & ~(1u << tet_edge_vertices[n.index][0])
                 & ~(1u << tet_edge_vertices[n.index][1]);
        case NodeKind::face_point:
          return 1u << n.index;
        case NodeKind::interior_point:
          return 0;
      }
      return 0;
    }

    /// Barycentric coordinates of the rest point @p rest in cell @p t of @p mesh:
    /// the weights that carry it, with the cell's affine map, to the deformed state.
    std::array<double, 4>
    rest_barycentric(const mesh::TetMesh &mesh, const unsigned int t, const Point &rest)
    {
      const mesh::Tet &c = mesh.tet(t);
      return barycentric(
        mesh.vertex(c[0]), mesh.vertex(c[1]), mesh.vertex(c[2]), mesh.vertex(c[3]), rest);
    }
  } // namespace


  ChildBuilder::ChildBuilder(mesh::TetMesh &mesh_in, physics::ParticleSystem &system_in)
      : mesh(mesh_in)
      , system(system_in)
  {
    prepare();
  }


  void
  ChildBuilder::reserve(const std::size_t n_vertices, const std::size_t n_edges)
  {
    separate_mark.reserve(n_vertices);
    edge_point.reserve(n_edges);
  }


  void
  ChildBuilder::prepare()
  {
    edge_point.resize(mesh.n_edges());
    if (separate_mark.size() < mesh.n_vertices())
      separate_mark.resize(mesh.n_vertices(), 0);
  }


  void
  ChildBuilder::build(const std::vector<unsigned int> &parents,
                      const std::vector<TetCut>       &cuts,
                      const std::vector<SplitResult>  &results,
                      const std::vector<unsigned int> &separated,
                      CrossingDecisions               &decisions,
                      CutStepStatistics               &statistics,
                      CutRecord                       *record)
  {
    prepare();
    ++separate_stamp;
    for (const unsigned int v : separated)
      separate_mark[v] = separate_stamp;
    if (record)
      child_origin.clear();
    make_children(parents, cuts, results, decisions, statistics, record);
    separate_points_on_cut(decisions, statistics, record);
  }


  unsigned int
  ChildBuilder::new_particle(const Point       &rest,
                             const unsigned int parent,
                             CutStepStatistics &statistics)
  {
    // The state interpolated from the parent: the same affine map at rest and deformed.
    const mesh::Tet &tet = mesh.tet(parent);
    const auto       l   = rest_barycentric(mesh, parent, rest);
    Point            x{{0, 0, 0}}, v{{0, 0, 0}};
    for (unsigned int i = 0; i < 4; ++i)
      for (unsigned int c = 0; c < 3; ++c)
      {
        x[c] += l[i] * system.position[3 * tet[i] + c];
        v[c] += l[i] * system.velocity[3 * tet[i] + c];
      }
    const unsigned int id = mesh.add_vertex(rest);
    system.add_particle(rest, x, v);
    ++statistics.new_particles;
    return id;
  }


  void
  ChildBuilder::make_children(const std::vector<unsigned int> &parents,
                              const std::vector<TetCut>       &cuts,
                              const std::vector<SplitResult>  &results,
                              CrossingDecisions               &decisions,
                              CutStepStatistics               &statistics,
                              CutRecord                       *record)
  {
    // New points, merged across tetrahedra through the edge they lie on (one particle
    // per edge), interior points per cell; boundary ids inherited from the parent.
    ++merge_stamp;
    made.clear();
    child_cut_faces.clear();
    ids.clear();
    for (std::size_t k = 0; k < cuts.size(); ++k)
    {
      const TetCut      &c        = cuts[k];
      const SplitResult &r        = results[k];
      const unsigned int parent   = parents[k];
      unsigned int       interior = mesh::invalid_index;
      if (r.kind != CutKind::none && r.kind != CutKind::touch)
      {
        statistics.cut_tets += 1;
        statistics.created_tets += r.n_children;
      }
      // The parent's boundary ids, looked up once for all its children (most
      // parents are inside the body and have none).
      std::array<unsigned int, 4> parent_ids;
      unsigned int                parent_boundary = 0;
      for (unsigned int f = 0; f < 4; ++f)
      {
        parent_ids[f] = mesh.boundary_id(parent, f);
        if (parent_ids[f] != mesh::invalid_index)
          parent_boundary |= 1u << f;
      }
      for (unsigned int i = 0; i < r.n_children; ++i)
      {
        const Child &child = r.children[i];
        mesh::Tet    t;
        for (unsigned int j = 0; j < 4; ++j)
        {
          const NodeRef &n = child.nodes[j];
          unsigned int  *slot;
          switch (n.kind)
          {
            case NodeKind::vertex:
              t[j] = static_cast<unsigned int>(c.vertex_ids[n.index]);
              continue;
            case NodeKind::edge_point:
            {
              EdgePoint &es = edge_point[mesh.tet_edges(parent)[n.index]];
              if (es.point_stamp != merge_stamp)
              {
                es.point_stamp = merge_stamp;
                es.point       = mesh::invalid_index;
              }
              // One point per edge: its copies, where the crack opens, are decided
              // with the vertices on the cut (below).
              slot = &es.point;
              break;
            }
            case NodeKind::face_point:
              // The cutter's cuts have no crack front inside a cell.
              AssertThrow(false, dealii::ExcInternalError());
              DEAL_II_FALLTHROUGH;
            default:
              slot = &interior;
              break;
          }
          if (*slot == mesh::invalid_index)
          {
            const Point p =
              n.kind == NodeKind::edge_point ? r.edge_points[n.index] : r.interior_point;
            *slot = new_particle(p, parent, statistics);
            if (record)
            {
              record->new_points.push_back({*slot, n.kind, record_key(c, n), p});
            }
            if (n.kind != NodeKind::interior_point)
            {
              decisions.mark_on_cut(*slot);
              if (separate_mark.size() <= *slot)
                separate_mark.resize(std::size_t(*slot) + 256, 0);
              separate_mark[*slot] = separate_stamp;
            }
          }
          t[j] = *slot;
        }
        std::array<unsigned int, 4> fid{{0, 0, 0, 0}};
        for (unsigned int j = 0; j < 4; ++j)
        {
          if (child.cut_faces & (1u << j))
          {
            fid[j] = cut_boundary_id;
            continue;
          }
          // A face on a parent's boundary face keeps its boundary id: the parent's
          // faces that all three of its nodes lie on (the last such face wins).
          if (parent_boundary == 0)
            continue;
          unsigned int on = parent_boundary;
          for (unsigned int m = 0; m < 4; ++m)
            if (m != j)
              on &= parent_faces_of_node(child.nodes[m]);
          for (unsigned int f = 0; f < 4; ++f)
            if (on & (1u << f))
              fid[j] = parent_ids[f];
        }
        made.push_back(t);
        if (record)
          child_origin.push_back({{static_cast<unsigned int>(k), i}});
        child_cut_faces.push_back(child.cut_faces);
        ids.push_back(fid);
      }
    }
  }


  void
  ChildBuilder::separate_points_on_cut(CrossingDecisions &decisions,
                                       CutStepStatistics &statistics,
                                       CutRecord         *record)
  {
    // Vertices on the cut: one copy per group of their children connected through
    // faces not on the cut, so that the two sides separate where the crack is open
    // and stay joined at the crack tip.
    incidences.clear();
    for (std::size_t k = 0; k < made.size(); ++k)
      for (const unsigned int v : made[k])
        if (v < separate_mark.size() && separate_mark[v] == separate_stamp)
          incidences.push_back({{v, static_cast<unsigned int>(k)}});
    std::sort(incidences.begin(), incidences.end());
    for (std::size_t b = 0; b < incidences.size();)
    {
      const unsigned int v = incidences[b][0];
      std::size_t        e = b;
      star.clear();
      while (e < incidences.size() && incidences[e][0] == v)
      {
        const mesh::Tet &c = made[incidences[e][1]];
        star.push_back({{{c[0], c[1], c[2], c[3]}}, child_cut_faces[incidences[e][1]]});
        ++e;
      }
      const unsigned int n_groups = separate_star(v, star, star_group);
      copy_ids.assign(n_groups, v);
      for (unsigned int g = 1; g < n_groups; ++g)
      {
        const unsigned int copy = mesh.add_vertex(mesh.vertex(v));
        system.add_particle(mesh.vertex(v),
                            system.current_position(v),
                            {{system.velocity[3 * v],
                              system.velocity[3 * v + 1],
                              system.velocity[3 * v + 2]}});
        // A copy keeps its original's constraint (the scene extends its particle
        // lists from `copied_particles`).
        system.free[copy] = system.free[v];
        statistics.copied_particles.push_back({{v, copy}});
        decisions.mark_on_cut(copy);
        ++statistics.new_particles;
        copy_ids[g] = copy;
        if (record)
          record->new_points.push_back(
            {copy, NodeKind::vertex, {{v, 0, 0, 0}}, mesh.vertex(v)});
      }
      for (std::size_t i = 0; i < star.size(); ++i)
      {
        const unsigned int child = incidences[b + i][1];
        for (unsigned int m = 0; m < 4; ++m)
          if (made[child][m] == v)
          {
            made[child][m] = copy_ids[star_group[i]];
            if (record)
              record->vertex_choices.push_back(
                {child_origin[child][0],
                 static_cast<std::uint8_t>(child_origin[child][1]),
                 static_cast<std::uint8_t>(m),
                 copy_ids[star_group[i]]});
          }
      }
      decisions.mark_on_cut(v);
      b = e;
    }
  }

} // namespace lacerta::cut
