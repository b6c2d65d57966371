#include <lacerta/cut/cell_selection.h>
#include <lacerta/cut/crossing_decisions.h>

#include <algorithm>

namespace lacerta::cut
{
  CellSelection::CellSelection(const mesh::TetMesh &mesh_in)
      : mesh(mesh_in)
  {
  }


  void
  CellSelection::reserve(const std::size_t n_tets, const std::size_t n_vertices)
  {
    separate_mark.reserve(n_vertices);
    fresh_mark.reserve(n_vertices);
    tet_mark.reserve(n_tets);
    in_star.reserve(n_tets);
  }


  void
  CellSelection::prepare()
  {
    tet_mark.resize(mesh.n_tets(), 0);
    in_star.resize(mesh.n_tets(), 0);
    if (separate_mark.size() < mesh.n_vertices())
      separate_mark.resize(mesh.n_vertices(), 0);
    fresh_mark.resize(std::max<std::size_t>(fresh_mark.size(), mesh.n_vertices()), 0);
  }


  void
  CellSelection::select(CrossingDecisions &decisions)
  {
    prepare();
    select_cells(decisions);
    make_cuts(decisions);
  }


  void
  CellSelection::select_cells(CrossingDecisions &decisions)
  {
    ++affected_stamp;
    affected.clear();
    separated_vertices.clear();
    const auto consider = [&](const unsigned int t)
    {
      if (tet_mark[t] != affected_stamp)
      {
        tet_mark[t] = affected_stamp;
        in_star[t]  = 0;
        affected.push_back(t);
      }
    };
    const auto consider_edge = [&](const std::uint64_t key)
    {
      around.clear();
      mesh.tets_around_edge(CrossingDecisions::edge_end(key, 0),
                            CrossingDecisions::edge_end(key, 1),
                            around);
      for (const unsigned int n : around)
        consider(n);
    };
    // The cells whose copies of @p v are decided again: its whole star.
    const auto separate = [&](const unsigned int v)
    {
      if (separate_mark[v] == affected_stamp)
        return;
      separate_mark[v] = affected_stamp;
      separated_vertices.push_back(v);
      for (const unsigned int n : mesh.tets_of_vertex(v))
      {
        consider(n);
        in_star[n] = 1;
      }
    };
    for (const std::uint64_t key : decisions.new_crossings())
      consider_edge(key);
    for (const unsigned int v : decisions.new_on_cut())
      fresh_mark[v] = affected_stamp;
    for (const unsigned int v : decisions.new_on_cut())
      separate(v);
    // The closure: a cell cut through applies its crossings, and every cell around
    // an applied crossing is split with it (conforming: it is refined through the
    // cut point if the surface does not cross it through yet); the vertices on the
    // cut in a cell cut through get their copies decided over their whole stars.
    for (std::size_t q = 0; q < affected.size(); ++q)
    {
      const unsigned int t   = affected[q];
      const mesh::Tet   &tet = mesh.tet(t);
      // A face whose last vertex came onto the cut in this sweep lies in the cut from
      // now on: the copies of all three of its vertices are decided again.
      for (const auto &fv : mesh::TetMesh::face_vertices)
        if (decisions.on_cut(tet[fv[0]]) && decisions.on_cut(tet[fv[1]])
            && decisions.on_cut(tet[fv[2]])
            && (fresh_mark[tet[fv[0]]] == affected_stamp
                || fresh_mark[tet[fv[1]]] == affected_stamp
                || fresh_mark[tet[fv[2]]] == affected_stamp))
          for (const unsigned int k : fv)
            separate(tet[k]);
      const CrossingDecisions::CellDecision d = decisions.decide_cell(t);
      if (!d.complete)
        continue;
      for (unsigned int e = 0; e < 6; ++e)
        if ((d.crossed >> e) & 1u)
        {
          const std::uint64_t key =
            CrossingDecisions::edge_key(tet[tet_edge_vertices[e][0]],
                                        tet[tet_edge_vertices[e][1]]);
          if (decisions.apply_crossing(key))
            consider_edge(key);
        }
      for (const unsigned int v : tet)
        if (decisions.on_cut(v))
          separate(v);
    }
  }


  void
  CellSelection::make_cuts(const CrossingDecisions &decisions)
  {
    removed_cells.clear();
    cell_cuts.clear();
    for (const unsigned int t : affected)
    {
      const CrossingDecisions::CellDecision d   = decisions.decide_cell(t);
      const mesh::Tet                      &tet = mesh.tet(t);
      TetCut                                c   = decisions.whole_cell(t);
      if (d.complete)
        for (unsigned int i = 0; i < 4; ++i)
          c.vertex_side[i] = d.side[i];
      for (unsigned int e = 0; e < 6; ++e)
        if ((d.crossed >> e) & 1u)
        {
          const bool applied =
            d.complete
            || decisions.is_applied(
              CrossingDecisions::edge_key(tet[tet_edge_vertices[e][0]],
                                          tet[tet_edge_vertices[e][1]]));
          if (applied)
          {
            c.cut_edges |= std::uint8_t(1u << e);
            c.edge_parameter[e] = d.t[e];
          }
        }
      // A cell that is neither cut nor refined nor in the star of a vertex whose
      // copies are decided stays as it is.
      if (c.cut_edges == 0 && !in_star[t])
        continue;
      removed_cells.push_back(t);
      cell_cuts.push_back(c);
    }
  }

} // namespace lacerta::cut
