#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/view/mouse_scalpel.h>

#include <filesystem>
#include <iomanip>
#include <sstream>

namespace lacerta::view
{
  using cut::Blade;
  using cut::Point;

  namespace
  {
    bool
    same(const Blade &a, const Blade &b)
    {
      return a.tail == b.tail && a.head == b.head;
    }


    /// Whether @p b lies on the straight path from @p a to @p c at time fraction @p s,
    /// within a nanometre.
    bool
    on_the_way(const Blade &a, const Blade &b, const Blade &c, const double s)
    {
      return mesh::distance(b.tail, mesh::lerp(a.tail, c.tail, s)) < 1e-9
             && mesh::distance(b.head, mesh::lerp(a.head, c.head, s)) < 1e-9;
    }
  } // namespace


  void
  MouseScalpel::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.declare_entry("Blade length",
                      "0.1",
                      dealii::Patterns::Double(1e-6, 100),
                      "Length of the blade lacerta-view's mouse holds [m]; it lies "
                      "along the direction the camera looks.");
    prm.declare_entry("Blade depth",
                      "0.05",
                      dealii::Patterns::Double(0, 100),
                      "How far the mouse's blade reaches below the point of the "
                      "surface under the mouse, along the view [m] (at most 'Blade "
                      "length').");
  }


  MouseScalpel::Parameters
  MouseScalpel::parse_parameters(dealii::ParameterHandler &prm)
  {
    Parameters p;
    p.length = prm.get_double("Blade length");
    p.depth  = prm.get_double("Blade depth");
    if (p.depth > p.length)
      throw_error("Viewer/Blade depth = ",
                  p.depth,
                  " m is more than 'Blade length' = ",
                  p.length,
                  " m: the blade would start below the surface.");
    return p;
  }


  MouseScalpel::MouseScalpel(const Parameters &parameters, const double object_size)
      : parameters(parameters)
      , lift(2 * object_size + parameters.length)
  {
  }


  Blade
  MouseScalpel::cutting_blade(const Point &point) const
  {
    return {mesh::sub(point, mesh::scale(parameters.length - parameters.depth, view)),
            mesh::add(point, mesh::scale(parameters.depth, view))};
  }


  Blade
  MouseScalpel::lifted(const Blade &b) const
  {
    return {mesh::sub(b.tail, mesh::scale(lift, view)),
            mesh::sub(b.head, mesh::scale(lift, view))};
  }


  void
  MouseScalpel::press(const Point &point, const Point &view_direction)
  {
    const std::lock_guard<std::mutex> lock(mutex);
    view        = mesh::normalized(view_direction);
    under_mouse = point;
    is_held = ever_held = true;
    waiting.reset();
    const Blade target = cutting_blade(point);
    planned            = {lifted(last_used), lifted(target), target};
  }


  void
  MouseScalpel::drag(const Point &point)
  {
    const std::lock_guard<std::mutex> lock(mutex);
    under_mouse = point;
  }


  void
  MouseScalpel::release()
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!is_held)
      return;
    is_held         = false;
    const Blade out = lifted(cutting_blade(under_mouse));
    planned.push_back(out);
    waiting = out;
  }


  bool
  MouseScalpel::held() const
  {
    const std::lock_guard<std::mutex> lock(mutex);
    return is_held;
  }


  std::optional<Blade>
  MouseScalpel::blade(double)
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!planned.empty())
    {
      const Blade next = planned.front();
      planned.erase(planned.begin());
      return next;
    }
    if (is_held)
      return cutting_blade(under_mouse);
    if (ever_held)
      return waiting;
    return std::nullopt;
  }


  void
  MouseScalpel::used(const double time, const Blade &blade)
  {
    const std::lock_guard<std::mutex> lock(mutex);
    last_used = blade;
    // A still blade, or one moving uniformly, is kept as the ends of its stretch: the
    // scalpel's linear interpolation gives the same blade at every step in between.
    const std::size_t n = record.size();
    if (n >= 2)
    {
      const auto &[t0, b0] = record[n - 2];
      const auto &[t1, b1] = record[n - 1];
      if ((same(b0, b1) && same(b1, blade))
          || (!same(b0, b1) && on_the_way(b0, b1, blade, (t1 - t0) / (time - t0))))
      {
        record.back() = {time, blade};
        return;
      }
    }
    if (n == 0 || time > record.back().first)
      record.emplace_back(time, blade);
  }


  void
  MouseScalpel::write_record(const std::string &file, const std::string &scene_file) const
  {
    const std::lock_guard<std::mutex>     lock(mutex);
    std::vector<std::pair<double, Blade>> keys = record;
    if (keys.empty())
      keys.emplace_back(0.0, last_used);
    if (keys.size() == 1)
      keys.emplace_back(keys[0].first + 1e-3, keys[0].second);
    std::ostringstream out;
    out << std::setprecision(17);
    out << "# A stroke recorded by lacerta-view: the blade at every step it ran, as "
           "scalpel\n# keyframes. 'lacerta <this file>' replays it in batch.\n"
        << "include " << std::filesystem::absolute(scene_file).string() << "\n\n"
        << "set End time = " << keys.back().first << "\n\n"
        << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
        << "    set Interpolation = linear\n    set Closed path   = false\n"
        << "    set Keyframes     = ";
    for (std::size_t k = 0; k < keys.size(); ++k)
    {
      const auto &[t, b] = keys[k];
      out << (k ? "; \\\n                        " : "") << t;
      for (const Point &p : {b.tail, b.head})
        for (const double x : p)
          out << ", " << x;
    }
    out << "\n  end\nend\n";
    write_file_atomically(file, out.str());
  }
} // namespace lacerta::view
