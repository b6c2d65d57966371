#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/vtk_reader.h>

#include <vtkCallbackCommand.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCommand.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <fstream>

namespace lacerta::mesh
{
  namespace
  {
    /// Collects the error messages VTK would otherwise print to its output window.
    void
    record_vtk_error(vtkObject *, unsigned long, void *client_data, void *call_data)
    {
      auto *messages = static_cast<std::string *>(client_data);
      if (call_data != nullptr)
        *messages += static_cast<const char *>(call_data);
    }


    bool
    ends_with(const std::string &text, const std::string &suffix)
    {
      return text.size() >= suffix.size()
             && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
    }


    /// Reads the file with the VTK reader that fits its extension.
    vtkSmartPointer<vtkUnstructuredGrid>
    read_grid(const std::string &file_name)
    {
      std::string                errors;
      vtkNew<vtkCallbackCommand> on_error;
      on_error->SetCallback(record_vtk_error);
      on_error->SetClientData(&errors);

      vtkSmartPointer<vtkUnstructuredGrid> grid;
      if (ends_with(file_name, ".vtu"))
      {
        vtkNew<vtkXMLUnstructuredGridReader> reader;
        reader->AddObserver(vtkCommand::ErrorEvent, on_error);
        reader->SetFileName(file_name.c_str());
        reader->Update();
        grid = reader->GetOutput();
        if (reader->GetErrorCode() != 0 && errors.empty())
          errors = "the VTK reader reported an error";
      }
      else
      {
        vtkNew<vtkUnstructuredGridReader> reader;
        reader->AddObserver(vtkCommand::ErrorEvent, on_error);
        reader->SetFileName(file_name.c_str());
        if (!reader->IsFileUnstructuredGrid())
          throw_error("Mesh file '",
                      file_name,
                      "' is not a legacy VTK file holding an UNSTRUCTURED_GRID.");
        reader->Update();
        grid = reader->GetOutput();
      }
      if (!errors.empty())
        throw_error("Mesh file '",
                    file_name,
                    "' could not be read (truncated or malformed?): ",
                    errors);
      return grid;
    }
  } // namespace


  TetMesh
  read_vtk_unstructured_grid(const std::string &file_name)
  {
    if (!std::ifstream(file_name))
      throw_error("Mesh file '", file_name, "' cannot be opened.");

    const vtkSmartPointer<vtkUnstructuredGrid> grid = read_grid(file_name);
    if (grid == nullptr || grid->GetNumberOfPoints() == 0)
      throw_error("Mesh file '", file_name, "' holds no points (truncated or empty?).");

    std::vector<Point3> vertices(grid->GetNumberOfPoints());
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
      grid->GetPoint(i, vertices[i].data());

    vtkDataArray *ids = grid->GetCellData()->GetArray("boundary_id");
    if (ids == nullptr)
      ids = grid->GetCellData()->GetArray("gmsh:physical");

    std::vector<Tet>              tets;
    std::vector<TetMesh::FaceTag> tags;
    vtkNew<vtkIdList>             points;
    for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
    {
      const int type = grid->GetCellType(c);
      grid->GetCellPoints(c, points);
      for (vtkIdType i = 0; i < points->GetNumberOfIds(); ++i)
        if (points->GetId(i) < 0 || points->GetId(i) >= grid->GetNumberOfPoints())
          throw_error("Mesh file '",
                      file_name,
                      "': cell ",
                      c,
                      " refers to point ",
                      points->GetId(i),
                      ", which does not exist (truncated file?).");
      if (type == VTK_TETRA)
        tets.push_back({static_cast<unsigned int>(points->GetId(0)),
                        static_cast<unsigned int>(points->GetId(1)),
                        static_cast<unsigned int>(points->GetId(2)),
                        static_cast<unsigned int>(points->GetId(3))});
      else if (type == VTK_TRIANGLE)
      {
        if (ids != nullptr)
          tags.push_back({{static_cast<unsigned int>(points->GetId(0)),
                           static_cast<unsigned int>(points->GetId(1)),
                           static_cast<unsigned int>(points->GetId(2))},
                          static_cast<unsigned int>(ids->GetTuple1(c))});
      }
      else if (type != VTK_VERTEX && type != VTK_POLY_VERTEX && type != VTK_LINE
               && type != VTK_POLY_LINE)
        throw_error("Mesh file '",
                    file_name,
                    "': cell ",
                    c,
                    " has VTK cell type ",
                    type,
                    ", not a tetrahedron (10); Lacerta needs a mesh of tetrahedra.");
    }
    return TetMesh(std::move(vertices), std::move(tets), file_name, tags);
  }
} // namespace lacerta::mesh
