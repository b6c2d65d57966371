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
   * Reads the tetrahedra of a VTK unstructured grid, legacy (.vtk) or XML (.vtu).
   * Triangles are boundary information: if the file has an integer cell array
   * `boundary_id` (or `gmsh:physical`), its value on a triangle becomes the boundary id
   * of that face. Vertices and lines are ignored. Any other cell type, a degenerate
   * tetrahedron, a coordinate that is not a finite number, an unreadable or truncated
   * file is an Error naming the file and the cell (counted from 0 in file order,
   * triangles included) or the point; VTK's own messages are kept out of the terminal
   * and put into the Error.
   */
  TetMesh
  read_vtk_unstructured_grid(const std::string &file_name);
} // namespace lacerta::mesh
