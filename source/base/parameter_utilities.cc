#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/utilities.h>

namespace lacerta
{
  void
  declare_point_entry(dealii::ParameterHandler &prm,
                      const std::string        &name,
                      const std::string        &default_value,
                      const std::string        &documentation)
  {
    prm.declare_entry(name,
                      default_value,
                      dealii::Patterns::List(dealii::Patterns::Double(), 3, 3, ","),
                      documentation + " Three numbers separated by commas.");
  }


  std::array<double, 3>
  get_point(const dealii::ParameterHandler &prm, const std::string &name)
  {
    const std::vector<double> values = dealii::Utilities::string_to_double(
      dealii::Utilities::split_string_list(prm.get(name), ','));
    return {values[0], values[1], values[2]};
  }


  std::unique_ptr<dealii::FunctionParser<3>>
  parse_vector_expression(const std::string &section,
                          const std::string &entry,
                          const std::string &expression)
  {
    auto function = std::make_unique<dealii::FunctionParser<3>>(3);
    try
    {
      function->initialize("x,y,z,t", expression, {}, true);
      function->value(dealii::Point<3>(), 0);
    }
    catch (const dealii::ExceptionBase &e)
    {
      std::ostringstream info;
      e.print_info(info);
      throw_error(section,
                  ": cannot use '",
                  entry,
                  "' = '",
                  expression,
                  "' (three expressions separated by ';' are needed): ",
                  info.str());
    }
    return function;
  }
} // namespace lacerta
