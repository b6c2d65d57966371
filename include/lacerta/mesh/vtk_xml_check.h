/**
 * @file
 * The structure of an XML VTK unstructured grid (.vtu), checked before VTK reads it.
 */
#pragma once

#include <string>

namespace lacerta::mesh
{
  /**
   * Checks what VTK's XML reader trusts in the .vtu file @p file_name before it reads
   * the data (it crashes on a Piece whose inline ASCII arrays hold fewer values than the
   * Piece declares, or a word that is not a number):
   * - the file parses as XML, and every `Piece` gives `NumberOfPoints` and
   *   `NumberOfCells` as non-negative integers;
   * - a Piece has `Points` with a 3-component array, and, if it has cells, `Cells` with
   *   the `connectivity`, `offsets` and `types` arrays;
   * - every `DataArray` of `Points`, `Cells`, `PointData` and `CellData` names its type
   *   and format, and its `NumberOfComponents`, if given, is a positive integer;
   * - an ASCII numeric array holds exactly one value per tuple and component (one
   *   tuple per point or per cell; the connectivity as many as the offsets say), each a
   *   number its type can hold (a finite coordinate for the points); the offsets do not
   *   decrease and the connectivity names points of the Piece.
   *
   * Binary and appended arrays are left to VTK, which checks their sizes as it decodes
   * them. A violation is an Error naming the file, the Piece and the array.
   */
  void
  check_vtk_xml_file(const std::string &file_name);
} // namespace lacerta::mesh
