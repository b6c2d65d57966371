/**
 * @file
 * Small helpers for entries that hold points and vectors.
 */
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <array>
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
} // namespace lacerta
