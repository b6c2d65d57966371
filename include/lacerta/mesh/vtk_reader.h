/**
 * @file
 * Reading VTK unstructured grids (.vtk legacy and .vtu XML) through the VTK library.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <string>

namespace lacerta::mesh
{
  /**
   * Reads the tetrahedra of a VTK unstructured grid. Triangles are boundary
   * information: if the file has an integer cell array `boundary_id` (or
   * `gmsh:physical`), its value on a triangle becomes the boundary id of that face.
   * Vertices and lines are ignored; any other cell type, an unreadable or truncated file
   * is an Error naming the file (and the cell).
   */
  TetMesh
  read_vtk_unstructured_grid(const std::string &file_name);
} // namespace lacerta::mesh
