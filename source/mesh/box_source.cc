// Mesh source `box`: a rectangular box subdivided into tetrahedra by deal.II.

#include <lacerta/base/parameter_utilities.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mesh/triangulation_conversion.h>

#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

namespace lacerta::mesh
{
  namespace
  {
    /**
     * A box [lower, upper] cut into repetitions[0] x [1] x [2] hexahedra, each split
     * into tetrahedra by GridGenerator::subdivided_hyper_rectangle_with_simplices.
     * Boundary ids follow deal.II's convention: 0/1 at x = min/max, 2/3 for y, 4/5 for z.
     */
    class BoxSource : public MeshSource
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        declare_point_entry(prm,
                            "Lower corner",
                            "0, 0, 0",
                            "Lower corner of the box [m].");
        declare_point_entry(prm,
                            "Upper corner",
                            "0.1, 0.1, 0.02",
                            "Upper corner of the box [m].");
        prm.declare_entry(
          "Repetitions",
          "4, 4, 1",
          dealii::Patterns::List(dealii::Patterns::Integer(1, 1000), 3, 3, ","),
          "Number of hexahedra along x, y and z; each is split into "
          "five tetrahedra.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        lower = get_point(prm, "Lower corner");
        upper = get_point(prm, "Upper corner");
        for (unsigned int d = 0; d < 3; ++d)
          if (!(upper[d] > lower[d]))
            throw_error("Mesh/Box: 'Upper corner' must be above 'Lower corner' in every "
                        "coordinate (coordinate ",
                        d,
                        ": ",
                        lower[d],
                        " >= ",
                        upper[d],
                        ").");
        const auto counts = dealii::Utilities::string_to_int(
          dealii::Utilities::split_string_list(prm.get("Repetitions"), ','));
        repetitions = {static_cast<unsigned int>(counts[0]),
                       static_cast<unsigned int>(counts[1]),
                       static_cast<unsigned int>(counts[2])};
      }

      TetMesh
      create_mesh() const override
      {
        dealii::Triangulation<3> triangulation;
        dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(
          triangulation,
          std::vector<unsigned int>(repetitions.begin(), repetitions.end()),
          dealii::Point<3>(lower[0], lower[1], lower[2]),
          dealii::Point<3>(upper[0], upper[1], upper[2]));
        // deal.II 9.4 cannot colorize simplex boxes: set the ids by face position.
        for (const auto &cell : triangulation.active_cell_iterators())
          for (const unsigned int f : cell->face_indices())
            if (cell->face(f)->at_boundary())
            {
              const dealii::Point<3> c = cell->face(f)->center();
              for (unsigned int d = 0; d < 3; ++d)
              {
                const double tolerance = 1e-10 * (upper[d] - lower[d]);
                if (std::abs(c[d] - lower[d]) < tolerance)
                  cell->face(f)->set_boundary_id(2 * d);
                else if (std::abs(c[d] - upper[d]) < tolerance)
                  cell->face(f)->set_boundary_id(2 * d + 1);
              }
            }
        return tet_mesh_from_triangulation(triangulation, "box");
      }

    private:
      Point3                      lower{}, upper{};
      std::array<unsigned int, 3> repetitions{};
    };
  } // namespace

  LACERTA_REGISTER_MESH_SOURCE(BoxSource,
                               "box",
                               "A rectangular box ('subsection Box') cut into hexahedra, "
                               "each split into tetrahedra; boundary ids 0..5 on the "
                               "faces x=min, x=max, y=min, y=max, z=min, z=max.");
} // namespace lacerta::mesh
