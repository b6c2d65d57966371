// Postprocessor `png`: pictures of the run, rendered offscreen with VTK.

#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/cut/tool.h>
#include <lacerta/postprocess/output_schedule.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/view/scene_picture.h>
#include <lacerta/view/x_display.h>

#include <deal.II/base/utilities.h>

#include <vtkNew.h>
#include <vtkRenderWindow.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <optional>
#include <sstream>

namespace lacerta::postprocess
{
  namespace
  {
    /**
     * Renders the tissue's surface, coloured by a field with a colour bar and a title
     * that gives the time, as picture-NNNNN.png, offscreen (under an X display: see
     * view::XDisplay).
     */
    class PngOutput : public Postprocessor
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry("Time between pictures",
                          "0.05",
                          dealii::Patterns::Double(0.0, 1e6),
                          "Simulated time between two pictures [s]; 0 renders every "
                          "step. The initial state is always rendered.");
        prm.declare_entry("Field",
                          "displacement",
                          dealii::Patterns::Selection(view::field_names()),
                          "What colours the surface: the displacement's magnitude, "
                          "the spring strain (elongation over rest length, the "
                          "laceration criterion) or the cell size (the level of "
                          "detail).");
        prm.declare_entry("Colour range",
                          "",
                          dealii::Patterns::Anything(),
                          "'low, high': the field values of the ends of the colour "
                          "scale (the same in every picture); empty: each picture's "
                          "own range.");
        prm.declare_entry("Width",
                          "800",
                          dealii::Patterns::Integer(16, 8192),
                          "Width of the pictures [pixels].");
        prm.declare_entry("Height",
                          "600",
                          dealii::Patterns::Integer(16, 8192),
                          "Height of the pictures [pixels].");
        prm.declare_entry("Camera position",
                          "",
                          dealii::Patterns::Anything(),
                          "'x, y, z' of the camera [m]; empty: the whole object in "
                          "view, seen from above, a little from the front (-y) and "
                          "the left (-x).");
        declare_point_entry(prm,
                            "Focal point",
                            "0, 0, 0",
                            "Where the camera looks, with 'Camera position' [m].");
        declare_point_entry(prm,
                            "View up",
                            "0, 0, 1",
                            "The direction that is up in the picture, with 'Camera "
                            "position'.");
        prm.declare_entry("Wireframe",
                          "false",
                          dealii::Patterns::Bool(),
                          "Whether the surface's edges are drawn over it.");
        prm.declare_entry("Title",
                          "",
                          dealii::Patterns::Anything(),
                          "Text before the time and the field in each picture's title.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        schedule.set_interval(prm.get_double("Time between pictures"));
        field     = view::field_from_name(prm.get("Field"));
        width     = prm.get_integer("Width");
        height    = prm.get_integer("Height");
        wireframe = prm.get_bool("Wireframe");
        title     = prm.get("Title");
        range     = parse_numbers(prm.get("Colour range"), 2, "Colour range");
        if (range && !((*range)[1] > (*range)[0]))
          throw_error("Postprocess/Png/Colour range: the high end must be above the "
                      "low end.");
        const auto position =
          parse_numbers(prm.get("Camera position"), 3, "Camera position");
        if (position)
          camera.position = {{(*position)[0], (*position)[1], (*position)[2]}};
        camera.focal_point = get_point(prm, "Focal point");
        camera.view_up     = get_point(prm, "View up");
      }

      void
      initialize(const std::string &output_directory, bool) override
      {
        display.emplace("The png postprocessor");
        display->attach(*window);
        directory = output_directory;
        window->SetOffScreenRendering(1);
        window->SetSize(static_cast<int>(width), static_cast<int>(height));
        window->AddRenderer(picture.renderer());
        picture.set_wireframe(wireframe);
      }

      bool
      writes_state(const double time) const override
      {
        return schedule.due(time);
      }

      void
      execute(const RunState &s) override
      {
        if (!writes_state(s.time))
          return;
        std::ostringstream heading;
        heading << (title.empty() ? "" : title + "   ") << "t = " << std::fixed
                << std::setprecision(4) << s.time << " s   " << view::field_title(field);
        std::optional<cut::Blade> blade;
        if (s.blade != nullptr)
          blade = *s.blade;
        picture.show(*s.mesh,
                     *s.system,
                     field,
                     blade,
                     heading.str(),
                     range ? std::optional<std::array<double, 2>>(
                       {{(*range)[0], (*range)[1]}})
                           : std::nullopt);
        if (n_written == 0)
          picture.set_camera(camera);
        window->Render();
        char name[64];
        std::snprintf(name, sizeof(name), "picture-%05u.png", n_written);
        write_file_atomically(directory + "/" + name, view::png_of_window(window));
        ++n_written;
        schedule.written(s.time);
      }

    private:
      /// @p count numbers separated by commas in @p text, or nothing if it is empty.
      static std::optional<std::array<double, 3>>
      parse_numbers(const std::string &text,
                    const unsigned int count,
                    const std::string &entry)
      {
        if (text.find_first_not_of(" \t") == std::string::npos)
          return std::nullopt;
        const std::vector<std::string> parts =
          dealii::Utilities::split_string_list(text, ',');
        std::array<double, 3> values{};
        bool                  good = parts.size() == count;
        for (unsigned int i = 0; good && i < count; ++i)
        {
          char *rest = nullptr;
          values[i]  = std::strtod(parts[i].c_str(), &rest);
          good = rest != parts[i].c_str() && *rest == '\0' && std::isfinite(values[i]);
        }
        if (!good)
          throw_error("Postprocess/Png/",
                      entry,
                      ": '",
                      text,
                      "' is not ",
                      count,
                      " numbers separated by commas (or empty).");
        return values;
      }

      /// The schedule and the pictures written so far.
      void
      serialize(Archive &archive) override
      {
        archive(schedule, n_written);
      }

      OutputSchedule                       schedule;
      view::Field                          field = view::Field::displacement;
      unsigned int                         width = 800, height = 600, n_written = 0;
      bool                                 wireframe = false;
      std::string                          title, directory;
      std::optional<std::array<double, 3>> range;
      view::Camera                         camera;
      view::ScenePicture                   picture;
      /// Declared before the window, which must go first.
      std::optional<view::XDisplay> display;
      vtkNew<vtkRenderWindow>       window;
    };
  } // namespace

  LACERTA_REGISTER_POSTPROCESSOR(
    PngOutput,
    "png",
    "Pictures of the run (picture-NNNNN.png), rendered offscreen with VTK: the "
    "surface coloured by a field, a colour bar, the blade, and a title with the "
    "time ('subsection Png'). Needs an X display: run under 'xvfb-run -a' on a "
    "machine without a screen.");
} // namespace lacerta::postprocess
