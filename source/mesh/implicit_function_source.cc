// Mesh source `implicit function`: an organ-like shape {x : f(x) < 0} meshed by CGAL.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/function_parser.h>
#include <deal.II/cgal/additional_data.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

namespace lacerta::mesh
{
  namespace
  {
    /// The parser's own explanation from a deal.II exception, without the code location.
    /**
     * The volume where an implicit function is negative, meshed with tetrahedra by
     * CGAL's Mesh_3 through GridGenerator::implicit_function.
     */
    class ImplicitFunctionSource : public MeshSource
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Function expression",
          "(x/0.05)^2 + (y/0.03)^2 + (z/0.025)^2 - 1 + 0.6*exp(-(x/0.02)^2 - "
          "((y-0.03)/0.02)^2)",
          dealii::Patterns::Anything(),
          "f(x,y,z) in deal.II's FunctionParser syntax; the object is where "
          "f < 0. The default is a kidney-like ellipsoid with a dent (the "
          "hilum) on the side y > 0.");
        declare_point_entry(prm,
                            "Interior point",
                            "0, -0.01, 0",
                            "A point where f < 0, from which CGAL starts [m].");
        prm.declare_entry("Outer ball radius",
                          "0.1",
                          dealii::Patterns::Double(1e-9),
                          "Radius of a ball around the interior point that contains the "
                          "whole object [m].");
        prm.declare_entry("Cell size",
                          "0.005",
                          dealii::Patterns::Double(1e-9),
                          "Upper bound of the circumradius of the tetrahedra [m].");
        prm.declare_entry(
          "Facet size",
          "0.005",
          dealii::Patterns::Double(1e-9),
          "Upper bound of the circumradius of the surface triangles [m].");
        prm.declare_entry(
          "Facet distance",
          "0.0008",
          dealii::Patterns::Double(1e-12),
          "Upper bound of the distance between a surface triangle and the "
          "true surface [m].");
        prm.declare_entry("Cell radius edge ratio",
                          "2",
                          dealii::Patterns::Double(1.0, 10.0),
                          "Upper bound of circumradius over shortest edge of the "
                          "tetrahedra (lower is better shaped, CGAL needs >= 2 to "
                          "guarantee termination).");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        expression             = prm.get("Function expression");
        interior_point         = get_point(prm, "Interior point");
        outer_ball_radius      = prm.get_double("Outer ball radius");
        cell_size              = prm.get_double("Cell size");
        facet_size             = prm.get_double("Facet size");
        facet_distance         = prm.get_double("Facet distance");
        cell_radius_edge_ratio = prm.get_double("Cell radius edge ratio");
      }

      TetMesh
      create_mesh() const override
      {
        const dealii::Point<3> inside(interior_point[0],
                                      interior_point[1],
                                      interior_point[2]);
        const auto function = parse_function("Mesh/Implicit function/Function expression",
                                             expression,
                                             1,
                                             false);
        const double f_inside = function->value(inside);
        if (!(f_inside < 0))
          throw_error(
            "Mesh/Implicit function: f is not negative at 'Interior point' (f = ",
            f_inside,
            ").");

        dealii::CGALWrappers::AdditionalData<3> data;
        data.cell_size              = cell_size;
        data.facet_size             = facet_size;
        data.facet_distance         = facet_distance;
        data.cell_radius_edge_ratio = cell_radius_edge_ratio;
        dealii::Triangulation<3> triangulation;
        dealii::GridGenerator::implicit_function(
          triangulation, *function, data, inside, outer_ball_radius);
        return tet_mesh_from_triangulation(triangulation, "implicit function");
      }

    private:
      std::string           expression;
      std::array<double, 3> interior_point{};
      double                outer_ball_radius = 0, cell_size = 0, facet_size = 0;
      double                facet_distance = 0, cell_radius_edge_ratio = 0;
    };
  } // namespace

  LACERTA_REGISTER_MESH_SOURCE(
    ImplicitFunctionSource,
    "implicit function",
    "An organ-like shape ('subsection Implicit function'), the "
    "set where an expression f(x,y,z) is negative, meshed with "
    "tetrahedra by CGAL.");
} // namespace lacerta::mesh
