/**
 * @file
 * A tetrahedral mesh with point and cell fields as one VTU file (ParaView).
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>

#include <string>
#include <vector>

namespace lacerta::postprocess
{
  /// A field written by write_vtu_file(): its name and values, `components` per point
  /// or per cell.
  struct VtuField
  {
    std::string                name;
    unsigned int               components = 1;
    const std::vector<double> *values     = nullptr;
  };

  /**
   * Writes the tetrahedra of @p mesh at @p positions (3 per vertex) with
   * @p point_fields and @p cell_fields to @p file, as compressed binary VTU, replacing
   * the file atomically. An Error names the file if VTK cannot encode it or it cannot
   * be written.
   */
  void
  write_vtu_file(const std::string           &file,
                 const mesh::TetMesh         &mesh,
                 const std::vector<double>   &positions,
                 const std::vector<VtuField> &point_fields,
                 const std::vector<VtuField> &cell_fields);
} // namespace lacerta::postprocess
