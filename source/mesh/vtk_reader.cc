#include <lacerta/base/exceptions.h>
#include <lacerta/base/input_path.h>
#include <lacerta/mesh/vtk_reader.h>
#include <lacerta/mesh/vtk_xml_check.h>

#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkCellTypes.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>
#include <vtkUnstructuredGrid.h>
#include <vtkUnstructuredGridReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace lacerta::mesh
{
  namespace
  {
    /**
     * Routes VTK's messages into a string while it lives. VTK reports some problems
     * (those of its XML parser, say) through the global output window rather than
     * through the reader, and would print them to the terminal without failing.
     */
    class CapturedVtkMessages
    {
    public:
      CapturedVtkMessages()
          : previous(vtkOutputWindow::GetInstance())
          , previous_verbosity(vtkLogger::GetCurrentVerbosityCutoff())
      {
        vtkOutputWindow::SetInstance(window);
        // VTK's logger would print the same messages to the terminal as well.
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
      }

      ~CapturedVtkMessages()
      {
        vtkOutputWindow::SetInstance(previous);
        vtkLogger::SetStderrVerbosity(previous_verbosity);
      }

      CapturedVtkMessages(const CapturedVtkMessages &) = delete;
      CapturedVtkMessages &
      operator=(const CapturedVtkMessages &) = delete;

      /**
       * The messages so far if one of them is an error (else ""), without VTK's source
       * locations and object addresses, which mean nothing to a user.
       */
      std::string
      errors() const
      {
        const std::string text = window->GetOutput();
        if (text.find("ERROR") == std::string::npos)
          return "";
        std::istringstream lines(text);
        std::string        result;
        for (std::string line; std::getline(lines, line);)
        {
          // Skip the source locations, and the pipeline's report that the reader
          // failed with its indented dump of the request: the reader said why.
          if (line.empty() || std::isspace(line[0])
              || line.find(": In ") != std::string::npos
              || line.find("returned failure for request") != std::string::npos)
            continue;
          const std::size_t address = line.find(" (0x");
          const std::size_t close   = line.find("): ", address);
          if (address != std::string::npos && close != std::string::npos)
            line.erase(address, close + 1 - address);
          result += (result.empty() ? "" : " ") + line;
        }
        return result;
      }

    private:
      vtkSmartPointer<vtkOutputWindow> previous;
      vtkLogger::Verbosity             previous_verbosity;
      vtkNew<vtkStringOutputWindow>    window;
    };


    /// Reads the file with the VTK reader that fits its extension.
    vtkSmartPointer<vtkUnstructuredGrid>
    read_grid(const std::string &file_name)
    {
      const CapturedVtkMessages messages;

      vtkSmartPointer<vtkUnstructuredGrid> grid;
      bool                                 failed = false;
      if (ends_with(file_name, ".vtu"))
      {
        vtkNew<vtkXMLUnstructuredGridReader> reader;
        if (!reader->CanReadFile(file_name.c_str()))
          throw_error("Mesh file '",
                      file_name,
                      "' is not an XML VTK file holding an UnstructuredGrid.");
        reader->SetFileName(file_name.c_str());
        reader->Update();
        grid   = reader->GetOutput();
        failed = reader->GetErrorCode() != 0;
      }
      else
      {
        vtkNew<vtkUnstructuredGridReader> reader;
        reader->SetFileName(file_name.c_str());
        if (!reader->IsFileUnstructuredGrid())
          throw_error("Mesh file '",
                      file_name,
                      "' is not a legacy VTK file holding an UNSTRUCTURED_GRID.");
        reader->Update();
        grid   = reader->GetOutput();
        failed = reader->GetErrorCode() != 0;
      }
      const std::string errors = messages.errors();
      if (failed || !errors.empty())
        throw_error("Mesh file '",
                    file_name,
                    "' could not be read (truncated or malformed?)",
                    errors.empty() ? "." : ": ",
                    errors);
      return grid;
    }


    /**
     * The header lines of an ASCII legacy file that carry counts, checked before VTK
     * reads it: VTK's legacy reader trusts them and reads on from a failed stream
     * (a `CELLS` line without its two counts crashes it). Every `POINTS`, `CELLS`,
     * `CELL_TYPES`, `CELL_DATA`, `POINT_DATA` and `FIELD` line must carry its counts as
     * non-negative integers; the cell list and the cell types must hold as many
     * integers as they announce (a short or non-numeric list crashes VTK too). VTK
     * also stops at a
     * coordinate written as `nan` or `inf` with "Unrecognized keyword", which names
     * neither the point nor the line: the POINTS are checked here too. Other problems
     * are left to VTK.
     */
    class LegacyHeaderCheck
    {
    public:
      explicit LegacyHeaderCheck(const std::string &file_name)
          : file_name(file_name)
      {
      }

      void
      run()
      {
        std::ifstream in(file_name);
        std::string   line;
        for (; line_number < 3 && std::getline(in, line); ++line_number)
          if (line_number == 2 && line.rfind("ASCII", 0) != 0)
            return;
        while (std::getline(in, line))
        {
          ++line_number;
          std::istringstream tokens(line);
          std::string        keyword;
          if (!(tokens >> keyword))
            continue;
          if (is_keyword(keyword, "points"))
            check_points(in, count(tokens, keyword, "the number of points"));
          else if (is_keyword(keyword, "cells"))
          {
            const std::size_t n    = count(tokens, keyword, "the number of cells");
            const std::size_t size = count(tokens, keyword, "the size of the cell list");
            check_cell_list(in, n, size);
          }
          else if (is_keyword(keyword, "cell_types"))
            check_integers(in,
                           count(tokens, keyword, "the number of cells"),
                           "CELL_TYPES");
          else if (is_keyword(keyword, "cell_data"))
            count(tokens, keyword, "the number of cells");
          else if (is_keyword(keyword, "point_data"))
            count(tokens, keyword, "the number of points");
          else if (is_keyword(keyword, "field"))
          {
            std::string name;
            tokens >> name;
            const std::size_t n_arrays = count(tokens, keyword, "the number of arrays");
            pending                    = std::istringstream();
            for (std::size_t a = 0; a < n_arrays; ++a)
              check_field_array(in);
          }
        }
      }

    private:
      [[noreturn]] void
      fail(const std::string &what) const
      {
        throw_error("Mesh file '", file_name, "', line ", line_number, ": ", what, ".");
      }

      /// Whether VTK takes @p token for the keyword @p lower_case: it compares the
      /// token's first letters, in lower case ("CELLSTYPES" is a CELLS line to VTK).
      static bool
      is_keyword(std::string token, const std::string &lower_case)
      {
        std::transform(token.begin(), token.end(), token.begin(), ::tolower);
        return token.compare(0, lower_case.size(), lower_case) == 0;
      }

      // The next token of @p tokens as a count, or an Error naming @p what.
      std::size_t
      count(std::istringstream &tokens,
            const std::string  &keyword,
            const char         *what) const
      {
        std::string token;
        tokens >> token;
        char                    *rest  = nullptr;
        const unsigned long long value = std::strtoull(token.c_str(), &rest, 10);
        if (token.empty() || token[0] == '-' || *rest != '\0' || value > (1ull << 40))
          fail(keyword + " must give " + what + " as a non-negative integer, not '"
               + token + "'");
        return static_cast<std::size_t>(value);
      }

      // The next token of the file after the current line's tokens, or an Error
      // naming @p section.
      std::string
      next_token(std::ifstream &in, const std::string &section)
      {
        std::string token;
        while (!(pending >> token))
        {
          std::string line;
          if (!std::getline(in, line))
            fail(section + " ends before all its values (truncated?)");
          ++line_number;
          pending = std::istringstream(line);
        }
        return token;
      }

      // The next integer of the file after the current line's tokens, or an Error
      // naming @p section.
      long long
      next_integer(std::ifstream &in, const char *section)
      {
        const std::string token = next_token(in, section);
        char             *rest  = nullptr;
        const long long   value = std::strtoll(token.c_str(), &rest, 10);
        if (token.empty() || *rest != '\0')
          fail(std::string(section) + " holds '" + token + "' where an integer belongs");
        return value;
      }

      // One array of a FIELD: "name components tuples type", then its values (skipped
      // here, so that an array name is not taken for a keyword).
      void
      check_field_array(std::ifstream &in)
      {
        const std::string name = next_token(in, "FIELD");
        if (name == "NULL_ARRAY")
          return;
        std::istringstream header(next_token(in, "FIELD") + " "
                                  + next_token(in, "FIELD"));
        const std::string  section = "FIELD array '" + name + "'";
        const std::size_t  values  = count(header, section, "its number of components")
                                   * count(header, section, "its number of tuples");
        next_token(in, section);
        for (std::size_t i = 0; i < values; ++i)
          next_token(in, section);
      }

      void
      check_integers(std::ifstream &in, const std::size_t n, const char *section)
      {
        pending = std::istringstream();
        for (std::size_t i = 0; i < n; ++i)
          next_integer(in, section);
      }

      // The cell list of the legacy format before version 5: @p n records "k i_1 ..
      // i_k" in @p size integers. (Version 5 writes OFFSETS and CONNECTIVITY arrays
      // instead, which VTK reads as data arrays.)
      void
      check_cell_list(std::ifstream &in, const std::size_t n, const std::size_t size)
      {
        pending = std::istringstream();
        if (in.peek() == 'O')
          return;
        std::size_t read = 0;
        for (std::size_t record = 0; record < n; ++record)
        {
          const long long k = next_integer(in, "CELLS");
          if (k < 0 || read + 1 + static_cast<std::size_t>(k) > size)
            fail("CELLS: cell " + std::to_string(record) + " has " + std::to_string(k)
                 + " vertices, more than the list's size " + std::to_string(size)
                 + " leaves");
          for (long long i = 0; i < k; ++i)
            next_integer(in, "CELLS");
          read += 1 + static_cast<std::size_t>(k);
        }
        if (read != size)
          fail("CELLS: the " + std::to_string(n) + " cells take " + std::to_string(read)
               + " integers, not the size " + std::to_string(size) + " it gives");
      }

      void
      check_points(std::ifstream &in, const std::size_t n_points)
      {
        std::size_t coordinate = 0;
        std::string line;
        while (coordinate < 3 * n_points && std::getline(in, line))
        {
          ++line_number;
          std::istringstream tokens(line);
          for (std::string token; coordinate < 3 * n_points && tokens >> token;
               ++coordinate)
          {
            char        *rest = nullptr;
            const double x    = std::strtod(token.c_str(), &rest);
            if (rest == token.c_str() || *rest != '\0' || !std::isfinite(x))
              fail("point " + std::to_string(coordinate / 3)
                   + " has a coordinate that is not a finite number ('" + token + "')");
          }
        }
      }

      const std::string  file_name;
      std::size_t        line_number = 0;
      std::istringstream pending;
    };


    /// "hexahedron" for VTK_HEXAHEDRON: VTK's class name without its prefix.
    std::string
    cell_type_name(const int type)
    {
      std::string name = vtkCellTypes::GetClassNameFromTypeId(type);
      if (name.rfind("vtk", 0) == 0)
        name = name.substr(3);
      std::transform(name.begin(), name.end(), name.begin(), ::tolower);
      return name;
    }
  } // namespace


  TetMesh
  read_vtk_unstructured_grid(const std::string &file_name)
  {
    if (!std::ifstream(file_name))
      throw_error("Mesh file '", file_name, "' cannot be opened.");
    if (ends_with(file_name, ".vtu"))
      check_vtk_xml_file(file_name);
    else
      LegacyHeaderCheck(file_name).run();

    const vtkSmartPointer<vtkUnstructuredGrid> grid = read_grid(file_name);
    if (grid == nullptr || grid->GetNumberOfPoints() == 0)
      throw_error("Mesh file '", file_name, "' holds no points (truncated or empty?).");

    std::vector<Point3> vertices(grid->GetNumberOfPoints());
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
    {
      grid->GetPoint(i, vertices[i].data());
      for (const double x : vertices[i])
        if (!std::isfinite(x))
          throw_error("Mesh file '",
                      file_name,
                      "': point ",
                      i,
                      " has a coordinate that is not a finite number (",
                      vertices[i][0],
                      ", ",
                      vertices[i][1],
                      ", ",
                      vertices[i][2],
                      ").");
    }

    vtkDataArray *ids = grid->GetCellData()->GetArray("boundary_id");
    if (ids == nullptr)
      ids = grid->GetCellData()->GetArray("gmsh:physical");
    if (ids != nullptr
        && (ids->GetNumberOfComponents() != 1
            || ids->GetNumberOfTuples() != grid->GetNumberOfCells()))
      throw_error("Mesh file '",
                  file_name,
                  "': the cell array '",
                  ids->GetName(),
                  "' must hold one value per cell (",
                  grid->GetNumberOfCells(),
                  "), not ",
                  ids->GetNumberOfTuples(),
                  " tuples of ",
                  ids->GetNumberOfComponents(),
                  ".");

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
      if ((type == VTK_TETRA && points->GetNumberOfIds() != 4)
          || (type == VTK_TRIANGLE && points->GetNumberOfIds() != 3))
        throw_error("Mesh file '",
                    file_name,
                    "': cell ",
                    c,
                    " (",
                    cell_type_name(type),
                    ") has ",
                    points->GetNumberOfIds(),
                    " vertices.");
      if (type == VTK_TETRA)
      {
        const Tet cell = {static_cast<unsigned int>(points->GetId(0)),
                          static_cast<unsigned int>(points->GetId(1)),
                          static_cast<unsigned int>(points->GetId(2)),
                          static_cast<unsigned int>(points->GetId(3))};
        // Checked here, not only in TetMesh, so that the message counts cells as the
        // file does (triangles included).
        const std::string problem = degeneracy(vertices, cell);
        if (!problem.empty())
          throw_error("Mesh file '",
                      file_name,
                      "': cell ",
                      c,
                      " (tetrahedron) is degenerate: ",
                      problem,
                      ".");
        tets.push_back(cell);
      }
      else if (type == VTK_TRIANGLE)
      {
        if (ids != nullptr)
        {
          const double id = ids->GetTuple1(c);
          if (!(id >= 0 && id < 1e9 && id == std::floor(id)))
            throw_error("Mesh file '",
                        file_name,
                        "': cell ",
                        c,
                        " (triangle) has the boundary id ",
                        id,
                        ", which is not a non-negative integer.");
          tags.push_back({{static_cast<unsigned int>(points->GetId(0)),
                           static_cast<unsigned int>(points->GetId(1)),
                           static_cast<unsigned int>(points->GetId(2))},
                          static_cast<unsigned int>(id)});
        }
      }
      else if (type != VTK_VERTEX && type != VTK_POLY_VERTEX && type != VTK_LINE
               && type != VTK_POLY_LINE)
        throw_error("Mesh file '",
                    file_name,
                    "': cell ",
                    c,
                    " is a ",
                    cell_type_name(type),
                    " (VTK cell type ",
                    type,
                    "), not a tetrahedron (10); Lacerta needs a mesh of tetrahedra.");
    }
    if (tets.empty())
      throw_error("Mesh file '", file_name, "' has no tetrahedra.");
    return TetMesh(std::move(vertices), std::move(tets), file_name, tags);
  }
} // namespace lacerta::mesh
