// Mesh source `file`: gmsh .msh (through deal.II's GridIn) and VTK .vtk/.vtu (through
// the VTK library).

#include <lacerta/base/input_path.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/mesh/vtk_reader.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/tria.h>

#include <algorithm>
#include <cmath>
#include <fstream>

namespace lacerta::mesh
{
  namespace
  {
    bool
    ends_with(const std::string &text, const std::string &suffix)
    {
      return text.size() >= suffix.size()
             && text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
    }


    /**
     * Checks what GridIn reports poorly or not at all: the format version, sections cut
     * off by truncation, and coordinates that are not finite numbers.
     */
    void
    check_gmsh_file(const std::string &file_name)
    {
      std::ifstream in(file_name);
      if (!in)
        throw_error("Mesh file '", file_name, "' cannot be opened.");

      std::vector<std::string> lines;
      for (std::string line; std::getline(in, line);)
      {
        if (!line.empty() && line.back() == '\r')
          line.pop_back();
        lines.push_back(line);
      }
      if (lines.size() < 2 || lines[0] != "$MeshFormat")
        throw_error("Mesh file '",
                    file_name,
                    "' is not a gmsh file: it does not start with $MeshFormat.");
      std::istringstream format(lines[1]);
      double             version   = 0;
      int                file_type = -1;
      format >> version >> file_type;
      if (!(version >= 2 && version < 3) && !(version >= 4 && version < 5))
        throw_error("Mesh file '",
                    file_name,
                    "': gmsh format version '",
                    lines[1],
                    "' is not supported (Lacerta reads versions 2 and 4).");
      if (file_type != 0)
        throw_error("Mesh file '",
                    file_name,
                    "' is a binary gmsh file; save it as ASCII.");

      std::string open_section;
      std::size_t open_line = 0;
      bool        has_nodes = false, has_elements = false;
      for (std::size_t i = 0; i < lines.size(); ++i)
      {
        const std::string &line = lines[i];
        if (!line.empty() && line[0] == '$')
        {
          if (open_section.empty())
          {
            open_section = line.substr(1);
            open_line    = i + 1;
          }
          else if (line == "$End" + open_section)
          {
            has_nodes |= (open_section == "Nodes");
            has_elements |= (open_section == "Elements");
            open_section.clear();
          }
          else
            throw_error("Mesh file '",
                        file_name,
                        "', line ",
                        i + 1,
                        ": found '",
                        line,
                        "' inside section $",
                        open_section,
                        " (opened on line ",
                        open_line,
                        "); the file is truncated or malformed.");
        }
        else if (open_section == "Nodes")
        {
          std::istringstream tokens(line);
          for (std::string token; tokens >> token;)
          {
            std::string lower = token;
            std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
            const bool not_finite =
              lower.find("nan") != std::string::npos
              || lower.find("inf") != std::string::npos
              || !std::isfinite(std::strtod(token.c_str(), nullptr));
            if (not_finite)
              throw_error("Mesh file '",
                          file_name,
                          "', line ",
                          i + 1,
                          ": the node coordinate '",
                          token,
                          "' is not a finite number.");
          }
        }
      }
      if (!open_section.empty())
        throw_error("Mesh file '",
                    file_name,
                    "' is truncated: section $",
                    open_section,
                    " (opened on line ",
                    open_line,
                    ") has no $End",
                    open_section,
                    ".");
      if (!has_nodes || !has_elements)
        throw_error("Mesh file '",
                    file_name,
                    "' is truncated or incomplete: it lacks a $",
                    has_nodes ? "Elements" : "Nodes",
                    " section.");
    }


    TetMesh
    read_gmsh(const std::string &file_name)
    {
      check_gmsh_file(file_name);
      dealii::Triangulation<3> triangulation;
      dealii::GridIn<3>        grid_in;
      grid_in.attach_triangulation(triangulation);
      std::ifstream in(file_name);
      try
      {
        grid_in.read_msh(in);
      }
      catch (const dealii::ExceptionBase &e)
      {
        std::ostringstream info;
        e.print_info(info);
        throw_error("Mesh file '",
                    file_name,
                    "' could not be read (truncated or malformed?): ",
                    info.str());
      }
      return tet_mesh_from_triangulation(triangulation, file_name);
    }


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
          "The mesh file: gmsh '.msh' (ASCII, format 2 or 4; surface "
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

  LACERTA_REGISTER_MESH_SOURCE(FileSource,
                               "file",
                               "A mesh read from a file ('subsection File'): gmsh .msh "
                               "(versions 2 and 4) or VTK .vtk/.vtu unstructured grids.");
} // namespace lacerta::mesh
