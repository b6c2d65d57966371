#include <lacerta/base/exceptions.h>
#include <lacerta/base/parsed_function.h>

#include <deal.II/base/exceptions.h>

#include <cctype>

namespace lacerta
{
  std::string
  exception_message(const dealii::ExceptionBase &exception)
  {
    std::ostringstream info;
    exception.print_info(info);
    std::string text = info.str();
    for (char &c : text)
      if (c == '\n')
        c = ' ';
    const auto first = text.find_first_not_of(' ');
    const auto last  = text.find_last_not_of(' ');
    return first == std::string::npos ? std::string()
                                      : text.substr(first, last - first + 1);
  }


  bool
  uses_position(const std::string &expression)
  {
    // The identifiers of the expression (a letter or '_', then letters, digits or
    // '_'); one that follows a digit or '.' is a number's exponent (1e-3).
    const auto starts = [](const char c)
    { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; };
    const auto in_number = [](const char c)
    { return std::isdigit(static_cast<unsigned char>(c)) || c == '.'; };
    for (std::size_t i = 0; i < expression.size();)
    {
      if (!starts(expression[i]))
      {
        ++i;
        continue;
      }
      const std::size_t first = i;
      while (i < expression.size()
             && (starts(expression[i])
                 || std::isdigit(static_cast<unsigned char>(expression[i]))))
        ++i;
      const std::string name = expression.substr(first, i - first);
      if ((first == 0 || !in_number(expression[first - 1]))
          && (name == "x" || name == "y" || name == "z"))
        return true;
    }
    return false;
  }


  std::unique_ptr<dealii::FunctionParser<3>>
  parse_function(const std::string                   &entry,
                 const std::string                   &expression,
                 const unsigned int                   n_components,
                 const bool                           time_dependent,
                 const std::map<std::string, double> &constants)
  {
    auto function = std::make_unique<dealii::FunctionParser<3>>(n_components);
    try
    {
      function->initialize(time_dependent ? "x,y,z,t" : "x,y,z",
                           expression,
                           constants,
                           time_dependent);
      for (unsigned int c = 0; c < n_components; ++c)
        function->value(dealii::Point<3>(), c);
    }
    catch (const dealii::ExceptionBase &e)
    {
      throw_error(entry,
                  ": cannot evaluate the expression '",
                  expression,
                  "'",
                  n_components > 1 ? " (" + std::to_string(n_components)
                                       + " components separated by ';' are needed)"
                                   : std::string(),
                  ": ",
                  exception_message(e));
    }
    return function;
  }
} // namespace lacerta
