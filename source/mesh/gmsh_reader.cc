// gmsh .msh files: a strict check of our own, then deal.II's GridIn reads the file that
// passed. The check is needed: GridIn (9.4.1) silently accepts a hexahedron among the
// tetrahedra and degenerate tetrahedra, and names neither the line nor the element of
// the problems it does find.

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/gmsh_reader.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/tria.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <unordered_map>
#include <utility>

namespace lacerta::mesh
{
  namespace
  {
    /// Name and number of nodes of the gmsh element types 1 to 19 (index = type).
    struct ElementType
    {
      const char  *name;
      unsigned int n_nodes;
    };
    constexpr ElementType  element_types[] = {{"", 0},
                                              {"line", 2},
                                              {"triangle", 3},
                                              {"quadrangle", 4},
                                              {"tetrahedron", 4},
                                              {"hexahedron", 8},
                                              {"prism", 6},
                                              {"pyramid", 5},
                                              {"second-order line", 3},
                                              {"second-order triangle", 6},
                                              {"second-order quadrangle", 9},
                                              {"second-order tetrahedron", 10},
                                              {"second-order hexahedron", 27},
                                              {"second-order prism", 18},
                                              {"second-order pyramid", 14},
                                              {"point", 1},
                                              {"8-node quadrangle", 8},
                                              {"20-node hexahedron", 20},
                                              {"15-node prism", 15},
                                              {"13-node pyramid", 13}};
    constexpr unsigned int gmsh_line = 1, gmsh_triangle = 2, gmsh_tetrahedron = 4,
                           gmsh_point = 15;


    /**
     * Reads the whitespace-separated tokens of one section of the file and knows the
     * line each came from, so that every message can name it.
     */
    class SectionReader
    {
    public:
      SectionReader(const std::string              &file_name,
                    const std::vector<std::string> &lines,
                    const std::string              &section,
                    const std::size_t               begin,
                    const std::size_t               end)
          : file_name(file_name)
          , lines(lines)
          , section(section)
          , current(begin)
          , end(end)
      {
      }

      /// The 1-based line of the last token read.
      std::size_t
      line() const
      {
        return current + 1;
      }

      /// The next token; a section that ends first is a truncated or malformed file.
      std::string
      token(const char *what)
      {
        while (current < end)
        {
          const std::string &text = lines[current];
          while (position < text.size() && std::isspace(text[position]))
            ++position;
          if (position < text.size())
          {
            const std::size_t start = position;
            while (position < text.size() && !std::isspace(text[position]))
              ++position;
            return text.substr(start, position - start);
          }
          ++current;
          position = 0;
        }
        throw_error("Mesh file '",
                    file_name,
                    "', line ",
                    end + 1,
                    ": section $",
                    section,
                    " ends where ",
                    what,
                    " was expected; the file is truncated or malformed.");
      }

      /// The next token as a non-negative integer.
      std::size_t
      integer(const char *what)
      {
        const std::string text = token(what);
        char             *rest = nullptr;
        const long long   n    = std::strtoll(text.c_str(), &rest, 10);
        if (rest == text.c_str() || *rest != '\0' || n < 0)
          fail("expected ", what, " (a non-negative integer), found '", text, "'");
        return static_cast<std::size_t>(n);
      }

      /// The next token as a floating-point number (which may be NaN or infinite).
      double
      number(const char *what)
      {
        const std::string text = token(what);
        char             *rest = nullptr;
        const double      x    = std::strtod(text.c_str(), &rest);
        if (rest == text.c_str() || *rest != '\0')
          fail("expected ", what, " (a number), found '", text, "'");
        return x;
      }

      /// Checks that nothing but whitespace is left in the section.
      void
      expect_end(const char *after)
      {
        for (; current < end; ++current, position = 0)
        {
          const std::string &text = lines[current];
          const std::size_t  next = text.find_first_not_of(" \t", position);
          if (next != std::string::npos)
            throw_error("Mesh file '",
                        file_name,
                        "', line ",
                        current + 1,
                        ": unexpected '",
                        text.substr(next),
                        "' after ",
                        after,
                        " in section $",
                        section,
                        " (the counts in the section do not match its contents).");
        }
      }

      /// Throws an Error naming the file and the current line.
      template <typename... Args>
      [[noreturn]] void
      fail(const Args &...pieces) const
      {
        throw_error("Mesh file '", file_name, "', line ", line(), ": ", pieces..., ".");
      }

    private:
      const std::string              &file_name;
      const std::vector<std::string> &lines;
      const std::string               section;
      std::size_t                     current;
      std::size_t                     position = 0;
      const std::size_t               end;
    };


    /// An element as the file gives it.
    struct Element
    {
      std::size_t              tag;
      unsigned int             type;
      std::vector<std::size_t> nodes;
      std::size_t              line;
    };


    /// Reads one element's type-dependent node list after its tag and type.
    Element
    read_element(SectionReader &in, const std::size_t tag, const std::size_t type)
    {
      const std::size_t n_types = sizeof(element_types) / sizeof(element_types[0]);
      if (type == 0 || type >= n_types)
        in.fail("element ", tag, " has type ", type, ", which Lacerta does not know");
      Element element{tag, static_cast<unsigned int>(type), {}, in.line()};
      element.nodes.resize(element_types[type].n_nodes);
      for (std::size_t &node : element.nodes)
        node = in.integer("a node tag");
      return element;
    }


    /// The lines of file @p file_name, without carriage returns.
    std::vector<std::string>
    read_lines(const std::string &file_name)
    {
      std::ifstream file(file_name);
      if (!file)
        throw_error("Mesh file '", file_name, "' cannot be opened.");
      std::vector<std::string> lines;
      for (std::string line; std::getline(file, line);)
      {
        if (!line.empty() && line.back() == '\r')
          line.pop_back();
        lines.push_back(line);
      }
      if (lines.empty() || lines[0] != "$MeshFormat")
        throw_error("Mesh file '",
                    file_name,
                    "' is not a gmsh file: it does not start with $MeshFormat.");
      return lines;
    }


    /// The sections of a gmsh file: [first line of the body, line of $End...) for
    /// every name.
    using Sections = std::map<std::string, std::pair<std::size_t, std::size_t>>;


    /// The sections of @p lines (the file @p file_name), every $Name closed by
    /// $EndName; $MeshFormat, $Nodes and $Elements are required.
    Sections
    find_sections(const std::string &file_name, const std::vector<std::string> &lines)
    {
      Sections    sections;
      std::string open_section;
      std::size_t open_line = 0;
      for (std::size_t i = 0; i < lines.size(); ++i)
      {
        const std::string &line = lines[i];
        if (line.empty() || line[0] != '$')
          continue;
        if (open_section.empty())
        {
          open_section = line.substr(1);
          open_line    = i;
        }
        else if (line == "$End" + open_section)
        {
          sections[open_section] = {open_line + 1, i};
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
                      open_line + 1,
                      "); the file is truncated or malformed.");
      }
      if (!open_section.empty())
        throw_error("Mesh file '",
                    file_name,
                    "' is truncated: section $",
                    open_section,
                    " (opened on line ",
                    open_line + 1,
                    ") has no $End",
                    open_section,
                    " before the end of the file at line ",
                    lines.size(),
                    ".");
      for (const char *required : {"MeshFormat", "Nodes", "Elements"})
        if (sections.count(required) == 0)
          throw_error("Mesh file '",
                      file_name,
                      "' is truncated or incomplete: it has no $",
                      required,
                      " section.");
      return sections;
    }


    /// Whether section $MeshFormat read by @p format is ASCII format 2.2 (true) or
    /// 4.1 (false); any other is an error.
    bool
    read_format_is_v2(SectionReader &format)
    {
      const std::string version_text = format.token("the format version");
      const double      version      = std::strtod(version_text.c_str(), nullptr);
      const std::size_t file_type    = format.integer("the file type");
      const bool        v2           = version >= 2 && version < 3;
      const bool        v41          = version >= 4.1 && version < 5;
      if (!v2 && !v41)
        format.fail("gmsh format version '",
                    version_text,
                    "' is not supported (Lacerta reads ASCII formats 2.2 and 4.1)");
      if (file_type != 0)
        format.fail("this is a binary gmsh file; save it as ASCII");
      return v2;
    }


    /// Reads the counts that open a format-4.1 section of @p kind ("node" or
    /// "element") blocks; returns the number of blocks.
    std::size_t
    read_block_count(SectionReader &in, const std::string &kind)
    {
      const std::size_t n_blocks =
        in.integer(("the number of " + kind + " blocks").c_str());
      in.integer(("the number of " + kind + "s").c_str());
      in.integer(("the smallest " + kind + " tag").c_str());
      in.integer(("the largest " + kind + " tag").c_str());
      return n_blocks;
    }


    /// Skips the entity dimension and tag that open a format-4.1 block.
    void
    skip_entity(SectionReader &in)
    {
      in.integer("the entity dimension");
      in.integer("the entity tag");
    }


    /// The nodes of a gmsh file: their coordinates, and their tags both ways.
    struct Nodes
    {
      std::unordered_map<std::size_t, unsigned int> index;
      std::vector<Point3>                           coordinates;
      std::vector<std::size_t>                      tag;
    };


    /// Section $Nodes read by @p nodes (format 2.2 if @p v2, else 4.1): every node
    /// defined once, at finite coordinates.
    Nodes
    read_nodes(SectionReader &nodes, const bool v2)
    {
      Nodes      result;
      const auto add_node = [&](const std::size_t tag, const Point3 &x)
      {
        for (const double xi : x)
          if (!std::isfinite(xi))
            nodes.fail("node ",
                       tag,
                       " has a coordinate that is not a finite number (",
                       x[0],
                       ", ",
                       x[1],
                       ", ",
                       x[2],
                       ")");
        if (!result.index.emplace(tag, result.coordinates.size()).second)
          nodes.fail("node ", tag, " is defined twice");
        result.coordinates.push_back(x);
        result.tag.push_back(tag);
      };
      if (v2)
      {
        const std::size_t n = nodes.integer("the number of nodes");
        for (std::size_t i = 0; i < n; ++i)
        {
          const std::size_t tag = nodes.integer("a node tag");
          Point3            x;
          for (double &xi : x)
            xi = nodes.number("the node coordinate");
          add_node(tag, x);
        }
      }
      else
      {
        const std::size_t n_blocks = read_block_count(nodes, "node");
        for (std::size_t b = 0; b < n_blocks; ++b)
        {
          skip_entity(nodes);
          const std::size_t        parametric = nodes.integer("the parametric flag");
          const std::size_t        n = nodes.integer("the number of nodes in the block");
          std::vector<std::size_t> tags(n);
          for (std::size_t &tag : tags)
            tag = nodes.integer("a node tag");
          for (const std::size_t tag : tags)
          {
            Point3 x;
            for (double &xi : x)
              xi = nodes.number("the node coordinate");
            if (parametric != 0)
              nodes.fail("node ", tag, " has parametric coordinates; save without them");
            add_node(tag, x);
          }
        }
      }
      nodes.expect_end("the last node");
      return result;
    }


    /// Section $Elements read by @p element_reader (format 2.2 if @p v2, else 4.1),
    /// with the line each element starts on.
    std::vector<Element>
    read_elements(SectionReader &element_reader, const bool v2)
    {
      std::vector<Element> elements;
      if (v2)
      {
        const std::size_t n = element_reader.integer("the number of elements");
        for (std::size_t i = 0; i < n; ++i)
        {
          const std::size_t tag    = element_reader.integer("an element tag");
          const std::size_t type   = element_reader.integer("the element type");
          const std::size_t n_tags = element_reader.integer("the number of element tags");
          for (std::size_t t = 0; t < n_tags; ++t)
            element_reader.integer("an element tag (physical, elementary, partition)");
          elements.push_back(read_element(element_reader, tag, type));
        }
      }
      else
      {
        const std::size_t n_blocks = read_block_count(element_reader, "element");
        for (std::size_t b = 0; b < n_blocks; ++b)
        {
          skip_entity(element_reader);
          const std::size_t type = element_reader.integer("the element type");
          const std::size_t n =
            element_reader.integer("the number of elements in the block");
          for (std::size_t i = 0; i < n; ++i)
          {
            const std::size_t tag = element_reader.integer("an element tag");
            elements.push_back(read_element(element_reader, tag, type));
          }
        }
      }
      element_reader.expect_end("the last element");
      return elements;
    }


    /// The faces of the tetrahedra and the triangles of a gmsh file, as sorted node
    /// index triples.
    struct Faces
    {
      /// Every tetrahedron's four faces, sorted (a sorted vector: a map costs more
      /// than the rest of the check on large meshes).
      std::vector<std::array<unsigned int, 3>> of_tets;
      /// The triangles, each with its element.
      std::vector<std::pair<std::array<unsigned int, 3>, const Element *>> triangles;
    };


    /// Checks every element of the file @p file_name: a known kind, defined nodes,
    /// tetrahedra and triangles not degenerate, at least one tetrahedron. Returns their
    /// faces.
    Faces
    check_elements(const std::string          &file_name,
                   const std::vector<Element> &elements,
                   const Nodes                &nodes)
    {
      Faces       faces;
      std::size_t n_tets = 0;
      for (const Element &element : elements)
      {
        const auto fail = [&](const auto &...pieces)
        {
          throw_error("Mesh file '",
                      file_name,
                      "', line ",
                      element.line,
                      ": element ",
                      element.tag,
                      " (",
                      element_types[element.type].name,
                      ") ",
                      pieces...,
                      ".");
        };
        std::vector<unsigned int> ids;
        for (const std::size_t node : element.nodes)
        {
          const auto found = nodes.index.find(node);
          if (found == nodes.index.end())
            fail("refers to node ", node, ", which $Nodes does not define");
          ids.push_back(found->second);
        }
        switch (element.type)
        {
          case gmsh_point:
          case gmsh_line:
            break;
          case gmsh_triangle:
          {
            std::array<unsigned int, 3> key = {ids[0], ids[1], ids[2]};
            std::sort(key.begin(), key.end());
            if (key[0] == key[1] || key[1] == key[2])
              fail("is degenerate: it repeats node ",
                   element.nodes[key[0] == key[1] ? 0 : 2]);
            faces.triangles.emplace_back(key, &element);
            break;
          }
          case gmsh_tetrahedron:
          {
            for (unsigned int i = 0; i < 4; ++i)
              for (unsigned int j = 0; j < i; ++j)
                if (ids[i] == ids[j])
                  fail("is degenerate: it repeats node ", element.nodes[i]);
            const Tet         cell    = {ids[0], ids[1], ids[2], ids[3]};
            const std::string problem = degeneracy(nodes.coordinates, cell);
            if (!problem.empty())
              fail("is degenerate: ", problem);
            for (const auto &f : TetMesh::face_vertices)
            {
              std::array<unsigned int, 3> key = {cell[f[0]], cell[f[1]], cell[f[2]]};
              std::sort(key.begin(), key.end());
              faces.of_tets.push_back(key);
            }
            ++n_tets;
            break;
          }
          default:
            fail("is not a tetrahedron; Lacerta needs a mesh of tetrahedra (triangles, "
                 "lines and points may describe its boundary)");
        }
      }
      if (n_tets == 0)
        throw_error("Mesh file '", file_name, "' has no tetrahedra.");
      std::sort(faces.of_tets.begin(), faces.of_tets.end());
      return faces;
    }


    /// Checks that no face of the file @p file_name's tetrahedra is shared by more
    /// than two, and that every triangle is a boundary face of them.
    void
    check_faces(const std::string &file_name, const Faces &faces, const Nodes &nodes)
    {
      const auto &of_tets = faces.of_tets;
      for (std::size_t i = 0, j = 0; i < of_tets.size(); i = j)
      {
        while (j < of_tets.size() && of_tets[j] == of_tets[i])
          ++j;
        const auto &key = of_tets[i];
        if (j - i > 2)
          throw_error("Mesh file '",
                      file_name,
                      "' is not a manifold: the face with nodes ",
                      nodes.tag[key[0]],
                      ", ",
                      nodes.tag[key[1]],
                      ", ",
                      nodes.tag[key[2]],
                      " is shared by ",
                      j - i,
                      " tetrahedra.");
      }
      // A triangle gives a boundary id; one that is no boundary face of a tetrahedron
      // cannot carry one.
      for (const auto &[key, element] : faces.triangles)
      {
        const auto range = std::equal_range(of_tets.begin(), of_tets.end(), key);
        if (range.second - range.first != 1)
          throw_error("Mesh file '",
                      file_name,
                      "', line ",
                      element->line,
                      ": element ",
                      element->tag,
                      " (triangle) is not a boundary face of the tetrahedra",
                      range.first == range.second ? "" : " (it lies inside the mesh)",
                      "; surface elements only give boundary ids.");
      }
    }
  } // namespace


  void
  check_gmsh_file(const std::string &file_name)
  {
    const std::vector<std::string> lines    = read_lines(file_name);
    const Sections                 sections = find_sections(file_name, lines);
    const auto                     reader   = [&](const std::string &name)
    {
      const auto &[begin, end] = sections.at(name);
      return SectionReader(file_name, lines, name, begin, end);
    };
    SectionReader format         = reader("MeshFormat");
    const bool    v2             = read_format_is_v2(format);
    SectionReader node_reader    = reader("Nodes");
    const Nodes   nodes          = read_nodes(node_reader, v2);
    SectionReader element_reader = reader("Elements");
    const auto    elements       = read_elements(element_reader, v2);
    const Faces   faces          = check_elements(file_name, elements, nodes);
    check_faces(file_name, faces, nodes);
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
      throw_error(
        "Mesh file '", file_name, "' could not be read by deal.II: ", info.str());
    }
    return tet_mesh_from_triangulation(triangulation, file_name);
  }
} // namespace lacerta::mesh
