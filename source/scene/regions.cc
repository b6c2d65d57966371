// Region plugins: box, sphere, boundary id.

#include <lacerta/base/parameter_utilities.h>
#include <lacerta/scene/region.h>

#include <deal.II/base/utilities.h>

#include <algorithm>
#include <cmath>

namespace lacerta::scene
{
  namespace
  {
    /**
     * The particles inside an axis-aligned box (boundary included).
     */
    class BoxRegion : public Region
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
                            "0, 0, 0",
                            "Upper corner of the box [m].");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        lower = get_point(prm, "Lower corner");
        upper = get_point(prm, "Upper corner");
      }

      std::vector<unsigned int>
      select(const mesh::TetMesh &mesh) const override
      {
        // A relative tolerance keeps vertices that lie on the box's faces.
        const double tolerance =
          1e-10
          * std::max(
            {upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2], 1e-300});
        std::vector<unsigned int> inside;
        for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
        {
          const auto &p  = mesh.vertex(v);
          bool        in = true;
          for (unsigned int d = 0; d < 3; ++d)
            in = in && p[d] >= lower[d] - tolerance && p[d] <= upper[d] + tolerance;
          if (in)
            inside.push_back(v);
        }
        return inside;
      }

    private:
      mesh::Point3 lower{}, upper{};
    };


    /**
     * The particles inside a ball.
     */
    class SphereRegion : public Region
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        declare_point_entry(prm, "Center", "0, 0, 0", "Centre of the ball [m].");
        prm.declare_entry("Radius",
                          "0",
                          dealii::Patterns::Double(0.0),
                          "Radius of the ball [m].");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        center = get_point(prm, "Center");
        radius = prm.get_double("Radius");
      }

      std::vector<unsigned int>
      select(const mesh::TetMesh &mesh) const override
      {
        std::vector<unsigned int> inside;
        for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
        {
          const auto &p = mesh.vertex(v);
          if (std::hypot(p[0] - center[0], p[1] - center[1], p[2] - center[2])
              <= radius * (1 + 1e-10))
            inside.push_back(v);
        }
        return inside;
      }

    private:
      mesh::Point3 center{};
      double       radius = 0;
    };


    /**
     * The particles on boundary faces with given ids.
     */
    class BoundaryIdRegion : public Region
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Boundary ids",
          "0",
          dealii::Patterns::List(dealii::Patterns::Integer(0, 255), 1),
          "Boundary ids whose faces' vertices form the region (a box mesh "
          "has 0..5 on x=min, x=max, y=min, y=max, z=min, z=max).");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        ids.clear();
        for (const int id : dealii::Utilities::string_to_int(
               dealii::Utilities::split_string_list(prm.get("Boundary ids"))))
          ids.push_back(static_cast<unsigned int>(id));
      }

      std::vector<unsigned int>
      select(const mesh::TetMesh &mesh) const override
      {
        std::vector<unsigned int> inside;
        for (const auto &face : mesh.get_boundary_faces())
          if (std::find(ids.begin(), ids.end(), face.boundary_id) != ids.end())
            for (const unsigned int lv : mesh::TetMesh::face_vertices[face.face])
              inside.push_back(mesh.tet(face.tet)[lv]);
        std::sort(inside.begin(), inside.end());
        inside.erase(std::unique(inside.begin(), inside.end()), inside.end());
        return inside;
      }

    private:
      std::vector<unsigned int> ids;
    };
  } // namespace

  LACERTA_REGISTER_REGION(BoxRegion,
                          "box",
                          "The particles inside an axis-aligned box ('subsection Box').");
  LACERTA_REGISTER_REGION(SphereRegion,
                          "sphere",
                          "The particles inside a ball ('subsection Sphere').");
  LACERTA_REGISTER_REGION(
    BoundaryIdRegion,
    "boundary id",
    "The particles on the boundary faces with given ids ('subsection "
    "Boundary id').");
} // namespace lacerta::scene
