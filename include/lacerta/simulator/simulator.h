/**
 * @file
 * The main loop and the parameter wiring: the only place that knows every subsystem.
 */
#pragma once

#include <lacerta/cut/tool.h>
#include <lacerta/postprocess/postprocessor.h>

#include <deal.II/base/parameter_handler.h>

#include <chrono>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace dealii
{
  class TimerOutput;
}
namespace lacerta::scene
{
  class Scene;
  struct SystemChange;
} // namespace lacerta::scene
namespace lacerta::physics
{
  class BlowUpMonitor;
  struct FrequencyBound;
  class Integrator;
  class MassBalancer;
  class StabilityBound;
} // namespace lacerta::physics

namespace lacerta
{
  class Archive;

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
     * Whether the run @p prm describes uses MPI: a study (`Mode = study`) or the FEM
     * reference (the `fem comparison` postprocessor), whose solvers are Trilinos'.
     * The programs initialise MPI only then: a scene of springs alone does not depend
     * on the MPI runtime starting.
     */
    static bool
    needs_mpi(const dealii::ParameterHandler &prm);

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
    /// The phases of run(), in order. Before the first step: the scene's summary, the
    /// stability limit, the postprocessors' step 0.
    void
    start_run();

    /// Zeroes the state's columns that describe one step.
    void
    begin_step();

    /// Moves the scalpel to where it is at the end of the step of length @p dt and
    /// cuts (Scene::cut()).
    void
    move_tool(double dt);

    /// Lets the springs past their limit tear (Scene::lacerate()).
    void
    lacerate();

    /// Integrates the step of length @p dt in the chosen sub-steps.
    void
    integrate(double dt);

    /// With multiresolution: the MT update after a stroke, then the level of detail
    /// the focus asks for.
    void
    update_multiresolution();

    /// Checks for blow-up where needed and calls the postprocessors and post_step.
    void
    postprocess();

    /// The energies line ten times per run and the progress line on a terminal.
    void
    report_progress();

    /// The end of the run: the summaries and, outside test mode, the timings.
    void
    finish_run();

    /**
     * After a step: writes a checkpoint if one is due (`subsection Checkpoint`);
     * returns whether the run stops here (`Stop after steps`).
     */
    bool
    checkpoint_if_due();

    /// Writes the checkpoint of the state after the current step.
    void
    write_checkpoint();

    /**
     * With `Resume`: reads the last checkpoint (the previous one if the last is
     * damaged) into the state start_run() built, instead of the postprocessors' step 0.
     */
    void
    resume_from_checkpoint();

    /// Writes or reads everything the run carries from one step to the next: the
    /// scene, the integrator, the monitors, the redistribution, the postprocessors.
    void
    serialize(Archive &archive);

    /// The parameters a checkpoint must have been written with to be resumed: all but
    /// `End time`, `Output directory` and `subsection Checkpoint`, and the threads.
    std::string
    checkpoint_parameters(const dealii::ParameterHandler &prm) const;

    /**
     * The simulator's subscriber to Scene::system_changed: the mass redistribution,
     * the invariants (after a local change), the integrator's scratch space, the
     * blow-up monitor's ledger and the stability bound follow the changed system, and
     * the sub-steps are chosen again. After a local change (a cut, a tear) the monitor
     * and the bound are updated around the changed particles only; their wall time is
     * added to the step's cut or tear time.
     */
    void
    on_system_changed(const scene::SystemChange &change);

    /// With `Check invariants`: stops the run naming @p at_step if one is broken.
    void
    check(unsigned int at_step) const;

    /// The energies and the loads' work into the state.
    void
    evaluate_energies();

    /// Whether @p substeps sub-steps per time step are stable under @p bound (0: nothing
    /// moves; a bound that is not finite is not stable).
    bool
    keeps_substeps(const physics::FrequencyBound &bound, unsigned int substeps) const;

    /**
     * The largest squared frequency ω² (rad²/s²) under which @p substeps sub-steps per
     * time step are stable (keeps_substeps(), which is taken to hold below a frequency
     * and fail above it), to the last bits: the limit the periodic re-check compares
     * each particle's row with. Infinite if every frequency keeps them. Kept for the
     * last @p substeps asked.
     */
    double
    largest_kept_squared_frequency(unsigned int substeps);

    /**
     * Checks the time step against the stability limit @p bound of the current state;
     * returns the sub-step count. @p current sub-steps, if given and still below the
     * limit, are kept without a report.
     */
    unsigned int
    choose_substeps(const physics::FrequencyBound &bound, unsigned int current = 0);

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
    /// The sub-step count and limit of the last largest_kept_squared_frequency().
    std::pair<unsigned int, double> kept_frequency_limit{0, 0.0};
    /// 'Stability/Maximum sub-steps': more sub-steps per step stop the run.
    unsigned int                                             max_substeps;
    std::unique_ptr<scene::Scene>                            scene;
    std::unique_ptr<physics::Integrator>                     integrator;
    std::vector<std::unique_ptr<postprocess::Postprocessor>> postprocessors;
    /// 'Stability/Mass redistribution': keeps the time step after topology changes,
    /// or nullptr.
    std::unique_ptr<physics::MassBalancer> mass_balancer;

    /// The run in progress: what the postprocessors see, the step, the time.
    postprocess::RunState state;
    unsigned int          step = 0, n_steps = 0, steps_done = 0;
    double                time               = 0;
    unsigned long long    n_integrator_steps = 0;
    /// Mass redistribution over the run: the most mass held away from the lumped
    /// masses at one change, the particles left above the target at the last one, and
    /// the changes.
    struct
    {
      double       largest_moved   = 0;
      unsigned int last_unresolved = 0, n_balances = 0;
    } redistribution;
    std::unique_ptr<physics::BlowUpMonitor> monitor;
    /// The stability bound per particle, updated locally after cuts and tears.
    std::unique_ptr<physics::StabilityBound> stability_bound;
    /// Wall time of on_system_changed() since the last cut or tear read it (s).
    double                                change_seconds = 0;
    std::unique_ptr<dealii::TimerOutput>  timer;
    std::chrono::steady_clock::time_point run_start;
    /// `subsection Checkpoint`: where, how often (steps, wall seconds; 0: never),
    /// whether to resume, and after how many steps to stop (0: at the end).
    struct
    {
      std::string                           file;
      unsigned int                          steps = 0, stop_after = 0;
      double                                seconds = 0;
      bool                                  resume  = false;
      std::string                           parameters;
      std::chrono::steady_clock::time_point last;
    } checkpoint;
    double last_progress = 0;
    bool   show_progress = false;
  };
} // namespace lacerta
