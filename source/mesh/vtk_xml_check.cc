#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/vtk_xml_check.h>

#include <vtkNew.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLDataParser.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <vector>

namespace lacerta::mesh
{
  namespace
  {
    /// The values an ASCII array of a VTK type may hold.
    struct ValueRange
    {
      bool        integer = false;
      long double lowest = 0, highest = 0;
    };

    /// The range of the VTK XML type name @p type, or nothing for a type that is not
    /// numeric (a String array, whose content VTK reads its own way).
    std::optional<ValueRange>
    value_range(const std::string &type)
    {
      if (type == "Float32" || type == "Float64")
        return ValueRange{false, 0, 0};
      struct Named
      {
        const char *name;
        long double lowest, highest;
      };
      static const Named integers[] = {{"Int8", -128.0L, 127.0L},
                                       {"UInt8", 0, 255.0L},
                                       {"Int16", -32768.0L, 32767.0L},
                                       {"UInt16", 0, 65535.0L},
                                       {"Int32", -2147483648.0L, 2147483647.0L},
                                       {"UInt32", 0, 4294967295.0L},
                                       {"Int64",
                                        -9223372036854775808.0L,
                                        9223372036854775807.0L},
                                       {"UInt64", 0, 18446744073709551615.0L}};
      for (const Named &named : integers)
        if (type == named.name)
          return ValueRange{true, named.lowest, named.highest};
      return std::nullopt;
    }


    /**
     * One pass over the parsed XML tree: each Piece, then its sections and arrays.
     * `where` names the Piece (and the array) in the messages.
     */
    class XmlCheck
    {
      /// What a tuple and one of its values are called in the messages.
      struct Words
      {
        const char *tuple, *value;
      };

    public:
      explicit XmlCheck(const std::string &file_name)
          : file_name(file_name)
      {
      }

      void
      run()
      {
        std::ifstream in(file_name, std::ios::binary);
        text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        vtkNew<vtkXMLDataParser> parser;
        parser->SetFileName(file_name.c_str());
        if (!parser->Parse() || parser->GetRootElement() == nullptr)
          throw_error("Mesh file '",
                      file_name,
                      "' could not be read (truncated or malformed?): it is not "
                      "well-formed XML.");
        vtkXMLDataElement *grid =
          parser->GetRootElement()->FindNestedElementWithName("UnstructuredGrid");
        if (grid == nullptr)
          throw_error("Mesh file '", file_name, "' has no UnstructuredGrid element.");
        unsigned int piece_index = 0;
        for (int i = 0; i < grid->GetNumberOfNestedElements(); ++i)
          if (std::strcmp(grid->GetNestedElement(i)->GetName(), "Piece") == 0)
            check_piece(grid->GetNestedElement(i), piece_index++);
      }

    private:
      [[noreturn]] void
      fail(const std::string &where, const std::string &what) const
      {
        throw_error("Mesh file '", file_name, "', ", where, ": ", what, ".");
      }

      /// The attribute @p name of @p element as a count.
      std::size_t
      count_attribute(vtkXMLDataElement *element,
                      const char        *name,
                      const std::string &where) const
      {
        const char *text = element->GetAttribute(name);
        if (text == nullptr)
          fail(where, std::string("no ") + name + " is given");
        char                    *rest  = nullptr;
        const unsigned long long value = std::strtoull(text, &rest, 10);
        if (*text == '\0' || *text == '-' || *rest != '\0' || value > (1ull << 40))
          fail(where,
               std::string(name) + " must be a non-negative integer, not '" + text + "'");
        return static_cast<std::size_t>(value);
      }

      /**
       * Checks the array @p array that must hold @p tuples tuples (none: any number of
       * whole tuples), and returns its values if it is an ASCII numeric array.
       */
      std::vector<long double>
      check_array(vtkXMLDataElement         *array,
                  std::optional<std::size_t> tuples,
                  const std::string         &where,
                  const Words               &words = {"tuple", "value"}) const
      {
        const char *type   = array->GetAttribute("type");
        const char *format = array->GetAttribute("format");
        if (type == nullptr || format == nullptr)
          fail(where, "a DataArray must give its type and its format");
        const std::size_t components =
          array->GetAttribute("NumberOfComponents")
            ? count_attribute(array, "NumberOfComponents", where)
            : 1;
        if (components == 0)
          fail(where, "NumberOfComponents must be positive");
        if (std::strcmp(format, "ascii") != 0)
        {
          if (std::strcmp(format, "binary") != 0 && std::strcmp(format, "appended") != 0)
            fail(where,
                 std::string("the format must be ascii, binary or appended, not '")
                   + format + "'");
          return {};
        }
        const std::optional<ValueRange> range = value_range(type);
        if (!range)
          return {};

        std::vector<long double> values;
        std::istringstream       tokens(inline_text(array));
        for (std::string token; tokens >> token;)
          values.push_back(
            parse(token, *range, values.size() / components, where, words));
        const std::size_t expected = tuples ? *tuples * components : values.size();
        if (values.size() != expected || values.size() % components != 0)
          fail(where,
               "it holds " + std::to_string(values.size()) + " values, not "
                 + (tuples ? std::to_string(expected)
                           : "a multiple of " + std::to_string(components)));
        return values;
      }

      /**
       * The inline data of @p element as VTK's reader finds it: from the first '>'
       * after the element's start to the next tag. (VTK's parser does not keep the
       * text; it seeks it later, and does not skip a '>' inside an attribute's quotes,
       * so neither does this.)
       */
      std::string
      inline_text(vtkXMLDataElement *element) const
      {
        const std::size_t start = text.find('>', element->GetXMLByteIndex());
        if (start == std::string::npos || start == 0 || text[start - 1] == '/')
          return "";
        const std::size_t end = text.find('<', start + 1);
        return text.substr(start + 1,
                           (end == std::string::npos ? text.size() : end) - start - 1);
      }

      /// The number @p token of an array of @p range (tuple @p tuple), or an Error.
      long double
      parse(const std::string &token,
            const ValueRange  &range,
            const std::size_t  tuple,
            const std::string &where,
            const Words       &words) const
      {
        // Only the characters a C++ stream reads as a number: VTK reads ASCII arrays
        // with operator>>, and strtold alone would also take "nan", "inf" and hex.
        const bool plain =
          token.find_first_not_of(range.integer ? "+-0123456789" : "+-.0123456789eE")
          == std::string::npos;
        char *rest              = nullptr;
        errno                   = 0;
        const long double value = std::strtold(token.c_str(), &rest);
        if (!plain || *rest != '\0' || errno == ERANGE || !std::isfinite(value)
            || (range.integer && (value < range.lowest || value > range.highest)))
          fail(where,
               std::string(words.tuple) + " " + std::to_string(tuple) + " has a "
                 + words.value
                 + (range.integer ? " that is not an integer its type holds ('"
                                  : " that is not a finite number ('")
                 + token + "')");
        return value;
      }

      /// The nested DataArray of @p section whose Name is @p name (nullptr: the first).
      static vtkXMLDataElement *
      find_array(vtkXMLDataElement *section, const char *name)
      {
        for (int i = 0; i < section->GetNumberOfNestedElements(); ++i)
        {
          vtkXMLDataElement *array = section->GetNestedElement(i);
          if (std::strcmp(array->GetName(), "DataArray") != 0)
            continue;
          const char *array_name = array->GetAttribute("Name");
          if (name == nullptr
              || (array_name != nullptr && std::strcmp(array_name, name) == 0))
            return array;
        }
        return nullptr;
      }

      void
      check_piece(vtkXMLDataElement *piece, const unsigned int index)
      {
        const std::string where    = "Piece " + std::to_string(index);
        const std::size_t n_points = count_attribute(piece, "NumberOfPoints", where);
        const std::size_t n_cells  = count_attribute(piece, "NumberOfCells", where);

        vtkXMLDataElement *points = piece->FindNestedElementWithName("Points");
        vtkXMLDataElement *xyz    = points ? find_array(points, nullptr) : nullptr;
        if (n_points > 0 && xyz == nullptr)
          fail(where, "it has no Points array");
        if (xyz != nullptr)
        {
          if (const char *c = xyz->GetAttribute("NumberOfComponents");
              c == nullptr || std::strcmp(c, "3") != 0)
            fail(where + ", Points", "NumberOfComponents must be 3");
          if (const char *type = xyz->GetAttribute("type");
              type == nullptr || !value_range(type))
            fail(where + ", Points", "the coordinates must be a numeric array");
          check_array(xyz, n_points, where + ", Points", {"point", "coordinate"});
        }

        if (n_cells > 0)
          check_cells(piece->FindNestedElementWithName("Cells"),
                      n_points,
                      n_cells,
                      where);
        check_data(piece->FindNestedElementWithName("PointData"),
                   n_points,
                   where + ", PointData",
                   "point");
        check_data(piece->FindNestedElementWithName("CellData"),
                   n_cells,
                   where + ", CellData",
                   "cell");
      }

      void
      check_cells(vtkXMLDataElement *cells,
                  const std::size_t  n_points,
                  const std::size_t  n_cells,
                  const std::string &where) const
      {
        vtkXMLDataElement *connectivity =
          cells ? find_array(cells, "connectivity") : nullptr;
        vtkXMLDataElement *offsets = cells ? find_array(cells, "offsets") : nullptr;
        vtkXMLDataElement *types   = cells ? find_array(cells, "types") : nullptr;
        if (connectivity == nullptr || offsets == nullptr || types == nullptr)
          fail(where,
               "its Cells must have the DataArrays connectivity, offsets and types");
        check_array(types, n_cells, where + ", Cells/types", {"cell", "type"});

        // One offset per cell (the end of its vertex list), or one more that starts
        // at 0 (the layout of VTK files from version 2).
        std::vector<long double> ends =
          check_array(offsets, std::nullopt, where + ", Cells/offsets");
        if (ends.size() == n_cells + 1 && ends[0] == 0)
          ends.erase(ends.begin());
        if (offsets->GetAttribute("format") == std::string("ascii")
            && ends.size() != n_cells)
          fail(where + ", Cells/offsets",
               "it holds " + std::to_string(ends.size()) + " values, not "
                 + std::to_string(n_cells));
        for (std::size_t c = 0; c < ends.size(); ++c)
          if (ends[c] < (c > 0 ? ends[c - 1] : 0))
            fail(where + ", Cells/offsets",
                 "cell " + std::to_string(c) + " ends before it starts");

        const std::vector<long double> ids =
          check_array(connectivity,
                      ends.empty() ? std::nullopt
                                   : std::optional<std::size_t>(
                                     static_cast<std::size_t>(ends.back())),
                      where + ", Cells/connectivity");
        for (std::size_t i = 0; i < ids.size(); ++i)
          if (ids[i] < 0 || ids[i] >= n_points)
            fail(where + ", Cells/connectivity",
                 "entry " + std::to_string(i) + " names point "
                   + std::to_string(static_cast<long long>(ids[i]))
                   + ", which the Piece does not have");
      }

      void
      check_data(vtkXMLDataElement *section,
                 const std::size_t  tuples,
                 const std::string &where,
                 const char        *tuple_word) const
      {
        if (section == nullptr)
          return;
        for (int i = 0; i < section->GetNumberOfNestedElements(); ++i)
        {
          vtkXMLDataElement *array = section->GetNestedElement(i);
          if (std::strcmp(array->GetName(), "DataArray") != 0)
            continue;
          const char *name = array->GetAttribute("Name");
          check_array(array,
                      tuples,
                      where + "/" + (name ? name : "array " + std::to_string(i)),
                      {tuple_word, "value"});
        }
      }

      const std::string file_name;
      /// The whole file.
      std::string text;
    };
  } // namespace


  void
  check_vtk_xml_file(const std::string &file_name)
  {
    XmlCheck(file_name).run();
  }
} // namespace lacerta::mesh
