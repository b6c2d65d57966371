/**
 * @file
 * The scalpel held with the mouse in lacerta-view, and the record of its path.
 */
#pragma once

#include <lacerta/cut/tool.h>

#include <deal.II/base/parameter_handler.h>

#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace lacerta::view
{
  /**
   * The blade the user holds: the viewer's thread tells it where the mouse is
   * (press(), drag(), release()); the simulation thread asks it for the blade at every
   * step (blade(), for SimulatorSignals::blade) and tells it which blade the step used
   * (used()), which it keeps as scalpel keyframes (write_record()).
   *
   * The blade is a segment along the direction the user looks (the camera's view at the
   * press), of `Blade length`, reaching `Blade depth` below the point under the mouse.
   * A press lifts the blade out of the tissue along that direction (far enough to
   * clear the whole object), moves it above the pressed point and lowers it there,
   * one step each, so that no motion between two cuts sweeps through tissue; a release
   * lifts it out again, where it waits. Until the first press the scene's own tool
   * moves the blade.
   */
  class MouseScalpel
  {
  public:
    /// `subsection Viewer`'s blade entries.
    struct Parameters
    {
      double length = 0.1;
      double depth  = 0.05;
    };

    /// Declares the blade's entries (in `subsection Viewer`).
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads them.
    static Parameters
    parse_parameters(dealii::ParameterHandler &prm);

    /**
     * A scalpel with @p parameters over an object of diameter @p object_size [m] (how
     * far a lifted blade is kept from the tissue).
     */
    MouseScalpel(const Parameters &parameters, double object_size);

    /// Viewer thread: the mouse went down over the tissue at @p point, the user looking
    /// along @p view (unit).
    void
    press(const cut::Point &point, const cut::Point &view);

    /// Viewer thread: the mouse moved, with the button down, to @p point (on the plane
    /// through the pressed point across the view).
    void
    drag(const cut::Point &point);

    /// Viewer thread: the button went up.
    void
    release();

    /// Whether the button is down.
    bool
    held() const;

    /// Simulation thread: the blade for the step ending at @p time (nullopt: the
    /// scene's tool).
    std::optional<cut::Blade>
    blade(double time);

    /// Simulation thread: the step that ended at @p time used @p blade.
    void
    used(double time, const cut::Blade &blade);

    /**
     * Writes the blades used so far as a parameter file that includes @p scene_file and
     * replays them with the `scalpel` tool in batch, ending at the last time used.
     */
    void
    write_record(const std::string &file, const std::string &scene_file) const;

  private:
    /// The cutting blade through @p point along the view.
    cut::Blade
    cutting_blade(const cut::Point &point) const;

    /// @p b moved out along the view, beyond the object.
    cut::Blade
    lifted(const cut::Blade &b) const;

    Parameters         parameters;
    double             lift;
    mutable std::mutex mutex;
    bool               is_held = false, ever_held = false;
    cut::Point         view{{0, 0, -1}}, under_mouse{};
    cut::Blade         last_used{};
    /// Blades to use at the next steps, first first (the lift, move and lowering of a
    /// press; the lift of a release); then the held blade or the waiting one.
    std::vector<cut::Blade>   planned;
    std::optional<cut::Blade> waiting;
    /// (time, blade) of every step, a still or uniformly moving stretch kept as its ends.
    std::vector<std::pair<double, cut::Blade>> record;
  };
} // namespace lacerta::view
