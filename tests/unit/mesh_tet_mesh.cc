// TetMesh: connectivity, orientation, refusal of degenerate input, spatial sorting,
// local replacements against a plain reference.

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

using namespace lacerta;
using namespace lacerta::mesh;

namespace
{
  /// Two tetrahedra sharing the face (1, 2, 3); the second given inverted.
  TetMesh
  two_tets()
  {
    return TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}},
                   {{0, 1, 2, 3}, {1, 3, 2, 4}},
                   "two tets");
  }
} // namespace


TEST(TetMesh, ConnectivityOfTwoTetrahedra)
{
  const TetMesh mesh = two_tets();
  EXPECT_EQ(mesh.n_tets(), 2u);
  EXPECT_EQ(mesh.n_vertices(), 5u);
  EXPECT_EQ(mesh.n_edges(), 9u);
  EXPECT_EQ(mesh.get_boundary_faces().size(), 6u);
  // Face 0 of tet 0 (opposite vertex 0) is the shared one.
  EXPECT_EQ(mesh.neighbor(0, 0), 1u);
  unsigned int shared = 0;
  for (unsigned int f = 0; f < 4; ++f)
    shared += (mesh.neighbor(1, f) == 0);
  EXPECT_EQ(shared, 1u);
  for (unsigned int t = 0; t < 2; ++t)
    EXPECT_GT(mesh.volume(t), 0.0);
  EXPECT_NEAR(mesh.total_volume(), 1.0 / 6 + 1.0 / 3, 1e-14);
}


TEST(TetMesh, FacesPointOutward)
{
  const TetMesh mesh = two_tets();
  for (const BoundaryFace &bf : mesh.get_boundary_faces())
  {
    const Tet &t = mesh.tet(bf.tet);
    // The vertex opposite the face lies behind it.
    const auto &fv = TetMesh::face_vertices[bf.face];
    EXPECT_LT(signed_volume(mesh.vertex(t[fv[0]]),
                            mesh.vertex(t[fv[1]]),
                            mesh.vertex(t[fv[2]]),
                            mesh.vertex(t[bf.face])),
              0.0);
  }
}


TEST(TetMesh, EdgesOfEveryTetAreItsOwn)
{
  const TetMesh mesh = two_tets();
  for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    for (unsigned int e = 0; e < 6; ++e)
    {
      const auto            &edge     = mesh.get_edges()[mesh.tet_edges(t)[e]];
      std::set<unsigned int> expected = {mesh.tet(t)[TetMesh::edge_vertices[e][0]],
                                         mesh.tet(t)[TetMesh::edge_vertices[e][1]]};
      EXPECT_EQ(std::set<unsigned int>(edge.begin(), edge.end()), expected);
    }
}


TEST(TetMesh, RefusesDegenerateCells)
{
  EXPECT_THROW(TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                       {{0, 1, 1, 3}},
                       "repeated"),
               Error);
  EXPECT_THROW(
    TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2, 3}}, "flat"), Error);
  EXPECT_THROW(TetMesh({{0, 0, 0}, {1, 0, 0}, {0, NAN, 0}, {0, 0, 1}},
                       {{0, 1, 2, 3}},
                       "nan"),
               Error);
  EXPECT_THROW(TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                       {{0, 1, 2, 7}},
                       "index"),
               Error);
  try
  {
    TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}}, {{0, 1, 2, 3}}, "flat.msh");
  }
  catch (const Error &e)
  {
    EXPECT_NE(std::string(e.what()).find("flat.msh"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("cell 0"), std::string::npos);
  }
}


TEST(TetMesh, RefusesNonManifoldFaces)
{
  EXPECT_THROW(
    TetMesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}, {1, 1, 1}},
            {{0, 1, 2, 3}, {0, 2, 1, 4}, {0, 1, 2, 5}},
            "three on a face"),
    Error);
}


TEST(TetMesh, SpatialSortKeepsGeometryAndBoundaryIds)
{
  // A strip of tets with a boundary id on one face.
  std::vector<Point3> v;
  std::vector<Tet>    t;
  for (unsigned int i = 0; i < 20; ++i)
    v.push_back({double(i % 5), double((i / 5) % 2), double(i / 10)});
  TetMesh      mesh(v,
               {{0, 1, 5, 10}, {1, 6, 5, 11}, {1, 5, 10, 11}},
               "strip",
               {{{0, 1, 5}, 7}});
  const double volume_before = mesh.total_volume();
  const auto   n_boundary    = mesh.get_boundary_faces().size();
  mesh.sort_spatially();
  EXPECT_NEAR(mesh.total_volume(), volume_before, 1e-14);
  EXPECT_EQ(mesh.get_boundary_faces().size(), n_boundary);
  unsigned int tagged = 0;
  for (const auto &bf : mesh.get_boundary_faces())
    tagged += (bf.boundary_id == 7);
  EXPECT_EQ(tagged, 1u);
  EXPECT_EQ(mesh.n_vertices(), 6u); // unused input vertices are dropped
}


// Renumbering the vertices of a mesh whose numbering has no relation to the geometry
// along the spatial order keeps every cell, edge, star and boundary flag with its
// vertices, and brings the ends of the edges closer in memory.
TEST(TetMesh, RenumberingVerticesKeepsTheMeshAndRestoresLocality)
{
  std::mt19937 rng(3);
  TetMesh      mesh = cut::test_support::box_tet_mesh(6, rng);
  mesh.enable_local_updates();
  const TetMesh                   before = mesh;
  const std::vector<unsigned int> order  = mesh.spatial_vertex_order();
  const double                    spread = mesh.index_spread();
  mesh.renumber_vertices(order);
  EXPECT_EQ(mesh.index_spread(), before.index_spread(order));
  EXPECT_LT(mesh.index_spread(), 0.5 * spread);
  // The spatial order of a spatially ordered mesh is the identity.
  const std::vector<unsigned int> again = mesh.spatial_vertex_order();
  for (unsigned int v = 0; v < again.size(); ++v)
    ASSERT_EQ(again[v], v);

  ASSERT_EQ(mesh.n_vertices(), before.n_vertices());
  ASSERT_EQ(mesh.n_tets(), before.n_tets());
  for (unsigned int v = 0; v < before.n_vertices(); ++v)
  {
    EXPECT_EQ(mesh.vertex(order[v]), before.vertex(v));
    EXPECT_EQ(mesh.is_boundary_vertex(order[v]), before.is_boundary_vertex(v));
    std::vector<unsigned int> star(mesh.tets_of_vertex(order[v]).begin(),
                                   mesh.tets_of_vertex(order[v]).end()),
      old_star(before.tets_of_vertex(v).begin(), before.tets_of_vertex(v).end());
    std::sort(star.begin(), star.end());
    std::sort(old_star.begin(), old_star.end());
    EXPECT_EQ(star, old_star) << "vertex " << v;
  }
  for (unsigned int t = 0; t < before.n_tets(); ++t)
  {
    for (unsigned int k = 0; k < 4; ++k)
      EXPECT_EQ(mesh.tet(t)[k], order[before.tet(t)[k]]);
    EXPECT_EQ(mesh.tet_edges(t), before.tet_edges(t));
  }
  for (std::size_t e = 0; e < before.get_edges().size(); ++e)
  {
    const auto &[a, b]                         = before.get_edges()[e];
    const std::array<unsigned int, 2> expected = {
      {std::min(order[a], order[b]), std::max(order[a], order[b])}};
    EXPECT_EQ(mesh.get_edges()[e], expected);
  }
  EXPECT_EQ(mesh.find_edge(order[before.get_edges()[0][1]],
                           order[before.get_edges()[0][0]]),
            0u);
  EXPECT_NEAR(mesh.total_volume(), before.total_volume(), 1e-14);

  std::vector<unsigned int> twice = order;
  twice[1]                        = twice[0];
  EXPECT_THROW(mesh.renumber_vertices(twice), Error);
  EXPECT_THROW(mesh.renumber_vertices({0, 1}), Error);
  EXPECT_THROW(mesh.renumber_vertices({}), Error);
}


TEST(TetMesh, ReplacingCellsApartFromEachOtherKeepsTheirEdges)
{
  // Four tetrahedra without a common vertex: 24 distinct edges among four cells, more
  // than the 1.5 per cell of a cut (the edge table of replace_tets() once had 16
  // slots here and never finished).
  std::vector<Point3> vertices;
  std::vector<Tet>    cells;
  for (unsigned int k = 0; k < 4; ++k)
  {
    const double       x = 2.0 * k;
    const unsigned int v = static_cast<unsigned int>(vertices.size());
    vertices.insert(vertices.end(), {{x, 0, 0}, {x + 1, 0, 0}, {x, 1, 0}, {x, 0, 1}});
    cells.push_back({v, v + 1, v + 2, v + 3});
  }
  TetMesh mesh(vertices, cells, "four apart");
  mesh.enable_local_updates();
  const unsigned int                       n_edges = mesh.n_edges();
  std::vector<std::array<unsigned int, 6>> edges_before;
  for (unsigned int t = 0; t < 4; ++t)
    edges_before.push_back(mesh.tet_edges(t));
  std::vector<unsigned int>                ids;
  TetMesh::Update                          update;
  std::vector<std::array<unsigned int, 4>> face_ids(4, {{1, 1, 1, 1}});
  std::vector<Tet>                         added;
  for (unsigned int t = 0; t < 4; ++t)
    added.push_back(mesh.tet(t));
  mesh.replace_tets({0, 1, 2, 3}, added, face_ids, ids, update);
  EXPECT_EQ(mesh.n_edges(), n_edges);
  EXPECT_EQ(update.n_added_edges, 0u);
  EXPECT_TRUE(update.edge_moves.empty());
  for (unsigned int t = 0; t < 4; ++t)
  {
    EXPECT_EQ(ids[t], t);
    EXPECT_EQ(mesh.tet_edges(t), edges_before[t]);
  }
  EXPECT_EQ(mesh.get_boundary_faces().size(), 16u);
}


namespace
{
  /// A face by its sorted vertex ids.
  std::array<unsigned int, 3>
  face_of(const Tet &cell, const unsigned int f)
  {
    std::array<unsigned int, 3> key = {{cell[TetMesh::face_vertices[f][0]],
                                        cell[TetMesh::face_vertices[f][1]],
                                        cell[TetMesh::face_vertices[f][2]]}};
    std::sort(key.begin(), key.end());
    return key;
  }


  /**
   * replace_tets() done the plain way: the removed cells leave the boundary face list
   * face by face, then every new cell's face without a neighbour yet looks for the
   * other cell with its three vertices among all cells and either joins it (and takes
   * it off the list) or enters the list. The list's order is part of the result (it
   * feeds the first contact of the cutter).
   */
  struct ReferenceMesh
  {
    std::vector<Tet>                         tets;
    std::vector<std::array<unsigned int, 4>> neighbors;
    std::vector<BoundaryFace>                boundary;

    explicit ReferenceMesh(const TetMesh &mesh)
        : tets(mesh.get_tets())
        , boundary(mesh.get_boundary_faces())
    {
      for (unsigned int t = 0; t < mesh.n_tets(); ++t)
        neighbors.push_back({{mesh.neighbor(t, 0),
                              mesh.neighbor(t, 1),
                              mesh.neighbor(t, 2),
                              mesh.neighbor(t, 3)}});
    }

    void
    remove_boundary_face(const unsigned int t, const unsigned int f)
    {
      for (std::size_t i = 0; i < boundary.size(); ++i)
        if (boundary[i].tet == t && boundary[i].face == f)
        {
          boundary[i] = boundary.back();
          boundary.pop_back();
          return;
        }
    }

    void
    replace(const std::vector<unsigned int>                &removed,
            const std::vector<Tet>                         &added,
            const std::vector<std::array<unsigned int, 4>> &face_ids)
    {
      for (const unsigned int r : removed)
        for (unsigned int f = 0; f < 4; ++f)
        {
          remove_boundary_face(r, f);
          const unsigned int n = neighbors[r][f];
          if (n != invalid_index)
            for (unsigned int &back : neighbors[n])
              if (back == r)
                back = invalid_index;
          neighbors[r][f] = invalid_index;
        }
      std::vector<unsigned int> ids;
      for (std::size_t k = 0; k < added.size(); ++k)
      {
        ids.push_back(k < removed.size() ? removed[k] : tets.size());
        if (k >= removed.size())
        {
          tets.emplace_back();
          neighbors.push_back(
            {{invalid_index, invalid_index, invalid_index, invalid_index}});
        }
        tets[ids.back()] = added[k];
      }
      for (std::size_t k = 0; k < added.size(); ++k)
        for (unsigned int f = 0; f < 4; ++f)
        {
          const unsigned int t = ids[k];
          if (neighbors[t][f] != invalid_index)
            continue;
          const auto   key   = face_of(tets[t], f);
          unsigned int other = invalid_index, other_face = 0;
          for (unsigned int s = 0; s < tets.size() && other == invalid_index; ++s)
            for (unsigned int g = 0; g < 4 && s != t; ++g)
              if (face_of(tets[s], g) == key)
              {
                other      = s;
                other_face = g;
              }
          if (other == invalid_index)
            boundary.push_back({t, f, face_ids[k][f]});
          else
          {
            neighbors[t][f]              = other;
            neighbors[other][other_face] = t;
            remove_boundary_face(other, other_face);
          }
        }
    }
  };


  /// Whether replacing @p removed by @p added leaves every face with at most two cells.
  bool
  stays_manifold(const std::vector<Tet>          &tets,
                 const std::vector<unsigned int> &removed,
                 const std::vector<Tet>          &added)
  {
    std::vector<bool> gone(tets.size(), false);
    for (const unsigned int r : removed)
      gone[r] = true;
    std::map<std::array<unsigned int, 3>, unsigned int> count;
    for (unsigned int t = 0; t < tets.size(); ++t)
      for (unsigned int f = 0; f < 4 && !gone[t]; ++f)
        ++count[face_of(tets[t], f)];
    for (const Tet &cell : added)
      for (unsigned int f = 0; f < 4; ++f)
        if (++count[face_of(cell, f)] > 2)
          return false;
    return true;
  }


  /// Checks @p mesh's connectivity against one computed from its cells alone.
  void
  expect_connectivity_from_scratch(const TetMesh &mesh, const std::string &where)
  {
    std::map<std::array<unsigned int, 3>, std::vector<unsigned int>> cells_of_face;
    std::set<std::array<unsigned int, 2>>                            edges;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      for (unsigned int f = 0; f < 4; ++f)
        cells_of_face[face_of(mesh.tet(t), f)].push_back(4 * t + f);
      for (unsigned int e = 0; e < 6; ++e)
      {
        unsigned int a = mesh.tet(t)[TetMesh::edge_vertices[e][0]],
                     b = mesh.tet(t)[TetMesh::edge_vertices[e][1]];
        const std::array<unsigned int, 2> edge = {{std::min(a, b), std::max(a, b)}};
        edges.insert(edge);
        ASSERT_EQ(mesh.get_edges()[mesh.tet_edges(t)[e]], edge) << where;
      }
    }
    std::set<std::array<unsigned int, 2>> boundary;
    std::vector<bool>                     on_boundary(mesh.n_vertices(), false);
    for (const auto &[key, owners] : cells_of_face)
    {
      ASSERT_LE(owners.size(), 2u) << where;
      if (owners.size() == 2)
      {
        EXPECT_EQ(mesh.neighbor(owners[0] / 4, owners[0] % 4), owners[1] / 4) << where;
        EXPECT_EQ(mesh.neighbor(owners[1] / 4, owners[1] % 4), owners[0] / 4) << where;
      }
      else
      {
        EXPECT_EQ(mesh.neighbor(owners[0] / 4, owners[0] % 4), invalid_index) << where;
        boundary.insert({{owners[0] / 4, owners[0] % 4}});
        for (const unsigned int v : key)
          on_boundary[v] = true;
      }
    }
    std::set<std::array<unsigned int, 2>> listed;
    for (const BoundaryFace &bf : mesh.get_boundary_faces())
      listed.insert({{bf.tet, bf.face}});
    EXPECT_EQ(listed, boundary) << where;
    EXPECT_EQ(mesh.get_boundary_faces().size(), boundary.size()) << where;
    const std::set<std::array<unsigned int, 2>> listed_edges(mesh.get_edges().begin(),
                                                             mesh.get_edges().end());
    EXPECT_EQ(listed_edges, edges) << where;
    EXPECT_EQ(mesh.n_edges(), edges.size()) << where;
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    {
      EXPECT_EQ(mesh.is_boundary_vertex(v), on_boundary[v]) << where << ", vertex " << v;
      std::vector<unsigned int> star;
      for (unsigned int t = 0; t < mesh.n_tets(); ++t)
        if (std::count(mesh.tet(t).begin(), mesh.tet(t).end(), v) != 0)
          star.push_back(t);
      std::vector<unsigned int> listed_star(mesh.tets_of_vertex(v).begin(),
                                            mesh.tets_of_vertex(v).end());
      std::sort(listed_star.begin(), listed_star.end());
      EXPECT_EQ(listed_star, star) << where << ", vertex " << v;
    }
  }

  /// A box of @p n x @p n x @p n unit cubes, six tetrahedra each (around the cube's
  /// diagonal), with local updates enabled.
  TetMesh
  box_of_cubes(const unsigned int n)
  {
    std::vector<Point3> points;
    const auto          index = [n](unsigned int i, unsigned int j, unsigned int k)
    { return (k * (n + 1) + j) * (n + 1) + i; };
    for (unsigned int k = 0; k <= n; ++k)
      for (unsigned int j = 0; j <= n; ++j)
        for (unsigned int i = 0; i <= n; ++i)
          points.push_back({double(i), double(j), double(k)});
    std::vector<Tet>                                 cells;
    const std::array<std::array<unsigned int, 3>, 6> paths = {
      {{{0, 1, 2}}, {{0, 2, 1}}, {{1, 0, 2}}, {{1, 2, 0}}, {{2, 0, 1}}, {{2, 1, 0}}}};
    for (unsigned int k = 0; k < n; ++k)
      for (unsigned int j = 0; j < n; ++j)
        for (unsigned int i = 0; i < n; ++i)
          for (const auto &path : paths)
          {
            std::array<unsigned int, 3> c{{i, j, k}};
            Tet                         t;
            t[0] = index(c[0], c[1], c[2]);
            for (unsigned int s = 0; s < 3; ++s)
            {
              ++c[path[s]];
              t[s + 1] = index(c[0], c[1], c[2]);
            }
            cells.push_back(t);
          }
    TetMesh mesh(points, cells, "box");
    mesh.enable_local_updates();
    mesh.reserve(2 * mesh.n_vertices(), 4 * mesh.n_tets());
    return mesh;
  }
} // namespace


TEST(TetMesh, RandomLocalReplacementsMatchTheReferenceAndARebuild)
{
  // A box of 4 x 4 x 4 cubes, six tetrahedra each, changed by random local
  // replacements: cells put back in another order and with their vertices rotated,
  // cells split at their centroid, edges split at their midpoint, cracks that give
  // part of a vertex's star a copy of the vertex, and cracks closed again (the new
  // cells then join surviving cells across former boundary faces). After each one
  // the neighbours and the boundary face list, in order, are those of the plain
  // reference, and neighbours, boundary faces, edges, stars and boundary flags those
  // of the cells alone.
  TetMesh mesh = box_of_cubes(4);

  std::mt19937 rng(20261122);
  const auto   pick = [&](const std::size_t size)
  {
    return static_cast<unsigned int>(
      std::uniform_int_distribution<std::size_t>(0, size - 1)(rng));
  };
  const auto cells_with = [&](const std::vector<unsigned int> &vs)
  {
    std::vector<unsigned int> out;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      bool all = true;
      for (const unsigned int v : vs)
        all = all && std::count(mesh.tet(t).begin(), mesh.tet(t).end(), v) != 0;
      if (all)
        out.push_back(t);
    }
    return out;
  };
  const auto replaced = [](Tet cell, const unsigned int from, const unsigned int to)
  {
    std::replace(cell.begin(), cell.end(), from, to);
    return cell;
  };
  const auto midpoint = [&](const unsigned int a, const unsigned int b)
  {
    const Point3 &x = mesh.vertex(a), &y = mesh.vertex(b);
    return Point3{{(x[0] + y[0]) / 2, (x[1] + y[1]) / 2, (x[2] + y[2]) / 2}};
  };
  std::vector<std::array<unsigned int, 2>> cracks; // (vertex, its copy)
  unsigned int                             done = 0, closed = 0;
  for (unsigned int step = 0; step < 120; ++step)
  {
    const unsigned int        kind = pick(5);
    std::vector<unsigned int> removed;
    std::vector<Tet>          added;
    unsigned int              new_vertex = invalid_index, cracked = 0, closing = 0;
    Point3                    new_point{};
    const unsigned int        t = pick(mesh.n_tets());
    // In every kind a face between a removed and a surviving cell is a face of a new
    // cell too (the caller's guarantee).
    if (kind == 0)
    {
      // A cell and its neighbours put back, each with an even permutation of its
      // vertices (the same orientation, other local faces).
      removed.push_back(t);
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(t, f) != invalid_index)
          removed.push_back(mesh.neighbor(t, f));
      for (const unsigned int r : removed)
      {
        const Tet &c = mesh.tet(r);
        added.push_back(pick(2) == 0 ? Tet{{c[1], c[2], c[0], c[3]}}
                                     : Tet{{c[2], c[3], c[0], c[1]}});
      }
    }
    else if (kind == 1)
    {
      // Split at the centroid: child i has the centroid in place of vertex i.
      const Tet &c = mesh.tet(t);
      for (unsigned int d = 0; d < 3; ++d)
        new_point[d] = (mesh.vertex(c[0])[d] + mesh.vertex(c[1])[d] + mesh.vertex(c[2])[d]
                        + mesh.vertex(c[3])[d])
                       / 4;
      new_vertex = mesh.n_vertices();
      removed.push_back(t);
      for (unsigned int i = 0; i < 4; ++i)
        added.push_back(replaced(c, c[i], new_vertex));
    }
    else if (kind == 2)
    {
      // Split an edge of t at its midpoint, in every cell around it.
      const auto  &e = TetMesh::edge_vertices[pick(6)];
      unsigned int a = mesh.tet(t)[e[0]], b = mesh.tet(t)[e[1]];
      new_point  = midpoint(a, b);
      new_vertex = mesh.n_vertices();
      removed    = cells_with({a, b});
      for (const unsigned int r : removed)
      {
        added.push_back(replaced(mesh.tet(r), a, new_vertex));
        added.push_back(replaced(mesh.tet(r), b, new_vertex));
      }
    }
    else if (kind == 3)
    {
      // A crack: the cells around a vertex on one side of a plane through it take a
      // copy of the vertex. The whole star is replaced, as the cutter replaces the
      // cells on both sides: a surviving cell never loses a neighbour.
      const unsigned int v    = mesh.tet(t)[pick(4)];
      const unsigned int axis = pick(3);
      cracked                 = v;
      new_point               = mesh.vertex(v);
      new_vertex              = mesh.n_vertices();
      unsigned int moved      = 0;
      removed                 = cells_with({v});
      for (const unsigned int r : removed)
      {
        double centre = 0;
        for (const unsigned int w : mesh.tet(r))
          centre += mesh.vertex(w)[axis] / 4;
        const bool below = centre < mesh.vertex(v)[axis];
        added.push_back(below ? replaced(mesh.tet(r), v, new_vertex) : mesh.tet(r));
        moved += below ? 1 : 0;
      }
      if (moved == 0 || moved == removed.size())
        removed.clear(); // no crack
    }
    else if (!cracks.empty())
    {
      // Close a crack: the copy's cells take the vertex back.
      closing              = pick(cracks.size());
      const auto [v, copy] = cracks[closing];
      for (const unsigned int r : cells_with({copy}))
      {
        removed.push_back(r);
        added.push_back(replaced(mesh.tet(r), copy, v));
      }
    }
    if (removed.empty() || !stays_manifold(mesh.get_tets(), removed, added))
      continue;
    std::shuffle(removed.begin(), removed.end(), rng);
    std::shuffle(added.begin(), added.end(), rng);
    std::vector<std::array<unsigned int, 4>> face_ids;
    for (std::size_t k = 0; k < added.size(); ++k)
      face_ids.push_back({{pick(5), pick(5), pick(5), pick(5)}});
    if (new_vertex != invalid_index)
    {
      ASSERT_EQ(mesh.add_vertex(new_point), new_vertex);
    }
    if (kind == 3)
      cracks.push_back({{cracked, new_vertex}});
    if (kind == 4)
      cracks.erase(cracks.begin() + closing);

    ReferenceMesh             reference(mesh);
    const auto                edges_before = mesh.get_edges();
    std::vector<unsigned int> ids;
    TetMesh::Update           update;
    mesh.replace_tets(removed, added, face_ids, ids, update);
    reference.replace(removed, added, face_ids);
    ++done;
    const std::string where =
      "step " + std::to_string(step) + " (kind " + std::to_string(kind) + ")";
    ASSERT_EQ(mesh.get_tets(), reference.tets) << where;
    for (unsigned int c = 0; c < mesh.n_tets(); ++c)
      for (unsigned int f = 0; f < 4; ++f)
        ASSERT_EQ(mesh.neighbor(c, f), reference.neighbors[c][f]) << where;
    ASSERT_EQ(mesh.get_boundary_faces().size(), reference.boundary.size()) << where;
    for (std::size_t i = 0; i < reference.boundary.size(); ++i)
    {
      EXPECT_EQ(mesh.get_boundary_faces()[i].tet, reference.boundary[i].tet) << where;
      EXPECT_EQ(mesh.get_boundary_faces()[i].face, reference.boundary[i].face) << where;
      EXPECT_EQ(mesh.get_boundary_faces()[i].boundary_id,
                reference.boundary[i].boundary_id)
        << where;
    }
    // The edge update replayed on the old edge list gives the new one where it
    // names a surviving edge: a surviving edge keeps its spring.
    std::vector<std::array<unsigned int, 2>> replay = edges_before;
    replay.resize(edges_before.size() + update.n_added_edges,
                  {{invalid_index, invalid_index}});
    for (const auto &[to, from] : update.edge_moves)
    {
      replay[to] = replay[from];
      replay.pop_back();
    }
    ASSERT_EQ(replay.size(), mesh.n_edges()) << where;
    for (unsigned int e = 0; e < replay.size(); ++e)
      if (replay[e][0] != invalid_index)
      {
        EXPECT_EQ(replay[e], mesh.get_edges()[e]) << where;
      }
    expect_connectivity_from_scratch(mesh, where);
    if (kind == 4)
      ++closed;
  }
  EXPECT_GT(done, 60u);
  EXPECT_GT(closed, 5u);
}


TEST(TetMesh, EdgeCollapsesRemoveCellsAndVerticesLocally)
{
  // Random edge collapses (b onto a: the cells with both go, b's other cells take a),
  // as a decimation or a coarser level of detail makes them: fewer cells come than go
  // and b is left without cells. After each one the moves replayed on the old cells
  // and vertices give the new ones, the new cells are where their ids say, and the
  // connectivity is that of the cells alone.
  TetMesh      mesh = box_of_cubes(4);
  std::mt19937 rng(20261128);
  unsigned int done = 0, moved_tets = 0, moved_vertices = 0;
  for (unsigned int step = 0; step < 300 && done < 40; ++step)
  {
    const unsigned int t =
      std::uniform_int_distribution<unsigned int>(0, mesh.n_tets() - 1)(rng);
    const unsigned int e = std::uniform_int_distribution<unsigned int>(0, 5)(rng);
    const unsigned int a = mesh.tet(t)[TetMesh::edge_vertices[e][0]],
                       b = mesh.tet(t)[TetMesh::edge_vertices[e][1]];
    std::vector<unsigned int> removed;
    std::vector<Tet>          added;
    bool                      legal         = true;
    const auto                signed_volume = [&](const Tet &cell)
    {
      const Point3 &p = mesh.vertex(cell[0]);
      double        d[3][3];
      for (unsigned int i = 0; i < 3; ++i)
        for (unsigned int c = 0; c < 3; ++c)
          d[i][c] = mesh.vertex(cell[i + 1])[c] - p[c];
      return d[0][0] * (d[1][1] * d[2][2] - d[1][2] * d[2][1])
             - d[0][1] * (d[1][0] * d[2][2] - d[1][2] * d[2][0])
             + d[0][2] * (d[1][0] * d[2][1] - d[1][1] * d[2][0]);
    };
    for (unsigned int c = 0; c < mesh.n_tets(); ++c)
    {
      const Tet &cell = mesh.tet(c);
      if (std::count(cell.begin(), cell.end(), b) == 0)
        continue;
      removed.push_back(c);
      if (std::count(cell.begin(), cell.end(), a) == 0)
      {
        Tet moved = cell;
        std::replace(moved.begin(), moved.end(), b, a);
        // A legal collapse flattens or turns over no cell.
        legal = legal && signed_volume(moved) * signed_volume(cell) > 1e-12;
        added.push_back(moved);
      }
    }
    // The caller's guarantee: a face between a removed and a surviving cell is a
    // face of a new cell (a collapse of a boundary edge can uncover one).
    std::set<std::array<unsigned int, 3>> new_faces;
    for (const Tet &cell : added)
      for (unsigned int f = 0; f < 4; ++f)
        new_faces.insert(face_of(cell, f));
    bool covered = true;
    for (const unsigned int r : removed)
      for (unsigned int f = 0; f < 4; ++f)
      {
        const unsigned int n = mesh.neighbor(r, f);
        if (n != invalid_index && std::count(removed.begin(), removed.end(), n) == 0)
          covered = covered && new_faces.count(face_of(mesh.tet(r), f)) != 0;
      }
    if (!legal || !covered || !stays_manifold(mesh.get_tets(), removed, added))
      continue;
    std::shuffle(removed.begin(), removed.end(), rng);
    const std::string      where       = "collapse " + std::to_string(done);
    const std::vector<Tet> tets_before = mesh.get_tets();
    std::vector<Point3>    points_before;
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      points_before.push_back(mesh.vertex(v));
    std::vector<std::array<unsigned int, 4>> face_ids(added.size(), {{0, 0, 0, 0}});
    std::vector<unsigned int>                ids;
    TetMesh::Update                          update;
    mesh.replace_tets(removed, added, face_ids, ids, update);
    std::vector<Tet> replay = tets_before;
    for (std::size_t k = 0; k < added.size(); ++k)
      replay[removed[k]] = added[k];
    for (const auto &[to, from] : update.tet_moves)
      replay[to] = replay[from];
    replay.resize(tets_before.size() - (removed.size() - added.size()));
    ASSERT_EQ(mesh.get_tets(), replay) << where;
    for (std::size_t k = 0; k < added.size(); ++k)
      ASSERT_EQ(mesh.tet(ids[k]), added[k]) << where;
    moved_tets += static_cast<unsigned int>(update.tet_moves.size());

    std::vector<std::array<unsigned int, 2>> moves;
    mesh.remove_vertices({b}, moves);
    ASSERT_EQ(mesh.n_vertices(), points_before.size() - 1) << where;
    std::vector<unsigned int> renamed(points_before.size());
    for (unsigned int v = 0; v < renamed.size(); ++v)
      renamed[v] = v;
    for (const auto &[to, from] : moves)
    {
      points_before[to] = points_before[from];
      renamed[from]     = to;
    }
    points_before.pop_back();
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      ASSERT_EQ(mesh.vertex(v), points_before[v]) << where;
    for (unsigned int c = 0; c < mesh.n_tets(); ++c)
      for (unsigned int i = 0; i < 4; ++i)
        ASSERT_EQ(mesh.tet(c)[i], renamed[replay[c][i]]) << where;
    moved_vertices += static_cast<unsigned int>(moves.size());
    expect_connectivity_from_scratch(mesh, where);
    ++done;
  }
  EXPECT_EQ(done, 40u);
  EXPECT_GT(moved_tets, 0u);
  EXPECT_GT(moved_vertices, 0u);
  // A vertex that a cell still holds is refused.
  std::vector<std::array<unsigned int, 2>> moves;
  EXPECT_THROW(mesh.remove_vertices({mesh.tet(0)[0]}, moves), std::exception);
}
