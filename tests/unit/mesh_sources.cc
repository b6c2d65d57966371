// Mesh sources on real files: gmsh 2.2 and 4.1, VTK legacy and XML, the implicit
// function; and the refusal of bad files with a message naming the file and the cell.

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/vtk_reader.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

using namespace lacerta;
using namespace lacerta::mesh;

namespace
{
  const std::string data_dir = LACERTA_TEST_DATA_DIR;

  /// Creates a mesh source by name through the parameter file machinery, as a scene does.
  TetMesh
  mesh_from_source(const std::string                        &source,
                   const std::map<std::string, std::string> &entries)
  {
    dealii::ParameterHandler prm;
    MeshSource::declare_parameters(prm);
    prm.enter_subsection("Mesh");
    prm.set("Source", source);
    std::string subsection = source;
    subsection[0]          = static_cast<char>(std::toupper(subsection[0]));
    prm.enter_subsection(subsection);
    for (const auto &[name, value] : entries)
      prm.set(name, value);
    prm.leave_subsection();
    prm.leave_subsection();
    return MeshSource::create(prm)->create_mesh();
  }


  TetMesh
  mesh_from_file(const std::string &name)
  {
    return mesh_from_source("file", {{"File name", data_dir + "/" + name}});
  }


  /**
   * The unit cube of tests/data: six tetrahedra around the diagonal (0,0,0)-(1,1,1),
   * three of them given inverted; the faces at x = 0 carry boundary id 1, those at
   * x = 1 id 2, the rest none (0).
   */
  void
  expect_tagged_unit_cube(const TetMesh &mesh)
  {
    EXPECT_EQ(mesh.n_tets(), 6u);
    EXPECT_EQ(mesh.n_vertices(), 8u);
    EXPECT_EQ(mesh.n_edges(), 19u); // 12 cube edges, 6 face diagonals, 1 body diagonal
    EXPECT_NEAR(mesh.total_volume(), 1.0, 1e-14);
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      EXPECT_NEAR(mesh.volume(t), 1.0 / 6, 1e-14) << "tet " << t;

    ASSERT_EQ(mesh.get_boundary_faces().size(), 12u);
    std::map<unsigned int, unsigned int> faces_with_id;
    for (const BoundaryFace &bf : mesh.get_boundary_faces())
    {
      ++faces_with_id[bf.boundary_id];
      const Tet &t = mesh.tet(bf.tet);
      for (const unsigned int lv : TetMesh::face_vertices[bf.face])
      {
        const double x = mesh.vertex(t[lv])[0];
        if (bf.boundary_id == 1)
        {
          EXPECT_EQ(x, 0.0);
        }
        else if (bf.boundary_id == 2)
        {
          EXPECT_EQ(x, 1.0);
        }
      }
    }
    EXPECT_EQ(faces_with_id[0], 8u);
    EXPECT_EQ(faces_with_id[1], 2u);
    EXPECT_EQ(faces_with_id[2], 2u);
  }


  /// The message of the Error that reading @p name throws ("" if none is thrown).
  std::string
  refusal(const std::string &name)
  {
    try
    {
      mesh_from_file(name);
    }
    catch (const Error &e)
    {
      return e.what();
    }
    return "";
  }
} // namespace


TEST(MeshSources, GmshVersion2)
{
  expect_tagged_unit_cube(mesh_from_file("cube_v2.msh"));
}


TEST(MeshSources, GmshVersion4)
{
  expect_tagged_unit_cube(mesh_from_file("cube_v4.msh"));
}


TEST(MeshSources, VtkLegacy)
{
  expect_tagged_unit_cube(mesh_from_file("cube.vtk"));
}


TEST(MeshSources, VtkXml)
{
  expect_tagged_unit_cube(read_vtk_unstructured_grid(data_dir + "/cube.vtu"));
}


/**
 * Files written by gmsh itself (contrib/meshes/box.geo): the unit cube with physical
 * surfaces 1 (x = 0) and 2 (x = 1); gmsh writes nodes of every entity, including the
 * other faces', and triangles only where a physical group asks.
 */
TEST(MeshSources, GmshWrittenByGmsh)
{
  const TetMesh v2 = mesh_from_file("gmsh_box_v2.msh");
  const TetMesh v4 = mesh_from_file("gmsh_box_v4.msh");
  EXPECT_EQ(v2.n_tets(), v4.n_tets());
  EXPECT_EQ(v2.n_vertices(), v4.n_vertices());
  for (const TetMesh *mesh : {&v2, &v4})
  {
    EXPECT_GT(mesh->n_tets(), 20u);
    EXPECT_NEAR(mesh->total_volume(), 1.0, 1e-12);
    for (unsigned int t = 0; t < mesh->n_tets(); ++t)
      EXPECT_GT(mesh->volume(t), 0.0);
    // A face gets id 1 exactly when it lies in x = 0, 2 when in x = 1.
    unsigned int n_tagged = 0;
    double       area[3]  = {0, 0, 0};
    for (const BoundaryFace &bf : mesh->get_boundary_faces())
    {
      const Tet    &t  = mesh->tet(bf.tet);
      const auto   &fv = TetMesh::face_vertices[bf.face];
      const Point3 &a = mesh->vertex(t[fv[0]]), &b = mesh->vertex(t[fv[1]]),
                   &c             = mesh->vertex(t[fv[2]]);
      const unsigned int expected = (a[0] == 0 && b[0] == 0 && c[0] == 0)   ? 1
                                    : (a[0] == 1 && b[0] == 1 && c[0] == 1) ? 2
                                                                            : 0;
      EXPECT_EQ(bf.boundary_id, expected);
      n_tagged += (bf.boundary_id != 0);
      const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      area[std::min(bf.boundary_id, 2u)] += 0.5
                                            * std::hypot(u[1] * w[2] - u[2] * w[1],
                                                         u[2] * w[0] - u[0] * w[2],
                                                         u[0] * w[1] - u[1] * w[0]);
    }
    EXPECT_GT(n_tagged, 0u);
    EXPECT_NEAR(area[0], 4.0, 1e-12);
    EXPECT_NEAR(area[1], 1.0, 1e-12);
    EXPECT_NEAR(area[2], 1.0, 1e-12);
  }
}


TEST(MeshSources, AllFormatsGiveTheSameMesh)
{
  // The same edges, compared by the positions of their ends: the readers need not
  // number the vertices alike.
  const auto edges_by_position = [](const TetMesh &mesh)
  {
    std::set<std::pair<Point3, Point3>> edges;
    for (const auto &e : mesh.get_edges())
      edges.insert(std::minmax(mesh.vertex(e[0]), mesh.vertex(e[1])));
    return edges;
  };
  const auto reference = edges_by_position(mesh_from_file("cube_v2.msh"));
  EXPECT_EQ(reference.size(), 19u);
  for (const char *name : {"cube_v4.msh", "cube.vtk", "cube.vtu"})
    EXPECT_EQ(edges_by_position(mesh_from_file(name)), reference) << name;
}


TEST(MeshSources, ImplicitFunctionDefaultIsAValidOrgan)
{
  // The defaults aim at a few thousand tetrahedra (0.1 s on the development
  // machine; not timed here: the test machines are shared).
  const TetMesh mesh = mesh_from_source("implicit function", {});
  EXPECT_GE(mesh.n_tets(), 2000u);
  EXPECT_LE(mesh.n_tets(), 10000u);
  double smallest = 1e300;
  for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    smallest = std::min(smallest, mesh.volume(t));
  EXPECT_GT(smallest, 0.0);
  // The default shape is an ellipsoid with semi-axes 5, 3 and 2.5 cm and a dent: its
  // volume is somewhat below the ellipsoid's, 4/3 pi abc = 1.5708e-4 m^3.
  const double ellipsoid = 4.0 / 3 * M_PI * 0.05 * 0.03 * 0.025;
  EXPECT_LT(mesh.total_volume(), ellipsoid);
  EXPECT_GT(mesh.total_volume(), 0.6 * ellipsoid);
  // A closed surface: every boundary vertex lies on f = 0 within the facet distance,
  // so nothing of the object sticks out of the bounding box of the ellipsoid.
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
  {
    EXPECT_LE(std::abs(mesh.vertex(v)[0]), 0.05 * 1.05);
    EXPECT_LE(std::abs(mesh.vertex(v)[1]), 0.03 * 1.05);
    EXPECT_LE(std::abs(mesh.vertex(v)[2]), 0.025 * 1.05);
  }
}


/**
 * The same parameters give the same mesh, vertex for vertex and cell for cell. At this
 * size (22,649 tetrahedra) CGAL's default time limit on its mesh optimisers made three
 * runs give 22,670, 22,657 and 22,655 tetrahedra.
 */
TEST(MeshSources, ImplicitFunctionIsReproducible)
{
  const std::map<std::string, std::string> entries = {{"Cell size", "0.003"},
                                                      {"Facet size", "0.003"},
                                                      {"Facet distance", "0.001"}};
  const TetMesh first  = mesh_from_source("implicit function", entries);
  const TetMesh second = mesh_from_source("implicit function", entries);
  ASSERT_GT(first.n_tets(), 20000u);
  ASSERT_EQ(first.n_vertices(), second.n_vertices());
  ASSERT_EQ(first.n_tets(), second.n_tets());
  for (unsigned int v = 0; v < first.n_vertices(); ++v)
    ASSERT_EQ(first.vertex(v), second.vertex(v)) << "vertex " << v;
  for (unsigned int t = 0; t < first.n_tets(); ++t)
    ASSERT_EQ(first.tet(t), second.tet(t)) << "tetrahedron " << t;
}


TEST(MeshSources, ImplicitFunctionBadExpressionIsRefused)
{
  try
  {
    mesh_from_source("implicit function", {{"Function expression", "x^2 + sin("}});
    FAIL() << "a bad expression was accepted";
  }
  catch (const Error &e)
  {
    EXPECT_NE(std::string(e.what()).find("Function expression"), std::string::npos)
      << e.what();
  }
}


/// A bad file and what its refusal must name besides the file.
struct BadFile
{
  const char *file;
  const char *where;
};


class MeshRefusal : public testing::TestWithParam<BadFile>
{
};


TEST_P(MeshRefusal, NamesTheFileAndTheCell)
{
  const std::string message = refusal(GetParam().file);
  ASSERT_FALSE(message.empty()) << GetParam().file << " was accepted";
  EXPECT_NE(message.find(data_dir + "/" + GetParam().file), std::string::npos) << message;
  EXPECT_NE(message.find(GetParam().where), std::string::npos) << message;
}


INSTANTIATE_TEST_SUITE_P(
  MeshSources,
  MeshRefusal,
  testing::Values(
    BadFile{"bad_repeated_vertex.msh",
            "line 32: element 10 (tetrahedron) is degenerate: it repeats node 5"},
    BadFile{"bad_zero_volume.msh",
            "line 32: element 10 (tetrahedron) is degenerate: its volume is zero"},
    BadFile{"bad_hexahedron.msh", "element 11 (hexahedron) is not a tetrahedron"},
    BadFile{"bad_hexahedron_v4.msh", "element 11 (hexahedron) is not a tetrahedron"},
    BadFile{"bad_nan.msh", "line 18: node 7 has a coordinate that is not a finite"},
    BadFile{"bad_truncated.msh", "is truncated: section $Elements"},
    BadFile{"bad_truncated_v4.msh", "is truncated: section $Nodes"},
    BadFile{"bad_repeated_vertex.vtk", "cell 9 (tetrahedron) is degenerate: it repeats"},
    BadFile{"bad_zero_volume.vtk", "cell 9 (tetrahedron) is degenerate: its volume"},
    BadFile{"bad_hexahedron.vtk", "cell 10 is a hexahedron"},
    BadFile{"bad_nan.vtk", "line 12: point 6 has a coordinate that is not a finite"},
    BadFile{"bad_truncated.vtk",
            "line 21: CELLS ends before all its values (truncated?)"},
    BadFile{"bad_repeated_vertex.vtu", "cell 9 (tetrahedron) is degenerate: it repeats"},
    BadFile{"bad_zero_volume.vtu", "cell 9 (tetrahedron) is degenerate: its volume"},
    BadFile{"bad_hexahedron.vtu", "cell 10 is a hexahedron"},
    BadFile{"bad_nan.vtu", "point 6 has a coordinate that is not a finite"},
    BadFile{"bad_truncated.vtu", "could not be read (truncated or malformed?): "},
    BadFile{"bad_word_in_cell_data.vtu",
            "Piece 0, CellData/boundary_id: cell 6 has a value that is not an integer"},
    BadFile{"bad_short_cell_data.vtu",
            "Piece 0, CellData/boundary_id: it holds 8 values, not 10"},
    BadFile{
      "bad_missing_offsets.vtu",
      "Piece 0: its Cells must have the DataArrays connectivity, offsets and types"},
    BadFile{"bad_offsets_past_connectivity.vtu",
            "Piece 0, Cells/connectivity: it holds 36 values, not 40"},
    BadFile{"bad_missing_node.msh",
            "line 32: element 10 (tetrahedron) refers to node 9, which $Nodes does not"},
    BadFile{"bad_interior_triangle.msh",
            "line 26: element 4 (triangle) is not a boundary face of the tetrahedra (it "
            "lies inside the mesh)"},
    BadFile{"does_not_exist.msh", "cannot be opened"}),
  [](const testing::TestParamInfo<BadFile> &info)
  {
    std::string name = info.param.file;
    for (char &c : name)
      if (!std::isalnum(c))
        c = '_';
    return name;
  });
