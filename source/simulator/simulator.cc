#include <lacerta/base/archive.h>
#include <lacerta/base/checkpoint_file.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/input_path.h>
#include <lacerta/base/output_file.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/cut/tool.h>
#include <lacerta/fem/study.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/mass_balancer.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/stability_bound.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/scene/scene.h>
#include <lacerta/simulator/simulator.h>
#include <lacerta/view/viewer.h>

#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <numeric>
#include <sstream>
#include <thread>
#include <unistd.h>

namespace lacerta
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    double
    seconds_since(const Clock::time_point start)
    {
      return std::chrono::duration<double>(Clock::now() - start).count();
    }


    /// Largest displacement from the rest position and the particle that has it.
    std::pair<double, unsigned int>
    largest_displacement(const physics::ParticleSystem &system)
    {
      double       largest = 0;
      unsigned int where   = 0;
      for (unsigned int i = 0; i < system.n_particles(); ++i)
      {
        const double *x = &system.position[3 * i];
        const double *r = &system.rest_position()[3 * i];
        const double  d = std::hypot(x[0] - r[0], x[1] - r[1], x[2] - r[2]);
        if (d > largest)
        {
          largest = d;
          where   = i;
        }
      }
      return {largest, where};
    }


    /**
     * Appends the lines of @p file to @p text, replacing every `include name` line by
     * the lines of that file (recursively). deal.II looks for included files in the
     * working directory; a scene variant includes its base scene by a name relative to
     * itself, so included names are resolved from the including file's directory first.
     */
    void
    append_with_includes(const std::string &file,
                         std::ostream      &text,
                         const unsigned int depth)
    {
      if (depth > 16)
        throw_error("Parameter file '",
                    file,
                    "': includes are nested too deeply (a cycle?).");
      std::ifstream in(file);
      if (!in)
        throw_error("Parameter file '", file, "' cannot be opened.");
      const std::filesystem::path directory = std::filesystem::path(file).parent_path();
      unsigned int                number    = 0;
      for (std::string line; std::getline(in, line);)
      {
        ++number;
        const std::string trimmed = dealii::Utilities::trim(line);
        if (trimmed.rfind("include ", 0) != 0)
        {
          text << line << '\n';
          continue;
        }
        const std::string     name = dealii::Utilities::trim(trimmed.substr(8));
        std::filesystem::path path(name);
        if (path.is_relative() && std::filesystem::exists(directory / path))
          path = directory / path;
        if (!std::filesystem::exists(path))
          throw_error("Parameter file '",
                      file,
                      "', line ",
                      number,
                      ": the included file '",
                      name,
                      "' cannot be opened.");
        append_with_includes(path.string(), text, depth + 1);
      }
    }
  } // namespace


  void
  Simulator::declare_parameters(dealii::ParameterHandler       &prm,
                                const std::vector<std::string> &constraint_names)
  {
    prm.declare_entry(
      "Output directory",
      "output",
      dealii::Patterns::DirectoryName(),
      "Where the run writes its files (created if needed); the parameters "
      "it used are copied there as parameters.prm.");
    prm.declare_entry("Mode",
                      "simulation",
                      dealii::Patterns::Selection("simulation|study"),
                      "'simulation' runs the scene in time; 'study' runs the variants of "
                      "'subsection Study' (error against run time, doc/accuracy.md).");
    prm.declare_entry("End time",
                      "1",
                      dealii::Patterns::Double(0.0, 1e6),
                      "Simulated time at which the run stops [s].");
    prm.declare_entry(
      "Time step",
      "1e-4",
      dealii::Patterns::Double(1e-12, 10.0),
      "Time step [s]. If it is above the stability limit the run sub-steps "
      "or stops (see 'Stability/Time step above limit').");
    prm.declare_entry(
      "Number of threads",
      "0",
      dealii::Patterns::Integer(0, 256),
      "Threads for the force evaluation (every force model: each thread evaluates the "
      "forces on its own range of particles); 0: one per core of the machine. Runs "
      "with different counts differ by rounding only (the order of a particle's "
      "force sum).");
    prm.declare_entry(
      "Test mode",
      "false",
      dealii::Patterns::Bool(),
      "Print no timings and no progress line and write zero wall times, so "
      "that the output of two runs can be compared.");

    prm.declare_entry(
      "Check invariants",
      "false",
      dealii::Patterns::Bool(),
      "Check the mesh and mass invariants (volume, conformity, no inverted or flat "
      "element, springs = edges, total mass = integral of the density) at the start "
      "and after every step that cuts; a violation stops the run. Costs O(mesh size) "
      "per cutting step.");

    prm.enter_subsection("Stability");
    prm.declare_entry(
      "Time step above limit",
      "substep",
      dealii::Patterns::Selection("substep|stop"),
      "What to do if 'Time step' exceeds the critical time step of the "
      "integrator: 'substep' splits every step into enough equal sub-steps, "
      "'stop' ends the run with a message naming the limit and the spring "
      "that sets it.");
    prm.declare_entry("Safety factor",
                      "0.9",
                      dealii::Patterns::Double(0.01, 1.0),
                      "Fraction of the critical time step that a (sub-)step may use.");
    prm.declare_entry("Energy growth tolerance",
                      "1",
                      dealii::Patterns::Double(1e-6, 1e6),
                      "The run stops as blown up when the mechanical energy exceeds the "
                      "initial energy plus the work of the loads by this fraction of the "
                      "largest energy seen.");
    prm.declare_entry(
      "Maximum sub-steps",
      "1000",
      dealii::Patterns::Integer(1, 1000000000),
      "With 'Time step above limit' = substep, the run stops instead of splitting a "
      "step into more sub-steps than this: a critical time step that small comes "
      "from a degenerate element (a sliver, a particle far off), not from the "
      "material, and the run would crawl.");
    prm.declare_entry(
      "Check interval",
      "10",
      dealii::Patterns::Integer(1, 1000000),
      "Steps between two blow-up checks (non-finite state, energy growth); "
      "the state is also checked before every output.");
    prm.declare_entry(
      "Mass redistribution",
      "true",
      dealii::Patterns::Bool(),
      "In a scene that can cut or tear (a tool, or lacerations), after every topology "
      "change (a cut, a tear, a new level of detail), raise the mass of each free "
      "particle whose Gershgorin bound at rest exceeds the bound of the system at the "
      "start, taking it from particles joined to it by springs (the mass of every "
      "piece stays the integral of the density over it), when the particles within "
      "reach can spare it. Small cells next to a cut then do not lower the critical "
      "time step (doc/stability.md). After a cut or a tear only the particles it "
      "changed are raised. false: masses are the lumped integrals of the density. "
      "Scenes that neither cut nor tear keep the lumped masses.");
    prm.declare_entry("Redistribution reach",
                      "3",
                      dealii::Patterns::Integer(1, 8),
                      "How many springs away 'Mass redistribution' may take mass from.");
    prm.leave_subsection();

    prm.enter_subsection("Checkpoint");
    prm.declare_entry(
      "Steps between checkpoints",
      "0",
      dealii::Patterns::Integer(0, 1000000000),
      "Write a checkpoint (<Output directory>/checkpoint.lcp, the one before it kept as "
      "checkpoint.lcp.previous) every this many steps; 0: never by steps.");
    prm.declare_entry(
      "Seconds between checkpoints",
      "0",
      dealii::Patterns::Double(0.0, 1e7),
      "Write a checkpoint after the first step that ends this much wall time after "
      "the last one (or the start) [s]; 0: never by wall time.");
    prm.declare_entry(
      "Resume",
      "false",
      dealii::Patterns::Bool(),
      "Continue the run from the last checkpoint in 'Output directory' (from the "
      "previous one if the last is damaged) instead of from the start. The parameters "
      "must be those the checkpoint was written with, but for 'End time', 'Output "
      "directory' and this subsection; the run then ends exactly as if it had never "
      "stopped.");
    prm.declare_entry(
      "Stop after steps",
      "0",
      dealii::Patterns::Integer(0, 1000000000),
      "End the run after this many steps (a resumed run counts from its start at "
      "time 0), with a checkpoint, as a batch job with a time limit would; 0: run to "
      "'End time'.");
    prm.leave_subsection();

    scene::Scene::declare_parameters(prm, constraint_names);
    physics::Integrator::declare_parameters(prm);
    postprocess::Postprocessor::declare_parameters(prm);
    fem::Study::declare_parameters(prm);
    view::Viewer::declare_parameters(prm);
  }


  void
  Simulator::read_parameters(const std::string &file, dealii::ParameterHandler &prm)
  {
    if (!std::ifstream(file))
      throw_error("Parameter file '", file, "' cannot be opened.");
    set_input_directory(std::filesystem::path(file).parent_path().string());
    std::ostringstream text;
    append_with_includes(file, text, 0);

    const auto parse = [&](dealii::ParameterHandler &handler, const bool skip_undefined)
    {
      try
      {
        std::istringstream input(text.str());
        handler.parse_input(input, file, "", skip_undefined);
      }
      catch (const dealii::ExceptionBase &e)
      {
        std::ostringstream info;
        e.print_info(info);
        throw_error("Parameter file '", file, "': ", info.str());
      }
    };

    // First pass: learn the constraint names, which declare subsections of their own.
    dealii::ParameterHandler first;
    // The placeholder '<name>' of --help is declared too, so that the printed default
    // file is itself a valid parameter file.
    declare_parameters(first, {"<name>"});
    parse(first, true);
    std::vector<std::string> names = scene::Constraint::names(first);
    if (std::find(names.begin(), names.end(), "<name>") == names.end())
      names.push_back("<name>");
    declare_parameters(prm, names);
    parse(prm, false);

    prm.enter_subsection("Checkpoint");
    const bool checkpoints = prm.get_integer("Steps between checkpoints") > 0
                             || prm.get_double("Seconds between checkpoints") > 0
                             || prm.get_bool("Resume")
                             || prm.get_integer("Stop after steps") > 0;
    prm.leave_subsection();
    if (checkpoints && prm.get("Mode") == "study")
      throw_error("Parameter file '",
                  file,
                  "': 'subsection Checkpoint' applies to "
                  "'Mode = simulation'; a study ('Mode = study') runs its variants "
                  "from the start and cannot be checkpointed.");
  }


  bool
  Simulator::needs_mpi(const dealii::ParameterHandler &prm)
  {
    if (prm.get("Mode") == "study")
      return true;
    const std::vector<std::string> names = dealii::Utilities::split_string_list(
      prm.get({"Postprocess"}, "List of postprocessors"));
    return std::find(names.begin(), names.end(), "fem comparison") != names.end();
  }


  void
  Simulator::print_help(std::ostream &out)
  {
    dealii::ParameterHandler prm;
    declare_parameters(prm, {"<name>"});
    // Comment lines only, so that the output is itself a valid parameter file.
    out << "# lacerta <scene.prm> runs a scene; lacerta --help prints this file.\n"
        << "# The default parameter file, with every entry documented. Each plugin kind\n"
        << "# lists its plugins in the documentation of its selector entry. Constraints\n"
        << "# are named instances (Constraints/Names); '<name>' stands for one of "
           "them.\n\n";
    prm.print_parameters(out, dealii::ParameterHandler::PRM);
  }


  Simulator::Simulator(dealii::ParameterHandler &prm, const std::string &parameter_file)
  {
    output_directory = prm.get("Output directory");
    end_time         = prm.get_double("End time");
    time_step        = prm.get_double("Time step");
    n_threads        = prm.get_integer("Number of threads");
    if (n_threads == 0)
      n_threads = std::max(1u, std::thread::hardware_concurrency());
    test_mode        = prm.get_bool("Test mode");
    check_invariants = prm.get_bool("Check invariants");
    prm.enter_subsection("Stability");
    substep_when_unstable = prm.get("Time step above limit") == "substep";
    safety_factor         = prm.get_double("Safety factor");
    energy_tolerance      = prm.get_double("Energy growth tolerance");
    check_interval        = prm.get_integer("Check interval");
    max_substeps          = prm.get_integer("Maximum sub-steps");

    const bool         redistribute_mass    = prm.get_bool("Mass redistribution");
    const unsigned int redistribution_reach = prm.get_integer("Redistribution reach");
    prm.leave_subsection();
    prm.enter_subsection("Checkpoint");
    checkpoint.file       = output_directory + "/checkpoint.lcp";
    checkpoint.steps      = prm.get_integer("Steps between checkpoints");
    checkpoint.seconds    = prm.get_double("Seconds between checkpoints");
    checkpoint.resume     = prm.get_bool("Resume");
    checkpoint.stop_after = prm.get_integer("Stop after steps");
    prm.leave_subsection();
    checkpoint.parameters = checkpoint_parameters(prm);

    create_output_directory(output_directory);
    std::ostringstream copy;
    copy << "# Parameters used by lacerta for " << parameter_file << "\n";
    prm.print_parameters(copy, dealii::ParameterHandler::ShortPRM);
    write_file_atomically(output_directory + "/parameters.prm", copy.str());

    scene      = std::make_unique<scene::Scene>(prm, n_threads);
    integrator = physics::Integrator::create(prm);
    // A scene that cuts or tears always prints the paper's tables.
    postprocessors =
      postprocess::Postprocessor::create(prm,
                                         scene->cutter || scene->lacerator
                                           ? std::vector<std::string>{"cut tables"}
                                           : std::vector<std::string>{});
    // Only cuts and tears make the small cells the redistribution is for.
    if (redistribute_mass && (scene->cutter || scene->lacerator))
      mass_balancer =
        std::make_unique<physics::MassBalancer>(*scene->system, redistribution_reach);
    integrator->initialize(*scene->system);
    for (auto &p : postprocessors)
    {
      p->initialize(output_directory, test_mode);
      p->subscribe(*scene);
    }
    scene->system_changed.connect([this](const scene::SystemChange &change)
                                  { on_system_changed(change); });
    if (checkpoint.steps > 0 || checkpoint.seconds > 0 || checkpoint.stop_after > 0)
    {
      // A postprocessor that cannot be resumed says so now, not at the first
      // checkpoint.
      std::string scratch;
      Archive     archive(scratch);
      for (auto &p : postprocessors)
        p->serialize(archive);
    }
  }


  std::string
  Simulator::checkpoint_parameters(const dealii::ParameterHandler &prm) const
  {
    std::ostringstream printed;
    prm.print_parameters(printed, dealii::ParameterHandler::ShortPRM);
    std::istringstream       in(printed.str());
    std::string              line, kept;
    std::vector<std::string> path;
    while (std::getline(in, line))
    {
      const std::size_t first = line.find_first_not_of(' ');
      if (first == std::string::npos)
        continue;
      const std::string text          = line.substr(first);
      const auto        in_checkpoint = [&]
      { return !path.empty() && path.front() == "Checkpoint"; };
      bool skipped = in_checkpoint();
      if (text.rfind("subsection ", 0) == 0)
        path.push_back(text.substr(11));
      else if (text == "end" && !path.empty())
        path.pop_back();
      else if (path.empty())
        skipped = text.rfind("set End time ", 0) == 0
                  || text.rfind("set Output directory ", 0) == 0;
      if (!skipped && !in_checkpoint())
        kept += text + "\n";
    }
    return kept + "threads = " + std::to_string(n_threads) + "\n";
  }


  Simulator::~Simulator() = default;


  bool
  Simulator::keeps_substeps(const physics::FrequencyBound &bound,
                            const unsigned int             substeps) const
  {
    if (bound.omega == 0)
      return true;
    if (!std::isfinite(bound.omega))
      return false;
    const physics::ParticleSystem &system = *scene->system;
    return time_step / substeps
           <= safety_factor
                * integrator->critical_time_step(bound.omega,
                                                 system.mass_damping,
                                                 system.spring_damping);
  }


  double
  Simulator::largest_kept_squared_frequency(const unsigned int substeps)
  {
    if (kept_frequency_limit.first == substeps)
      return kept_frequency_limit.second;
    const auto keeps = [&](const double omega)
    {
      physics::FrequencyBound b;
      b.omega = omega;
      return keeps_substeps(b, substeps);
    };
    // Bracket the limit by doubling, then halve the bracket until its ends are
    // neighbouring doubles; the lower end keeps the sub-steps.
    double low = 0, high = 1;
    while (keeps(high) && high < std::numeric_limits<double>::max() / 2)
    {
      low = high;
      high *= 2;
    }
    double limit = std::numeric_limits<double>::infinity();
    if (!keeps(high))
    {
      for (unsigned int k = 0; k < 2100; ++k)
      {
        const double middle = low + 0.5 * (high - low);
        if (middle <= low || middle >= high)
          break;
        (keeps(middle) ? low : high) = middle;
      }
      limit = low * low;
    }
    kept_frequency_limit = {substeps, limit};
    return limit;
  }


  unsigned int
  Simulator::choose_substeps(const physics::FrequencyBound &bound,
                             const unsigned int             current)
  {
    const physics::ParticleSystem &system = *scene->system;
    if (current > 0 && keeps_substeps(bound, current))
      return current;
    if (bound.omega == 0)
      return current > 0 ? current : 1;
    if (!std::isfinite(bound.omega))
      throw_error("The simulation blew up: the bound on the highest eigenfrequency is "
                  "not finite at ",
                  physics::describe_spring(system, bound.spring),
                  ".");
    const double critical = integrator->critical_time_step(bound.omega,
                                                           system.mass_damping,
                                                           system.spring_damping);
    std::cout << "Stability: highest eigenfrequency <= " << bound.omega
              << " rad/s (Gershgorin bound at particle " << bound.particle
              << "); critical time step " << critical << " s; time step " << time_step
              << " s\n";
    if (critical <= 0)
      throw_error(
        "No time step is stable for this integrator on this system: it amplifies "
        "every undamped oscillation. Set 'Material/Mass damping' or "
        "'Material/Spring damping' above 0, or choose another 'Integrator/Scheme'.");
    const double allowed = safety_factor * critical;
    if (time_step <= allowed)
      return 1;
    if (!substep_when_unstable)
      throw_error(
        "'Time step' = ",
        time_step,
        " s is above the stability limit ",
        critical,
        " s of the integrator (times 'Stability/Safety factor' = ",
        safety_factor,
        ": ",
        allowed,
        " s). The limit is set by ",
        physics::describe_spring(system, bound.spring),
        ". Reduce 'Time step' or set 'Stability/Time step above limit' = substep.");
    const double n_needed = std::ceil(time_step / allowed);
    if (n_needed > max_substeps)
      throw_error("The simulation blew up: 'Time step' = ",
                  time_step,
                  " s would need ",
                  n_needed,
                  " sub-steps (more than 'Stability/Maximum sub-steps' = ",
                  max_substeps,
                  ") to stay below the critical time step ",
                  critical,
                  " s, which is set by ",
                  physics::describe_spring(system, bound.spring),
                  ". A limit that small comes from a degenerate element or a particle "
                  "far off, not from the material.");
    const unsigned int n = static_cast<unsigned int>(n_needed);
    std::cout << "Stability: each step is split into " << n << " sub-steps of "
              << time_step / n << " s\n";
    return n;
  }


  void
  Simulator::print_stability_against_full_mesh() const
  {
    const physics::ParticleSystem &system   = *scene->system;
    const auto                     critical = [&](const double omega)
    {
      return integrator->critical_time_step(omega,
                                            system.mass_damping,
                                            system.spring_damping);
    };
    const double lod_omega = physics::bound_highest_frequency(system).omega;
    const scene::Scene::StabilityAtRest &full = scene->full_mesh_stability;
    std::cout << "Stability against the full mesh: critical time step "
              << critical(lod_omega) << " s on the level of detail, "
              << critical(full.omega)
              << " s on the full mesh; multi-rate stepping (each spring at its own "
                 "stable step, in powers of two) would evaluate "
              << std::setprecision(3) << 100 * physics::multirate_evaluation_share(system)
              << " % of the level of detail's springs per step (full mesh: "
              << 100 * full.multirate_share << " %)\n"
              << std::setprecision(6);
  }


  void
  Simulator::run()
  {
    start_run();
    for (step = step + 1; step <= n_steps; ++step)
    {
      const double dt         = std::min(time_step, end_time - time);
      const auto   step_start = Clock::now();
      begin_step();
      if (scene->cutter)
        move_tool(dt);
      if (scene->lacerator)
        lacerate();
      integrate(dt);
      time = (step == n_steps) ? end_time : time + dt;
      update_multiresolution();
      state.step         = step;
      state.time         = time;
      state.time_step    = dt;
      state.step_seconds = seconds_since(step_start);
      postprocess();
      report_progress();
      if (checkpoint_if_due() || (signals.stop && signals.stop()))
        break;
    }
    finish_run();
  }


  void
  Simulator::start_run()
  {
    physics::ParticleSystem &system = *scene->system;
    scene->print_summary(std::cout);
    if (scene->multiresolution)
      scene->multiresolution->print_summary(std::cout, test_mode);
    std::cout << "Integrator: "
              << "time step " << time_step << " s, end time " << end_time << " s\n";
    timer           = std::make_unique<dealii::TimerOutput>(std::cout,
                                                  dealii::TimerOutput::never,
                                                  dealii::TimerOutput::wall_times);
    state           = postprocess::RunState();
    stability_bound = std::make_unique<physics::StabilityBound>();
    stability_bound->compute(system);
    system.clear_changes();
    state.substeps = choose_substeps(stability_bound->bound());
    if (scene->multiresolution)
      print_stability_against_full_mesh();
    monitor = std::make_unique<physics::BlowUpMonitor>(system, energy_tolerance);
    check(0);
    state.mesh     = &scene->active_mesh();
    state.system   = &system;
    state.material = &scene->material;
    state.blade    = scene->cutter ? &scene->cutter->blade() : nullptr;
    step           = 0;
    time           = 0;
    steps_done     = 0;
    if (checkpoint.resume)
      resume_from_checkpoint();
    else
      postprocess();
    checkpoint.last      = Clock::now();
    const double epsilon = 1e-9 * time_step;
    n_steps = static_cast<unsigned int>(std::ceil((end_time - epsilon) / time_step));
    show_progress = !test_mode && isatty(STDERR_FILENO);
    run_start     = Clock::now();
    last_progress = 0;
    std::cout << "Running " << n_steps << " steps\n";
  }


  void
  Simulator::begin_step()
  {
    // This step's columns start at zero; what the run carries (the mesh, the blade, the
    // sub-steps, the energies last evaluated) stays.
    state.cut_tets = state.created_tets = 0;
    state.update_seconds = state.cut_step_seconds = 0;
    state.over_limit = state.tears = state.torn_tets = state.tear_created_tets = 0;
    state.tear_seconds = state.mt_update_seconds = state.integration_seconds = 0;
    state.split_fragments                                                    = 0;
    state.reextracted                                                        = false;
    state.reextraction_seconds                                               = 0;
  }


  void
  Simulator::move_tool(const double dt)
  {
    dealii::TimerOutput::Scope scope(*timer, "cut");
    std::optional<cut::Blade>  blade;
    if (signals.blade)
      blade = signals.blade(time + dt);
    change_seconds = 0;
    const cut::CutStepStatistics cut =
      scene->cut(blade ? *blade : scene->tool->blade(time + dt), time);
    state.cut_tets       = cut.cut_tets;
    state.created_tets   = cut.created_tets;
    state.update_seconds = cut.update_seconds;
    state.cut_step_seconds =
      cut.search_seconds + cut.update_seconds + cut.reinit_seconds + change_seconds;
  }


  void
  Simulator::lacerate()
  {
    dealii::TimerOutput::Scope scope(*timer, "laceration");
    change_seconds                       = 0;
    const cut::LacerationStatistics tear = scene->lacerate(time);
    state.over_limit                     = tear.over_limit;
    if (!tear.changed)
      return;
    state.tears             = 1;
    state.torn_tets         = tear.cut_tets;
    state.tear_created_tets = tear.created_tets;
    state.tear_seconds      = tear.update_seconds + change_seconds;
  }


  void
  Simulator::integrate(const double dt)
  {
    dealii::TimerOutput::Scope scope(*timer, "integration");
    physics::ParticleSystem   &system = *scene->system;
    const auto                 start  = Clock::now();
    const double               h      = dt / state.substeps;
    system.force_seconds              = 0;
    n_integrator_steps += state.substeps;
    for (unsigned int k = 0; k < state.substeps; ++k)
    {
      scene->update_loads(time + k * h);
      integrator->step(system, time + k * h, h);
    }
    state.integration_seconds = seconds_since(start);
    state.force_seconds       = system.force_seconds;
  }


  void
  Simulator::update_multiresolution()
  {
    if (!scene->multiresolution)
      return;
    if (const auto mt_cut = scene->update_multiresolution_after_cut(time))
    {
      state.split_fragments   = mt_cut->update.split_fragments;
      state.mt_update_seconds = mt_cut->update.seconds;
    }
    const auto start           = Clock::now();
    state.reextracted          = scene->update_level_of_detail(time, step, std::cout);
    state.reextraction_seconds = state.reextracted ? seconds_since(start) : 0.0;
  }


  void
  Simulator::on_system_changed(const scene::SystemChange &change)
  {
    const auto               start  = Clock::now();
    physics::ParticleSystem &system = *scene->system;
    if (mass_balancer)
    {
      // A cut or a tear is balanced locally (nothing global per cut); a change of the
      // level of detail, which renumbers particles the ledger names, as a whole.
      const physics::MassBalanceStatistics b =
        change.cause == scene::SystemChange::Cause::level_of_detail
            || system.all_particles_changed()
          ? mass_balancer->balance(system)
          : mass_balancer->rebalance(system, system.changed_particles());
      redistribution.largest_moved   = std::max(redistribution.largest_moved, b.moved);
      redistribution.last_unresolved = b.unresolved;
      ++redistribution.n_balances;
    }
    check(step);
    integrator->initialize(system);
    if (system.all_particles_changed())
    {
      // Every particle counts as changed: the blow-up monitor checks the new state
      // against its ledger at once, so that a change that puts particles far off stops
      // the run naming it, then restarts; the bound is computed anew.
      monitor->restart(system, step, change.time, change.describe());
      stability_bound->compute(system);
    }
    else
    {
      // A local change is followed locally (nothing global per cut): the changed
      // particles are checked now and the ledger restarts at the next check; the
      // bound is computed again around the changed particles.
      monitor->note_local_change(
        system, system.changed_particles(), step, change.time, change.describe());
      stability_bound->update(system, system.changed_particles());
    }
    system.clear_changes();
    state.substeps = choose_substeps(stability_bound->bound());
    state.mesh     = &scene->active_mesh();
    state.blade    = scene->cutter ? &scene->cutter->blade() : nullptr;
    change_seconds += seconds_since(start);
  }


  void
  Simulator::check(const unsigned int at_step) const
  {
    if (!check_invariants)
      return;
    const std::string problem = cut::check_invariants(scene->active_mesh(),
                                                      *scene->system,
                                                      scene->expected_volume(),
                                                      scene->integral_of_density);
    if (!problem.empty())
      throw_error("Check invariants: after step ", at_step, ": ", problem, ".");
  }


  void
  Simulator::evaluate_energies()
  {
    const physics::ParticleSystem &system = *scene->system;
    state.kinetic_energy                  = system.kinetic_energy();
    state.elastic_energy                  = system.elastic_energy();
    state.body_force_energy               = system.body_force_energy();
    state.input_work                      = monitor->input_work();
  }


  void
  Simulator::postprocess()
  {
    physics::ParticleSystem &system = *scene->system;
    bool                     writes = false, needs_energies = false;
    for (const auto &p : postprocessors)
    {
      writes |= p->writes_state(state.time);
      needs_energies |= p->needs_energies(state.time);
    }
    if (writes || step % check_interval == 0)
    {
      monitor->check(system, step, state.time);
      // The limit falls when an element collapses (the geometric stiffness of a
      // strongly compressed spring) without any change of the system. The bound with
      // the row weights kept from the last change holds at the current positions and
      // is at least the fresh one, so it decides alone while every row allows the
      // current sub-steps (the decision is then that of a fresh bound); only
      // otherwise are the weights chosen again and the bound kept.
      if (substep_when_unstable
          && !stability_bound->kept_weights_within(
            system, largest_kept_squared_frequency(state.substeps)))
      {
        stability_bound->compute(system);
        state.substeps = choose_substeps(stability_bound->bound(), state.substeps);
      }
    }
    if (needs_energies)
    {
      evaluate_energies();
      if (!std::isfinite(state.kinetic_energy + state.elastic_energy))
        monitor->check(system, step, state.time);
    }
    dealii::TimerOutput::Scope scope(*timer, "output");
    for (auto &p : postprocessors)
      p->execute(state);
    if (signals.post_step)
      signals.post_step(state);
  }


  void
  Simulator::report_progress()
  {
    steps_done                               = step;
    const unsigned int             n_reports = 10;
    const physics::ParticleSystem &system    = *scene->system;
    if (step * n_reports / n_steps != (step - 1) * n_reports / n_steps || step == n_steps)
    {
      monitor->check(system, step, time);
      evaluate_energies();
      const auto [displacement, where] = largest_displacement(system);
      std::cout << "t = " << time << " s: kinetic energy " << state.kinetic_energy
                << " J, elastic energy " << state.elastic_energy
                << " J, largest displacement " << displacement << " m (particle " << where
                << ")\n";
    }
    const double elapsed = seconds_since(run_start);
    if (show_progress && elapsed > 2 && elapsed - last_progress > 1)
    {
      last_progress = elapsed;
      std::fprintf(stderr,
                   "\rstep %u/%u  t = %.4g s  %3.0f%%  %.0f s left   ",
                   step,
                   n_steps,
                   time,
                   100.0 * step / n_steps,
                   elapsed * (n_steps - step) / step);
    }
  }


  void
  Simulator::finish_run()
  {
    const physics::ParticleSystem &system = *scene->system;
    if (show_progress && last_progress > 0)
      std::fprintf(stderr, "\n");
    std::cout << "Done: " << steps_done << " steps, " << n_integrator_steps
              << " integrator steps\n";
    if (mass_balancer && redistribution.n_balances > 0)
    {
      const double total = std::accumulate(system.mass.begin(), system.mass.end(), 0.0);
      std::cout << "Mass redistribution: " << redistribution.n_balances
                << " topology changes; at most " << redistribution.largest_moved
                << " kg away from the lumped masses at one ("
                << 100 * redistribution.largest_moved / total << " % of the mass); "
                << redistribution.last_unresolved
                << " particles above the target after the last\n";
    }
    for (auto &p : postprocessors)
      p->finish(state);
    if (!test_mode)
    {
      const double wall = seconds_since(run_start);
      std::cout << "Wall time " << wall << " s; force evaluation throughput "
                << double(system.springs.size()) * integrator->n_evaluations_per_step()
                     * n_integrator_steps / wall
                << " springs/s (whole loop)\n";
      timer->print_summary();
    }
  }


  bool
  Simulator::checkpoint_if_due()
  {
    const bool stop = checkpoint.stop_after > 0 && step >= checkpoint.stop_after;
    if (stop || (checkpoint.steps > 0 && step % checkpoint.steps == 0)
        || (checkpoint.seconds > 0
            && std::chrono::duration<double>(Clock::now() - checkpoint.last).count()
                 >= checkpoint.seconds))
      write_checkpoint();
    if (stop)
      std::cout << "Stopped after step " << step << " at t = " << time
                << " s ('Checkpoint/Stop after steps'); 'Checkpoint/Resume = true' "
                   "continues the run.\n";
    return stop;
  }


  void
  Simulator::write_checkpoint()
  {
    dealii::TimerOutput::Scope scope(*timer, "checkpoint");
    std::string                payload;
    Archive                    archive(payload);
    archive.section("parameters");
    archive &checkpoint.parameters;
    serialize(archive);
    write_checkpoint_file(checkpoint.file, payload);
    checkpoint.last = Clock::now();
  }


  void
  Simulator::resume_from_checkpoint()
  {
    std::string payload, file = checkpoint.file;
    try
    {
      payload = read_checkpoint_file(file);
    }
    catch (const Error &last)
    {
      // A checkpoint damaged on the disk: the one before it was kept for this.
      const std::string previous = checkpoint.file + ".previous";
      if (!std::filesystem::exists(previous))
        throw;
      std::cout << last.what() << " Resuming from the previous checkpoint.\n";
      file    = previous;
      payload = read_checkpoint_file(file);
    }
    Archive archive(payload, file);
    archive.section("parameters");
    std::string written;
    archive    &written;
    if (written != checkpoint.parameters)
    {
      // Name the first entry that differs.
      std::istringstream a(written), b(checkpoint.parameters);
      std::string        line_a, line_b;
      while (std::getline(a, line_a) && std::getline(b, line_b) && line_a == line_b)
        ;
      throw_error("Checkpoint: '",
                  file,
                  "' was written with other parameters: '",
                  line_a,
                  "' where this run has '",
                  line_b,
                  "'. Only 'End time', 'Output directory' and 'subsection Checkpoint' "
                  "may change when a run is resumed.");
    }
    serialize(archive);
    archive.finish();
    std::cout << "Resumed from " << file << " after step " << step << ", t = " << time
              << " s\n";
  }


  void
  Simulator::serialize(Archive &archive)
  {
    archive.section("simulator");
    archive(step, time, n_integrator_steps, redistribution);
    archive(state.step, state.time, state.time_step, state.substeps);
    archive(state.kinetic_energy, state.elastic_energy, state.body_force_energy);
    archive(state.input_work);
    archive &*scene;
    // The integrator's scratch space follows the loaded system, as after any change;
    // what it carries between steps is then read into it.
    if (archive.loading())
      integrator->initialize(*scene->system);
    archive(*integrator, monitor, stability_bound, mass_balancer);
    archive.section("postprocessors");
    for (auto &p : postprocessors)
      p->serialize(archive);
    steps_done = step;
  }
} // namespace lacerta
