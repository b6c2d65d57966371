/**
 * @file
 * Small helpers for entries that hold points and vectors.
 */
#pragma once

#include <deal.II/base/parameter_handler.h>

namespace dealii
{
  template <int dim>
  class FunctionParser;
}

#include <array>
#include <memory>
#include <string>

namespace lacerta
{
  /**
   * Declares an entry holding three comma-separated numbers (a point or a vector).
   */
  void
  declare_point_entry(dealii::ParameterHandler &prm,
                      const std::string        &name,
                      const std::string        &default_value,
                      const std::string        &documentation);

  /**
   * Reads an entry declared by declare_point_entry().
   */
  std::array<double, 3>
  get_point(const dealii::ParameterHandler &prm, const std::string &name);

  /**
   * Parses three expressions of x, y, z, t separated by ';' (a vector field that may
   * vary in time); a bad expression is an Error naming @p section and @p entry.
   */
  std::unique_ptr<dealii::FunctionParser<3>>
  parse_vector_expression(const std::string &section,
                          const std::string &entry,
                          const std::string &expression);
} // namespace lacerta
