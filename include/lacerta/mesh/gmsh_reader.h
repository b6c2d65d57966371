/**
 * @file
 * Reading gmsh .msh files (ASCII, format 2.2 and 4.1) through deal.II's GridIn.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <string>

namespace lacerta::mesh
{
  /**
   * Checks a gmsh ASCII file (format 2.x or 4.1) before deal.II reads it: the sections
   * are complete, every node coordinate is a finite number, every element has a known
   * type and refers to defined nodes, volume elements are tetrahedra that are not
   * degenerate, surface elements are triangles (the only faces a tetrahedron has).
   * Points and lines are accepted and ignored. A problem is an Error whose message
   * names the file, the line and the element (by its tag in the file).
   */
  void
  check_gmsh_file(const std::string &file_name);

  /**
   * Reads the tetrahedra of a gmsh ASCII file after check_gmsh_file() accepted it.
   * Triangles are boundary information, not cells: their physical tag becomes the
   * boundary id of the face they cover (0 where no triangle is given).
   */
  TetMesh
  read_gmsh(const std::string &file_name);
} // namespace lacerta::mesh
