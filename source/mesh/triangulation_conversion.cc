#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/grid/tria.h>

namespace lacerta::mesh
{
  TetMesh
  tet_mesh_from_triangulation(const dealii::Triangulation<3, 3> &triangulation,
                              const std::string                 &source)
  {
    // Keep only the vertices cells use (a triangulation may hold unused ones).
    const auto               &all_vertices = triangulation.get_vertices();
    std::vector<unsigned int> compact(all_vertices.size(), invalid_index);
    std::vector<Point3>       vertices;
    std::vector<Tet>          tets;
    tets.reserve(triangulation.n_active_cells());
    std::vector<TetMesh::FaceTag> tags;

    const auto index_of = [&](const unsigned int v)
    {
      if (compact[v] == invalid_index)
      {
        compact[v] = vertices.size();
        vertices.push_back({all_vertices[v][0], all_vertices[v][1], all_vertices[v][2]});
      }
      return compact[v];
    };

    unsigned int cell_number = 0;
    for (const auto &cell : triangulation.active_cell_iterators())
    {
      if (cell->n_vertices() != 4)
        throw_error("Mesh '",
                    source,
                    "': cell ",
                    cell_number,
                    " is a ",
                    cell->reference_cell().to_string(),
                    ", not a tetrahedron; Lacerta needs a mesh of tetrahedra.");
      tets.push_back({index_of(cell->vertex_index(0)),
                      index_of(cell->vertex_index(1)),
                      index_of(cell->vertex_index(2)),
                      index_of(cell->vertex_index(3))});
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary() && cell->face(f)->boundary_id() != 0)
          tags.push_back({{index_of(cell->face(f)->vertex_index(0)),
                           index_of(cell->face(f)->vertex_index(1)),
                           index_of(cell->face(f)->vertex_index(2))},
                          cell->face(f)->boundary_id()});
      ++cell_number;
    }
    return TetMesh(std::move(vertices), std::move(tets), source, tags);
  }


  void
  tet_mesh_to_triangulation(const TetMesh               &mesh,
                            dealii::Triangulation<3, 3> &triangulation)
  {
    std::vector<dealii::Point<3>> vertices(mesh.n_vertices());
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      vertices[v] =
        dealii::Point<3>(mesh.vertex(v)[0], mesh.vertex(v)[1], mesh.vertex(v)[2]);

    std::vector<dealii::CellData<3>> cells(mesh.n_tets(), dealii::CellData<3>(4));
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      for (unsigned int i = 0; i < 4; ++i)
        cells[t].vertices[i] = mesh.tet(t)[i];

    dealii::SubCellData boundary;
    for (const BoundaryFace &bf : mesh.get_boundary_faces())
      if (bf.boundary_id != 0)
      {
        dealii::CellData<2> face(3);
        for (unsigned int i = 0; i < 3; ++i)
          face.vertices[i] = mesh.tet(bf.tet)[TetMesh::face_vertices[bf.face][i]];
        face.boundary_id = bf.boundary_id;
        boundary.boundary_quads.push_back(face);
      }
    triangulation.create_triangulation(vertices, cells, boundary);
  }
} // namespace lacerta::mesh
