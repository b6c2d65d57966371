// The level of detail queries: `uniform` and `focus`.

#include <lacerta/base/archive.h>
#include <lacerta/mt/lod_query.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace lacerta::mt
{
  namespace
  {
    /**
     * The cube root of @p x to a few units in the last place: a first guess from the
     * exponent bits, refined by Newton steps. focus_slack() needs one for every node
     * an incremental extraction tests, and std::cbrt costs several times more.
     */
    double
    cube_root(const double x)
    {
      if (!(x >= std::numeric_limits<double>::min()) || !std::isfinite(x))
        return std::cbrt(x); // zero, subnormal, negative, infinite or NaN
      std::uint64_t bits = 0;
      std::memcpy(&bits, &x, sizeof(x));
      // Divides the biased exponent by 3: within 4 % of the root.
      bits     = bits / 3 + 0x2a9f789300000000ull;
      double y = 0;
      std::memcpy(&y, &bits, sizeof(y));
      // Newton converges quadratically: 4 % -> 1e-3 -> 1e-6 -> 1e-12 -> rounding.
      for (unsigned int i = 0; i < 4; ++i)
        y -= (y * y * y - x) / (3 * y * y);
      return y;
    }


    /**
     * The same cell size everywhere.
     */
    class UniformQuery : public LodQuery
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Cell size",
                          "0",
                          dealii::Patterns::Double(0.0, 1e3),
                          "Largest cell size allowed everywhere [m]; 0 extracts the full "
                          "resolution.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        error = error_of_cell_size(prm.get_double("Cell size"));
      }

      double
      minimum_error(const mesh::Point3 &, double) const override
      {
        return error;
      }

      double
      focus_slack(const mesh::Point3 &, double, double) const override
      {
        // No focus: the answer never changes.
        return std::numeric_limits<double>::infinity();
      }

      /// Nothing: the query has no focus.
      void
      serialize(Archive &) override
      {
      }

    private:
      double error = 0;
    };


    /**
     * The surgical focus of Section 4.2: fine within a radius of the tool, coarser
     * with the distance from it.
     */
    class FocusQuery : public LodQuery
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Radius",
                          "0.02",
                          dealii::Patterns::Double(0.0, 1e3),
                          "Radius of the ball around the focus where the cell size is "
                          "'Cell size near the focus' [m].");
        prm.declare_entry("Cell size near the focus",
                          "0",
                          dealii::Patterns::Double(0.0, 1e3),
                          "Largest cell size within the radius [m]; 0 is the full "
                          "resolution.");
        prm.declare_entry(
          "Cell size growth",
          "0.5",
          dealii::Patterns::Double(0.0, 1e3),
          "How fast the allowed cell size grows beyond the radius: "
          "h(d) = h0 + growth (d - radius) at distance d from the focus.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        radius    = prm.get_double("Radius");
        near_size = prm.get_double("Cell size near the focus");
        growth    = prm.get_double("Cell size growth");
      }

      void
      set_focus(const mesh::Point3 &point) override
      {
        travel += distance_to(point);
        focus = point;
      }

      double
      focus_travel() const override
      {
        return travel;
      }

      /// The focus and the distance it travelled.
      void
      serialize(Archive &archive) override
      {
        archive(focus, travel);
      }

      double
      focus_slack(const mesh::Point3 &center,
                  const double        ball_radius,
                  const double        error) const override
      {
        // The answer depends on the focus through its distance to the center only, and
        // minimum_error < error exactly when that distance is below D = ball_radius +
        // radius + (h - h0) / growth, h the cell size of the error: the focus must
        // travel at least |distance - D| to change it. The margin covers rounding (h
        // from the error by a cube root).
        const double h = cube_root(error * 6 * std::sqrt(2.0));
        if (growth == 0 || h < near_size * (1 - 1e-9))
          return std::numeric_limits<double>::infinity(); // never changes
        if (h <= near_size)
          return 0; // too close to call

        const double critical = ball_radius + radius + (h - near_size) / growth;
        const double slack    = std::abs(distance_to(center) - critical);
        return std::max(0.0, slack - 1e-9 * (1 + critical));
      }

      double
      minimum_error(const mesh::Point3 &center, const double ball_radius) const override
      {
        // The allowed error grows with the distance, so its minimum over the ball is at
        // the ball's point nearest to the focus.
        const double d = std::max(0.0, distance_to(center) - ball_radius);
        return error_of_cell_size(near_size + growth * std::max(0.0, d - radius));
      }

    private:
      double
      distance_to(const mesh::Point3 &point) const
      {
        return std::hypot(point[0] - focus[0], point[1] - focus[1], point[2] - focus[2]);
      }

      double       radius = 0, near_size = 0, growth = 0, travel = 0;
      mesh::Point3 focus = {{0, 0, 0}};
    };
  } // namespace

  LACERTA_REGISTER_LOD_QUERY(
    UniformQuery,
    "uniform",
    "The same largest cell size everywhere (subsection Uniform).");
  LACERTA_REGISTER_LOD_QUERY(
    FocusQuery,
    "focus",
    "Full resolution (or 'Cell size near the focus') within 'Radius' of the tool, "
    "cells growing linearly with the distance beyond it (subsection Focus).");
} // namespace lacerta::mt
