#include <lacerta/base/exceptions.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/scene/material.h>

namespace lacerta::scene
{
  namespace
  {
    /// Parses `name=value, name=value` into constants for the expressions.
    std::map<std::string, double>
    parse_constants(const std::string &constants)
    {
      std::map<std::string, double> values;
      for (const auto &pair : dealii::Utilities::split_string_list(constants, ','))
      {
        const auto parts = dealii::Utilities::split_string_list(pair, '=');
        if (parts.size() != 2)
          throw_error("Material/Function constants: '",
                      pair,
                      "' is not of the form name=value.");
        values[parts[0]] = dealii::Utilities::string_to_double(parts[1]);
      }
      return values;
    }


    /**
     * The scalar field @p expression of entry @p entry. A plain number (digits, sign,
     * point, exponent: no variable can appear) becomes a ConstantFunction, which the
     * cut update recognises (physics::constant_value()) to compute masses and
     * stiffnesses without a Function call per point. Its value is the parser's own,
     * so no mass or stiffness changes.
     */
    std::unique_ptr<dealii::Function<3>>
    parse_field(const std::string                   &entry,
                const std::string                   &expression,
                const std::map<std::string, double> &constants)
    {
      auto parser = parse_function(entry, expression, 1, false, constants);
      if (expression.find_first_not_of("0123456789.eE+- \t") == std::string::npos)
        return std::make_unique<dealii::Functions::ConstantFunction<3>>(
          parser->value(dealii::Point<3>()));
      return parser;
    }
  } // namespace


  void
  Material::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Material");
    prm.declare_entry("Density",
                      "1000",
                      dealii::Patterns::Anything(),
                      "Mass density σ(x, y, z) [kg/m^3], an expression in deal.II's "
                      "FunctionParser syntax. Particle masses integrate it exactly for "
                      "polynomials up to degree 2 (Section 3.1).");
    prm.declare_entry("Youngs modulus",
                      "1e6",
                      dealii::Patterns::Anything(),
                      "Young's modulus E(x, y, z) [Pa], an expression; evaluated at the "
                      "centroid of every tetrahedron for the spring stiffness "
                      "k_e = sum E V / |e|^2 (Section 3.2).");
    prm.declare_entry(
      "Maximum elongation",
      "0.3",
      dealii::Patterns::Anything(),
      "Largest strain (|x_i - x_j| - L) / L a spring bears before the tissue may tear "
      "(Section 7), an expression of x, y, z evaluated at the spring's rest midpoint; "
      "its values must lie in [0.001, 100]. Used only if 'Laceration/Enabled' is true.");
    prm.declare_entry(
      "Poisson ratio",
      "0.25",
      dealii::Patterns::Double(0.0, 0.499),
      "Poisson ratio of the FEM reference, of the fitted springs and of the force "
      "models 'volume springs' and 'corotated fem'. The paper's springs contract "
      "with their own effective ratio whatever is asked here (doc/accuracy.md).");
    prm.declare_entry(
      "Spring stiffness",
      "paper",
      dealii::Patterns::Selection("paper|fitted"),
      "How springs get their stiffness: 'paper' sums E V / |e|^2 over the "
      "tetrahedra of an edge (Section 3.2); 'fitted' sums the stiffnesses that fit "
      "each tetrahedron's linear FEM stiffness with 'Poisson ratio' best in least "
      "squares (Lloyd, Szekely, Harders 2007; doc/accuracy.md compares both). Both cost "
      "the same per step.");
    prm.declare_entry(
      "Function constants",
      "",
      dealii::Patterns::Anything(),
      "Constants usable in the expressions, as 'name=value, name=value'.");
    prm.declare_entry("Mass damping",
                      "0",
                      dealii::Patterns::Double(0.0, 1e6),
                      "Viscous damping per particle c [1/s]: force -c m v.");
    prm.declare_entry("Spring damping",
                      "0",
                      dealii::Patterns::Double(0.0, 1.0),
                      "Damping along springs β [s]: force -β k ((v_b - v_a)·n) n, i.e. "
                      "stiffness-proportional (Rayleigh) damping.");
    prm.leave_subsection();
  }


  void
  Material::parse_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Material");
    const auto constants = parse_constants(prm.get("Function constants"));
    density_function     = parse_field("Material/Density", prm.get("Density"), constants);
    youngs_function =
      parse_field("Material/Youngs modulus", prm.get("Youngs modulus"), constants);
    elongation_function = parse_function(
      "Material/Maximum elongation", prm.get("Maximum elongation"), 1, false, constants);
    poisson_ratio  = prm.get_double("Poisson ratio");
    fitted_springs = prm.get("Spring stiffness") == "fitted";
    mass_damping   = prm.get_double("Mass damping");
    spring_damping = prm.get_double("Spring damping");
    prm.leave_subsection();
  }
} // namespace lacerta::scene
