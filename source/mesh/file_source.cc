// Mesh source `file`: gmsh .msh (through deal.II's GridIn) and VTK .vtk/.vtu (through
// the VTK library).

#include <lacerta/base/input_path.h>
#include <lacerta/mesh/gmsh_reader.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/vtk_reader.h>

#include <fstream>

namespace lacerta::mesh
{
  namespace
  {
    /**
     * A mesh read from a file; the format follows the extension.
     */
    class FileSource : public MeshSource
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "File name",
          "",
          dealii::Patterns::FileName(),
          "The mesh file: gmsh '.msh' (ASCII, format 2.2 or 4.1; surface "
          "elements give boundary ids through their physical tag) or VTK "
          "unstructured grid '.vtk' (legacy) or '.vtu' (XML; triangles give "
          "boundary ids through a cell array 'boundary_id'). A relative "
          "name is taken from the directory of the parameter file.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        file_name = resolve_input_path(prm.get("File name"));
        if (file_name.empty())
          throw_error("Mesh/File: 'File name' is empty; name a .msh, .vtk or .vtu file.");
      }

      TetMesh
      create_mesh() const override
      {
        if (!std::ifstream(file_name))
          throw_error("Mesh file '", file_name, "' cannot be opened.");
        if (ends_with(file_name, ".msh"))
          return read_gmsh(file_name);
        if (ends_with(file_name, ".vtk") || ends_with(file_name, ".vtu"))
          return read_vtk_unstructured_grid(file_name);
        throw_error("Mesh file '",
                    file_name,
                    "' has an unknown extension; use .msh, .vtk or .vtu.");
      }

    private:
      std::string file_name;
    };
  } // namespace

  LACERTA_REGISTER_MESH_SOURCE(
    FileSource,
    "file",
    "A mesh read from a file ('subsection File'): gmsh .msh "
    "(ASCII formats 2.2 and 4.1) or VTK .vtk/.vtu unstructured grids.");
} // namespace lacerta::mesh
