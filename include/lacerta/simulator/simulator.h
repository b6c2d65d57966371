/**
 * @file
 * The main loop and the parameter wiring: the only place that knows every subsystem.
 */
#pragma once

#include <lacerta/cut/tool.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace lacerta::scene
{
  class Scene;
}
namespace lacerta::physics
{
  class Integrator;
  class MassBalancer;
} // namespace lacerta::physics
namespace lacerta::postprocess
{
  class Postprocessor;
  struct RunState;
} // namespace lacerta::postprocess

namespace lacerta
{
  /**
   * Hooks into the main loop for a program that drives a scene interactively
   * (lacerta-view), after ASPECT's SimulatorSignals. Each is optional; the simulation
   * thread calls them.
   */
  struct SimulatorSignals
  {
    /// The blade at the end of the step that ends at time t, instead of the tool's
    /// (nullopt: the tool's).
    std::function<std::optional<cut::Blade>(double t)> blade;
    /// Called once before the first step and after every step, with what the
    /// postprocessors see.
    std::function<void(const postprocess::RunState &)> post_step;
    /// Asked after every step: true ends the run there, as if at the end time.
    std::function<bool()> stop;
  };

  /**
   * Runs a scene: builds it from the parameters, integrates it in time with stability
   * control, and calls the postprocessors.
   */
  class Simulator
  {
  public:
    /**
     * Declares every parameter; @p constraint_names are the instances named in
     * `Constraints/Names`.
     */
    static void
    declare_parameters(dealii::ParameterHandler       &prm,
                       const std::vector<std::string> &constraint_names);

    /**
     * Reads @p file into @p prm (declaring it first). An unknown entry, a value out of
     * range or a missing file is an Error that names it.
     */
    static void
    read_parameters(const std::string &file, dealii::ParameterHandler &prm);

    /**
     * Prints the full documented default parameter file, with every plugin of every
     * kind and its description, to @p out.
     */
    static void
    print_help(std::ostream &out);

    /**
     * Builds the scene described by @p prm, read from @p parameter_file.
     */
    Simulator(dealii::ParameterHandler &prm, const std::string &parameter_file);

    ~Simulator();

    /// Runs the scene to its end time; throws an Error if the run cannot go on.
    void
    run();

    /// Hooks for an interactive driver; set them before run().
    SimulatorSignals signals;

    /// The scene, e.g. to read the final state after run().
    const scene::Scene &
    get_scene() const
    {
      return *scene;
    }

  private:
    /**
     * Checks the time step against the stability limit of the current state; returns
     * the sub-step count. @p current sub-steps, if given and still below the limit,
     * are kept without a report.
     */
    unsigned int
    choose_substeps(unsigned int current = 0);

    /**
     * With multiresolution: prints the critical time step of the level of detail next
     * to the full mesh's, and the share of spring evaluations multi-rate stepping would
     * leave on each (issue 17).
     */
    void
    print_stability_against_full_mesh() const;

    std::string  output_directory;
    double       end_time;
    double       time_step;
    unsigned int n_threads;
    bool         test_mode;
    bool         check_invariants;
    bool         substep_when_unstable;
    double       safety_factor;
    double       energy_tolerance;
    unsigned int check_interval;
    /// 'Stability/Maximum sub-steps': more sub-steps per step stop the run.
    unsigned int                                             max_substeps;
    std::unique_ptr<scene::Scene>                            scene;
    std::unique_ptr<physics::Integrator>                     integrator;
    std::vector<std::unique_ptr<postprocess::Postprocessor>> postprocessors;
    /// 'Stability/Mass redistribution': keeps the time step after topology changes,
    /// or nullptr.
    std::unique_ptr<physics::MassBalancer> mass_balancer;
  };
} // namespace lacerta
