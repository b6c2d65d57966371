// TetMesh: connectivity, orientation, refusal of degenerate input, spatial sorting.

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>

#include <gtest/gtest.h>

#include <cmath>
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
  TetMesh::EdgeUpdate                      update;
  std::vector<std::array<unsigned int, 4>> face_ids(4, {{1, 1, 1, 1}});
  std::vector<Tet>                         added;
  for (unsigned int t = 0; t < 4; ++t)
    added.push_back(mesh.tet(t));
  mesh.replace_tets({0, 1, 2, 3}, added, face_ids, ids, update);
  EXPECT_EQ(mesh.n_edges(), n_edges);
  EXPECT_EQ(update.n_added, 0u);
  EXPECT_TRUE(update.moves.empty());
  for (unsigned int t = 0; t < 4; ++t)
  {
    EXPECT_EQ(ids[t], t);
    EXPECT_EQ(mesh.tet_edges(t), edges_before[t]);
  }
  EXPECT_EQ(mesh.get_boundary_faces().size(), 16u);
}
