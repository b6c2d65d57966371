/**
 * @file
 * Expressions from the parameter file as deal.II FunctionParser objects.
 */
#pragma once

#include <deal.II/base/function_parser.h>

#include <map>
#include <memory>
#include <string>

namespace dealii
{
  class ExceptionBase;
}

namespace lacerta
{
  /**
   * Parses @p expression (components separated by ';') as a function of x, y, z (and t
   * if @p time_dependent) with @p n_components components, and evaluates it once at
   * the origin: deal.II 9.4 parses on the first evaluation, so a syntax error would
   * otherwise surface in the middle of a run. An error is a lacerta::Error that names
   * @p entry (e.g. "Material/Density") and the expression.
   */
  std::unique_ptr<dealii::FunctionParser<3>>
  parse_function(const std::string                   &entry,
                 const std::string                   &expression,
                 unsigned int                         n_components,
                 bool                                 time_dependent,
                 const std::map<std::string, double> &constants = {});

  /**
   * Whether @p expression (as given to parse_function()) names x, y or z: if not, its
   * value is the same at every point and may be evaluated once per time.
   */
  bool
  uses_position(const std::string &expression);

  /**
   * The explanation a deal.II exception carries (without file, line and condition), on
   * one line.
   */
  std::string
  exception_message(const dealii::ExceptionBase &exception);
} // namespace lacerta
