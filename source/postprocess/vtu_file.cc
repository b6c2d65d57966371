#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/postprocess/vtu_file.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

namespace lacerta::postprocess
{
  namespace
  {
    vtkSmartPointer<vtkDoubleArray>
    make_array(const VtuField &field, const vtkIdType tuples, const std::string &file)
    {
      if (field.values == nullptr
          || field.values->size() != static_cast<std::size_t>(tuples) * field.components)
        throw_error("Cannot write '",
                    file,
                    "': the field '",
                    field.name,
                    "' does not have ",
                    field.components,
                    " values per entity.");
      auto array = vtkSmartPointer<vtkDoubleArray>::New();
      array->SetName(field.name.c_str());
      array->SetNumberOfComponents(static_cast<int>(field.components));
      array->SetNumberOfTuples(tuples);
      for (vtkIdType i = 0; i < tuples; ++i)
        for (unsigned int c = 0; c < field.components; ++c)
          array->SetComponent(i,
                              static_cast<int>(c),
                              (*field.values)[i * field.components + c]);
      return array;
    }
  } // namespace


  void
  write_vtu_file(const std::string           &file,
                 const mesh::TetMesh         &mesh,
                 const std::vector<double>   &positions,
                 const std::vector<VtuField> &point_fields,
                 const std::vector<VtuField> &cell_fields)
  {
    const vtkIdType   n = mesh.n_vertices();
    vtkNew<vtkPoints> points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    for (vtkIdType i = 0; i < n; ++i)
      points->SetPoint(i, &positions[3 * i]);
    vtkNew<vtkCellArray> cells;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      const vtkIdType ids[4] = {mesh.tet(t)[0],
                                mesh.tet(t)[1],
                                mesh.tet(t)[2],
                                mesh.tet(t)[3]};
      cells->InsertNextCell(4, ids);
    }
    vtkNew<vtkUnstructuredGrid> grid;
    grid->SetPoints(points);
    grid->SetCells(VTK_TETRA, cells);
    for (const VtuField &field : point_fields)
      grid->GetPointData()->AddArray(make_array(field, n, file));
    for (const VtuField &field : cell_fields)
      grid->GetCellData()->AddArray(make_array(field, mesh.n_tets(), file));

    // The file is composed in memory and then replaced atomically: a write that fails
    // leaves the earlier file valid.
    vtkNew<vtkXMLUnstructuredGridWriter> writer;
    writer->WriteToOutputStringOn();
    writer->SetInputData(grid);
    writer->SetDataModeToAppended();
    writer->SetCompressorTypeToZLib();
    if (writer->Write() != 1)
      throw_error("Cannot write '", file, "': VTK failed to encode it.");
    write_file_atomically(file, writer->GetOutputString());
  }
} // namespace lacerta::postprocess
