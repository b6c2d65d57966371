/**
 * @file
 * The material of the object: density and Young's modulus fields, damping.
 */
#pragma once

#include <deal.II/base/function.h>
#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <memory>

namespace lacerta::scene
{
  /**
   * Density σ(x) and Young's modulus E(x) as FunctionParser expressions of x, y, z
   * (`subsection Material`; a density or modulus that is a plain number is a
   * ConstantFunction), the Poisson ratio for the FEM reference, and damping.
   */
  class Material
  {
  public:
    /// Declares `subsection Material`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads `subsection Material`; an expression that does not parse is an Error.
    void
    parse_parameters(dealii::ParameterHandler &prm);

    /// Density σ(x) in kg/m³.
    const dealii::Function<3> &
    density() const
    {
      return *density_function;
    }

    /// Young's modulus E(x) in Pa.
    const dealii::Function<3> &
    youngs_modulus() const
    {
      return *youngs_function;
    }

    /**
     * Maximum elongation ε_max(x) of a spring, as a strain (|x_i - x_j| - L) / L,
     * evaluated at the spring's rest midpoint (Section 7; read only by scenes that
     * enable `Laceration`).
     */
    const dealii::Function<3> &
    maximum_elongation() const
    {
      return *elongation_function;
    }

    /// Poisson ratio (used by the FEM reference; springs behave as ν = 1/4).
    double poisson_ratio = 0.25;
    /// Whether spring stiffnesses are fitted to linear elasticity (Lloyd et al. 2007)
    /// instead of the paper's k = E V / |e|².
    bool fitted_springs = false;
    /// Viscous damping per particle (1/s).
    double mass_damping = 0;
    /// Damping along springs (s).
    double spring_damping = 0;

  private:
    /// ConstantFunctions when the expressions are plain numbers, else their parsers.
    std::unique_ptr<dealii::Function<3>>       density_function;
    std::unique_ptr<dealii::Function<3>>       youngs_function;
    std::unique_ptr<dealii::FunctionParser<3>> elongation_function;
  };
} // namespace lacerta::scene
