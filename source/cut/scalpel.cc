// Tool `scalpel`: a blade moved along keyframes from the parameter file.
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/tool.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <vector>

namespace lacerta::cut
{
  namespace
  {
    /**
     * A scalpel whose blade (tail, head) follows keyframes, interpolated linearly or by
     * Catmull-Rom splines (smooth, through every keyframe). A closed path joins the
     * last keyframe back to the first and repeats; open or closed, the path may cross
     * itself (a loop that passes its start punches a hole, the paper's Figure 9).
     */
    class Scalpel : public Tool
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Keyframes",
          "0, 0, 0, 1, 0, 0, -1; 1, 0, 0, 1, 0, 0, -1",
          dealii::Patterns::List(
            dealii::Patterns::List(dealii::Patterns::Double(-1e6, 1e6), 7, 7, ","),
            2,
            100000,
            ";"),
          "Keyframes separated by ';', each 't, tail_x, tail_y, tail_z, head_x, "
          "head_y, head_z': the time [s] and the blade's two ends [m] in world "
          "coordinates. Times must increase. Before the first keyframe the blade "
          "waits there; after the last it stays (open path) or the path repeats "
          "(closed path).");
        prm.declare_entry("Interpolation",
                          "linear",
                          dealii::Patterns::Selection("linear|catmull-rom"),
                          "How the blade moves between keyframes: along straight "
                          "lines, or along Catmull-Rom splines through the keyframes.");
        prm.declare_entry(
          "Closed path",
          "false",
          dealii::Patterns::Bool(),
          "If true, the blade returns from the last keyframe to the first in the "
          "time of the first segment and the path repeats with that period.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        const std::string text = prm.get("Keyframes");
        for (const std::string &frame : dealii::Utilities::split_string_list(text, ';'))
        {
          const std::vector<double> v = dealii::Utilities::string_to_double(
            dealii::Utilities::split_string_list(frame, ','));
          if (!keys.empty() && !(v[0] > keys.back().time))
            throw_error("Tool/Scalpel/Keyframes: the times must increase; keyframe ",
                        keys.size() + 1,
                        " has time ",
                        v[0],
                        " after ",
                        keys.back().time,
                        ".");
          keys.push_back({v[0], {{{v[1], v[2], v[3]}}, {{v[4], v[5], v[6]}}}});
          const Point &a = keys.back().blade.tail, &b = keys.back().blade.head;
          if (!(norm(sub(b, a)) > 0))
            throw_error("Tool/Scalpel/Keyframes: keyframe ",
                        keys.size(),
                        " has a blade of zero length (tail = head).");
        }
        smooth = prm.get("Interpolation") == "catmull-rom";
        closed = prm.get_bool("Closed path");
        if (closed)
        {
          const double first = keys[1].time - keys[0].time;
          period             = keys.back().time + first - keys[0].time;
        }
      }

      Blade
      blade(double t) const override
      {
        const std::size_t n = keys.size();
        if (t <= keys[0].time)
          return keys[0].blade;
        if (closed)
          t = keys[0].time + std::fmod(t - keys[0].time, period);
        else if (t >= keys.back().time)
          return keys.back().blade;
        // Segment k runs from key k to key k+1 (closed: the last to the first).
        std::size_t k = 0;
        while (k + 1 < n && keys[k + 1].time <= t)
          ++k;
        const double t0 = keys[k].time;
        const double t1 = (k + 1 < n) ? keys[k + 1].time : keys[0].time + period;
        const double s  = (t - t0) / (t1 - t0);
        const auto   at = [&](const long i) -> const Blade &
        {
          if (closed)
            return keys[((i % long(n)) + long(n)) % long(n)].blade;
          return keys[std::min<long>(std::max<long>(i, 0), long(n) - 1)].blade;
        };
        const Blade &p1 = at(long(k)), &p2 = at(long(k) + 1);
        if (!smooth)
          return {lerp(p1.tail, p2.tail, s), lerp(p1.head, p2.head, s)};
        const Blade &p0 = at(long(k) - 1), &p3 = at(long(k) + 2);
        const auto   spline =
          [s](const Point &a, const Point &b, const Point &c, const Point &d)
        {
          Point r;
          for (unsigned int i = 0; i < 3; ++i)
            r[i] = 0.5
                   * (2 * b[i] + (-a[i] + c[i]) * s
                      + (2 * a[i] - 5 * b[i] + 4 * c[i] - d[i]) * s * s
                      + (-a[i] + 3 * b[i] - 3 * c[i] + d[i]) * s * s * s);
          return r;
        };
        return {spline(p0.tail, p1.tail, p2.tail, p3.tail),
                spline(p0.head, p1.head, p2.head, p3.head)};
      }

    private:
      struct Key
      {
        double time;
        Blade  blade;
      };
      std::vector<Key> keys;
      bool             smooth = false;
      bool             closed = false;
      double           period = 0;
    };
  } // namespace

  LACERTA_REGISTER_TOOL(Scalpel,
                        "scalpel",
                        "A scalpel: a blade segment (tail, head) moved along keyframes "
                        "(linear or Catmull-Rom, open or closed, possibly "
                        "self-intersecting). Its swept surface cuts the deformed tissue "
                        "(doc/cutting.md).");
} // namespace lacerta::cut
