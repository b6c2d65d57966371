/**
 * @file
 * The main loop and the parameter wiring: the only place that knows every subsystem.
 */
#pragma once

#include <deal.II/base/parameter_handler.h>

#include <iosfwd>
#include <memory>
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
}

namespace lacerta
{
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
