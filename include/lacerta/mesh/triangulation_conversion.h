/**
 * @file
 * Conversion between deal.II triangulations of simplices and TetMesh.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <string>

namespace dealii
{
  template <int dim, int spacedim>
  class Triangulation;
}

namespace lacerta::mesh
{
  /**
   * Builds a TetMesh from a deal.II triangulation of tetrahedra, keeping the boundary
   * ids of its faces. A cell that is not a tetrahedron is an error naming @p source and
   * the cell.
   */
  TetMesh
  tet_mesh_from_triangulation(const dealii::Triangulation<3, 3> &triangulation,
                              const std::string                 &source);

  /**
   * Fills @p triangulation (which must be empty) with the tetrahedra of @p mesh in
   * their rest configuration, with the mesh's boundary ids; used by the FEM reference.
   */
  void
  tet_mesh_to_triangulation(const TetMesh               &mesh,
                            dealii::Triangulation<3, 3> &triangulation);
} // namespace lacerta::mesh
