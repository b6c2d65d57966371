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
#include <numeric>
#include <sstream>
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
    prm.declare_entry("Number of threads",
                      "1",
                      dealii::Patterns::Integer(1, 256),
                      "Threads for the force evaluation.");
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
      "false",
      dealii::Patterns::Bool(),
      "After every topology change (a cut, a tear, a new level of detail), raise the "
      "mass of each free particle whose Gershgorin bound at rest exceeds the bound of "
      "the system at the start, taking it from particles joined to it by springs "
      "(the mass of every piece stays the integral of the density over it), when the "
      "particles within reach can spare it. Small cells next to a cut then do not "
      "lower the critical time step (doc/stability.md). Off by default: it changes "
      "the dynamics near a cut, and the cutter still judges crossings where the "
      "tissue is. false: masses are the lumped integrals of the density.");
    prm.declare_entry("Redistribution reach",
                      "3",
                      dealii::Patterns::Integer(1, 8),
                      "How many springs away 'Mass redistribution' may take mass from.");
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

    create_output_directory(output_directory);
    std::ostringstream copy;
    copy << "# Parameters used by lacerta for " << parameter_file << "\n";
    prm.print_parameters(copy, dealii::ParameterHandler::ShortPRM);
    write_file_atomically(output_directory + "/parameters.prm", copy.str());

    scene          = std::make_unique<scene::Scene>(prm, n_threads);
    integrator     = physics::Integrator::create(prm);
    postprocessors = postprocess::Postprocessor::create(prm);
    if (redistribute_mass)
      mass_balancer =
        std::make_unique<physics::MassBalancer>(*scene->system, redistribution_reach);
    integrator->initialize(*scene->system);
    for (auto &p : postprocessors)
      p->initialize(output_directory, test_mode);
  }


  Simulator::~Simulator() = default;


  unsigned int
  Simulator::choose_substeps(const unsigned int current)
  {
    const physics::ParticleSystem &system = *scene->system;
    const physics::FrequencyBound  bound  = physics::bound_highest_frequency(system);
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
    if (current > 0 && time_step / current <= safety_factor * critical)
      return current;
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
    dealii::TimerOutput      timer(std::cout,
                              dealii::TimerOutput::never,
                              dealii::TimerOutput::wall_times);
    physics::ParticleSystem &system = *scene->system;
    scene->print_summary(std::cout);
    if (scene->multiresolution)
      scene->multiresolution->print_summary(std::cout, test_mode);
    std::cout << "Integrator: "
              << "time step " << time_step << " s, end time " << end_time << " s\n";
    unsigned int substeps = choose_substeps();
    if (scene->multiresolution)
      print_stability_against_full_mesh();

    physics::BlowUpMonitor monitor(system, energy_tolerance);
    const auto             check = [&](const unsigned int step)
    {
      if (!check_invariants)
        return;
      const std::string problem = cut::check_invariants(scene->active_mesh(),
                                                        system,
                                                        scene->expected_volume(),
                                                        scene->integral_of_density);
      if (!problem.empty())
        throw_error("Check invariants: after step ", step, ": ", problem, ".");
    };
    check(0);
    // The paper's Table 1, averaged over the steps that cut.
    unsigned int       cutting_steps      = 0;
    unsigned long long n_integrator_steps = 0;
    double             sum_cut = 0, sum_created = 0, sum_update = 0, sum_relax = 0;
    unsigned int       n_tears = 0, n_torn = 0, n_tear_created = 0;
    double             sum_tear = 0;
    // The paper's Table 2 on a multiresolution model: the cutter's work on the level of
    // detail during a stroke (CuT, CrT, TetUp), then the MT update after it (SF,
    // MT-DAGUpd); per stroke and summed over the run.
    unsigned int stroke_cut = 0, stroke_created = 0, n_mt_updates = 0;
    double       stroke_update         = 0;
    unsigned int total_split_fragments = 0, total_mt_cut = 0, total_mt_created = 0;
    double       total_tet_update = 0, total_mt_update = 0;
    postprocess::RunState state;
    state.mesh     = &scene->active_mesh();
    state.system   = &system;
    state.material = &scene->material;
    state.blade    = scene->cutter ? &scene->cutter->blade() : nullptr;
    state.substeps = substeps;

    // After a topology change or a new level of detail the particles and springs are
    // others: the integrator's scratch space and the stability limit start afresh (the
    // invariants are checked first if @p check_now). The blow-up monitor checks the new
    // state against its ledger at once, so that a change that puts particles far off
    // stops the run naming it (@p cause), then restarts its ledger.
    // Mass redistribution over the run: the most mass held away from the lumped masses
    // at one change (each redistribution starts afresh from them), and the particles
    // left above the target at the last one.
    double       largest_moved   = 0;
    unsigned int last_unresolved = 0, n_balances = 0;
    const auto   system_changed = [&](const unsigned int step,
                                    const double       at,
                                    const bool         check_now,
                                    const std::string &cause)
    {
      if (mass_balancer)
      {
        const physics::MassBalanceStatistics b = mass_balancer->balance(system);
        largest_moved                          = std::max(largest_moved, b.moved);
        last_unresolved                        = b.unresolved;
        ++n_balances;
      }
      if (check_now)
        check(step);
      integrator->initialize(system);
      monitor.restart(system, step, at, cause);
      substeps = state.substeps = choose_substeps();
      state.mesh                = &scene->active_mesh();
    };
    const auto evaluate_energies = [&]
    {
      state.kinetic_energy    = system.kinetic_energy();
      state.elastic_energy    = system.elastic_energy();
      state.body_force_energy = system.body_force_energy();
      state.input_work        = monitor.input_work();
    };
    const auto postprocess = [&](const unsigned int step)
    {
      bool writes = false, needs_energies = false;
      for (const auto &p : postprocessors)
      {
        writes |= p->writes_state(state.time);
        needs_energies |= p->needs_energies(state.time);
      }
      if (writes || step % check_interval == 0)
      {
        monitor.check(system, step, state.time);
        // The limit falls when an element collapses (the geometric stiffness of a
        // strongly compressed spring) without any change of the system: keeping the
        // sub-steps chosen at the last change let the severed kidney pole blow up.
        if (substep_when_unstable)
          substeps = state.substeps = choose_substeps(substeps);
      }
      if (needs_energies)
      {
        evaluate_energies();
        if (!std::isfinite(state.kinetic_energy + state.elastic_energy))
          monitor.check(system, step, state.time);
      }
      dealii::TimerOutput::Scope scope(timer, "output");
      for (auto &p : postprocessors)
        p->execute(state);
      if (signals.post_step)
        signals.post_step(state);
    };

    postprocess(0);
    const double       epsilon = 1e-9 * time_step;
    const unsigned int n_steps =
      static_cast<unsigned int>(std::ceil((end_time - epsilon) / time_step));
    const unsigned int n_reports     = 10;
    const bool         show_progress = !test_mode && isatty(STDERR_FILENO);
    const auto         run_start     = Clock::now();
    double             last_progress = 0;
    std::cout << "Running " << n_steps << " steps\n";

    double       time       = 0;
    unsigned int steps_done = 0;
    for (unsigned int step = 1; step <= n_steps; ++step)
    {
      const double dt         = std::min(time_step, end_time - time);
      const auto   step_start = Clock::now();
      state.cut_tets = state.created_tets = 0;
      state.update_seconds = state.cut_step_seconds = 0;
      state.over_limit = state.tears = state.torn_tets = state.tear_created_tets = 0;
      state.tear_seconds                                                         = 0;
      state.split_fragments                                                      = 0;
      state.mt_update_seconds                                                    = 0;
      bool cut_changed                                                           = false;
      if (scene->cutter)
      {
        dealii::TimerOutput::Scope scope(timer, "cut");
        std::optional<cut::Blade>  blade;
        if (signals.blade)
          blade = signals.blade(time + dt);
        const cut::CutStepStatistics cut =
          scene->cutter->move_blade(blade ? *blade : scene->tool->blade(time + dt));
        state.cut_tets       = cut.cut_tets;
        state.created_tets   = cut.created_tets;
        state.update_seconds = cut.update_seconds;
        state.cut_step_seconds =
          cut.search_seconds + cut.update_seconds + cut.reinit_seconds;
        cut_changed = cut.changed;
        stroke_cut += cut.cut_tets;
        stroke_created += cut.created_tets;
        stroke_update += cut.update_seconds;
        if (cut.changed)
        {
          // The constraints take over the copies of their particles.
          scene->follow_cut(cut.copied_particles);
          system_changed(step, time, true, "the cut");
        }
      }
      if (scene->lacerator)
      {
        dealii::TimerOutput::Scope scope(timer, "laceration");
        if (cut_changed)
          scene->lacerator->mesh_changed();
        const cut::LacerationStatistics tear = scene->lacerator->check();
        state.over_limit                     = tear.over_limit;
        if (tear.changed)
        {
          state.tears             = 1;
          state.torn_tets         = tear.cut_tets;
          state.tear_created_tets = tear.created_tets;
          state.tear_seconds      = tear.update_seconds;
          ++n_tears;
          n_torn += tear.cut_tets;
          n_tear_created += tear.created_tets;
          sum_tear += tear.update_seconds;
          // On a multiresolution model the tear's split goes to the MT like a stroke's
          // (doc/lacerations.md): Table 2's CuT, CrT and TetUp include it.
          stroke_cut += tear.cut_tets;
          stroke_created += tear.created_tets;
          stroke_update += tear.update_seconds;
          std::cout << "Laceration at t = " << time + dt
                    << " s: " << (tear.continued ? "continued" : "started")
                    << " at the spring " << tear.seed_a << "-" << tear.seed_b << " ("
                    << tear.seed_ratio << " times its maximum elongation, "
                    << tear.over_limit << " surface springs past their limit); "
                    << tear.advances << " advances, "
                    << (tear.complete ? "through" : "stopped inside") << "; "
                    << tear.cut_tets << " tetrahedra split into " << tear.created_tets
                    << "; mesh components "
                    << cut::count_components(scene->active_mesh());
          if (!test_mode)
            std::cout << "; " << 1e3 * tear.update_seconds << " ms";
          std::cout << "\n";
          // As after a cut; the scalpel's search structures must see the torn faces.
          scene->follow_cut(tear.copied_particles);
          scene->restart_cutter();
          system_changed(step, time, true, "the laceration");
        }
      }
      const auto   relax_start = Clock::now();
      const double h           = dt / substeps;
      {
        dealii::TimerOutput::Scope scope(timer, "integration");
        system.force_seconds = 0;
        n_integrator_steps += substeps;
        for (unsigned int k = 0; k < substeps; ++k)
        {
          scene->update_loads(time + k * h);
          integrator->step(system, time + k * h, h);
        }
      }
      if (state.cut_tets > 0)
      {
        ++cutting_steps;
        sum_cut += state.cut_tets;
        sum_created += state.created_tets;
        sum_update += state.update_seconds;
        sum_relax += seconds_since(relax_start);
      }
      time = (step == n_steps) ? end_time : time + dt;
      if (const auto mt_cut = scene->update_multiresolution_after_cut(time))
      {
        // The simulation moves to the MT's version of the cut level of detail: new
        // particles and springs, as after a re-extraction.
        ++n_mt_updates;
        state.split_fragments   = mt_cut->update.split_fragments;
        state.mt_update_seconds = mt_cut->update.seconds;
        total_split_fragments += mt_cut->update.split_fragments;
        total_mt_cut += mt_cut->update.cut_tets;
        total_mt_created += mt_cut->update.created_tets;
        total_tet_update += stroke_update;
        total_mt_update += mt_cut->update.seconds;
        std::cout << "MT update after the stroke at t = " << time << " s: SF "
                  << mt_cut->update.split_fragments << ", CuT " << stroke_cut << ", CrT "
                  << stroke_created;
        if (!test_mode)
          std::cout << ", TetUp " << 1e3 * stroke_update << " ms, MT-DAGUpd "
                    << 1e3 * mt_cut->update.seconds << " ms";
        std::cout << "; MT tetrahedra cut " << mt_cut->update.cut_tets << ", created "
                  << mt_cut->update.created_tets << ", vertices added "
                  << mt_cut->update.new_vertices << "; level of detail "
                  << scene->active_mesh().n_tets() << " tetrahedra, "
                  << system.n_particles() << " particles (" << mt_cut->transfer.copied
                  << " copied, " << mt_cut->transfer.interpolated
                  << " interpolated), mass "
                  << std::accumulate(system.mass.begin(), system.mass.end(), 0.0)
                  << " kg; mesh components " << mt_cut->pieces_after
                  << " (the cutter's mesh had " << mt_cut->pieces_before << ")\n";
        stroke_cut = stroke_created = 0;
        stroke_update               = 0;
        system_changed(step, time, true, "the MT update after the stroke");
      }
      if (scene->update_level_of_detail(time, step, std::cout))
        system_changed(step, time, false, "the re-extraction of the level of detail");
      state.step = step;
      state.time = time;
      // The cutter is made anew after a tear (Scene::restart_cutter()).
      state.blade         = scene->cutter ? &scene->cutter->blade() : nullptr;
      state.time_step     = dt;
      state.step_seconds  = seconds_since(step_start);
      state.force_seconds = system.force_seconds;
      postprocess(step);
      steps_done = step;

      if (step * n_reports / n_steps != (step - 1) * n_reports / n_steps
          || step == n_steps)
      {
        monitor.check(system, step, time);
        evaluate_energies();
        const auto [displacement, where] = largest_displacement(system);
        std::cout << "t = " << time << " s: kinetic energy " << state.kinetic_energy
                  << " J, elastic energy " << state.elastic_energy
                  << " J, largest displacement " << displacement << " m (particle "
                  << where << ")\n";
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
      if (signals.stop && signals.stop())
        break;
    }
    if (show_progress && last_progress > 0)
      std::fprintf(stderr, "\n");

    std::cout << "Done: " << steps_done << " steps, " << n_integrator_steps
              << " integrator steps\n";
    if (mass_balancer && n_balances > 0)
    {
      const double total = std::accumulate(system.mass.begin(), system.mass.end(), 0.0);
      std::cout << "Mass redistribution: " << n_balances << " topology changes; at most "
                << largest_moved << " kg away from the lumped masses at one ("
                << 100 * largest_moved / total << " % of the mass); " << last_unresolved
                << " particles above the target after the last\n";
    }
    if (scene->cutter)
    {
      std::cout << "Cut summary (Table 1 columns, averages over the " << cutting_steps
                << " steps that cut): MS " << scene->active_mesh().n_tets() << ", CuT "
                << (cutting_steps ? sum_cut / cutting_steps : 0.0) << ", CrT "
                << (cutting_steps ? sum_created / cutting_steps : 0.0);
      if (!test_mode && cutting_steps > 0)
        std::cout << ", UpdT " << 1e3 * sum_update / cutting_steps << " ms, RxT "
                  << 1e3 * sum_relax / cutting_steps << " ms";
      if (scene->multiresolution)
        std::cout << "; " << n_mt_updates
                  << " MT updates (Table 2 columns: totals, times per stroke): SF "
                  << total_split_fragments << ", MT tetrahedra cut " << total_mt_cut
                  << ", created " << total_mt_created
                  << (scene->cut_pending() ? " (a stroke still waits for its update)"
                                           : "");
      if (!test_mode && n_mt_updates > 0)
        std::cout << ", TetUp " << 1e3 * total_tet_update / n_mt_updates
                  << " ms, MT-DAGUpd " << 1e3 * total_mt_update / n_mt_updates << " ms";
      // The pieces' rest volumes show what a cut separated (a punched hole).
      const std::vector<double> pieces = cut::component_volumes(scene->active_mesh());
      std::cout << "; mesh components " << pieces.size() << ", rest volumes (m^3)";
      for (const double v : pieces)
        std::cout << " " << v;
      std::cout << "\n";
    }
    if (scene->lacerator)
    {
      std::cout << "Laceration summary: " << n_tears << " tears, " << n_torn
                << " tetrahedra split into " << n_tear_created;
      if (!test_mode && n_tears > 0)
        std::cout << ", " << 1e3 * sum_tear / n_tears << " ms per tear";
      std::cout << "; mesh " << scene->active_mesh().n_tets()
                << " tetrahedra, components "
                << cut::count_components(scene->active_mesh()) << "\n";
    }
    if (!test_mode)
    {
      const double wall = seconds_since(run_start);
      std::cout << "Wall time " << wall << " s; force evaluation throughput "
                << double(system.springs.size()) * integrator->n_evaluations_per_step()
                     * n_integrator_steps / wall
                << " springs/s (whole loop)\n";
      timer.print_summary();
    }
  }
} // namespace lacerta
