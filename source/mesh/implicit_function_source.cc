// Mesh source `implicit function`: an organ-like shape {x : f(x) < 0} meshed by CGAL.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/function_parser.h>
#include <deal.II/cgal/triangulation.h>
#include <deal.II/cgal/utilities.h>
#include <deal.II/grid/tria.h>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/make_mesh_3.h>

namespace lacerta::mesh
{
  namespace
  {
    /**
     * The volume where an implicit function is negative, meshed with tetrahedra by
     * CGAL's Mesh_3 (as deal.II's GridGenerator::implicit_function does, but with the
     * mesh optimisers run to completion; see mesh_with_cgal()).
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

        return tet_mesh_from_triangulation(mesh_with_cgal(*function, inside),
                                           "implicit function");
      }

    private:
      /**
       * CGAL's Mesh_3 on {f < 0}. The sliver perturbation and the exudation that follow
       * the refinement are given no time limit: by default CGAL stops them after as
       * much wall time as the refinement took, so the mesh depended on the machine's
       * load and differed from run to run at fine sizes. Run to completion, they make
       * the mesh a function of the parameters alone.
       */
      dealii::Triangulation<3>
      mesh_with_cgal(const dealii::Function<3> &function,
                     const dealii::Point<3>    &inside) const
      {
        using Kernel   = CGAL::Exact_predicates_inexact_constructions_kernel;
        using Domain   = CGAL::Labeled_mesh_domain_3<Kernel>;
        using Tr       = CGAL::Mesh_triangulation_3<Domain,
                                              CGAL::Default,
                                              dealii::CGALWrappers::ConcurrencyTag>::type;
        using C3t3     = CGAL::Mesh_complex_3_in_triangulation_3<Tr, int, int>;
        using Criteria = CGAL::Mesh_criteria_3<Tr>;
        namespace p    = CGAL::parameters;

        const auto f = [&function](const Kernel::Point_3 &x)
        { return Kernel::FT(function.value(dealii::Point<3>(x.x(), x.y(), x.z()))); };
        const Domain domain = Domain::create_implicit_mesh_domain(
          f,
          Kernel::Sphere_3(Kernel::Point_3(inside[0], inside[1], inside[2]),
                           outer_ball_radius * outer_ball_radius));
        const Criteria           criteria(p::facet_size             = facet_size,
                                p::facet_angle            = 0.,
                                p::facet_distance         = facet_distance,
                                p::cell_radius_edge_ratio = cell_radius_edge_ratio,
                                p::cell_size              = cell_size);
        const C3t3               complex = CGAL::make_mesh_3<C3t3>(domain,
                                                     criteria,
                                                     p::perturb(p::time_limit = 0),
                                                     p::exude(p::time_limit = 0));
        dealii::Triangulation<3> triangulation;
        dealii::CGALWrappers::cgal_triangulation_to_dealii_triangulation(complex,
                                                                         triangulation);
        return triangulation;
      }

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
