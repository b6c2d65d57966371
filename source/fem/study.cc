#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/fem/elasticity.h>
#include <lacerta/fem/scene_problem.h>
#include <lacerta/fem/spring_statics.h>
#include <lacerta/fem/study.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/scene/scene.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#ifndef LACERTA_PYTHON
#define LACERTA_PYTHON "python3"
#endif
#ifndef LACERTA_PLOT_SCRIPT
#define LACERTA_PLOT_SCRIPT "contrib/plot/plot_study.py"
#endif

namespace lacerta::fem
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /// Displacements of a variant at the sample times, 3 per vertex per sample.
    using Samples = std::vector<std::vector<double>>;

    /// The force model of a study model of particles.
    std::string
    force_model_of(const std::string &model)
    {
      return model == "volume springs" || model == "corotated fem" ? model
                                                                   : "linear springs";
    }


    std::vector<double>
    displacement_of(const physics::ParticleSystem &system)
    {
      std::vector<double> u(system.position.size());
      for (std::size_t k = 0; k < u.size(); ++k)
        u[k] = system.position[k] - system.rest_position()[k];
      return u;
    }


    /// Runs an explicit integrator from rest, recording the samples (sub-stepping as
    /// the Simulator does when the step is above the stability limit).
    Samples
    run_explicit(dealii::ParameterHandler  &prm,
                 scene::Scene              &scene,
                 const std::string         &scheme,
                 const double               dt,
                 const std::vector<double> &sample_times)
    {
      prm.enter_subsection("Integrator");
      const std::string old_scheme = prm.get("Scheme");
      prm.set("Scheme", scheme);
      prm.leave_subsection();
      auto integrator = physics::Integrator::create(prm);
      prm.enter_subsection("Integrator");
      prm.set("Scheme", old_scheme);
      prm.leave_subsection();

      physics::ParticleSystem &system = *scene.system;
      integrator->initialize(system);
      const physics::FrequencyBound bound    = physics::bound_highest_frequency(system);
      const double                  critical = integrator->critical_time_step(bound.omega,
                                                             system.mass_damping,
                                                             system.spring_damping);
      if (!(critical > 0))
        throw_error("Study: integrator '", scheme, "' has no stable time step here.");
      const unsigned int substeps =
        std::max(1u, static_cast<unsigned int>(std::ceil(dt / (0.9 * critical))));
      Samples samples;
      double  t = 0;
      for (const double sample : sample_times)
      {
        while (t < sample - 1e-9 * dt)
        {
          const double step = std::min(dt, sample - t), h = step / substeps;
          for (unsigned int k = 0; k < substeps; ++k)
          {
            scene.update_loads(t + k * h);
            integrator->step(system, t + k * h, h);
          }
          t += step;
        }
        samples.push_back(displacement_of(system));
      }
      return samples;
    }


    /// FEM by Newmark with step dt, recording the (vertex) samples.
    std::vector<NodalField>
    run_newmark(ElasticitySolver          &solver,
                const double               dt,
                const std::vector<double> &sample_times)
    {
      std::vector<NodalField> samples;
      solver.start_dynamic(dt);
      for (const double sample : sample_times)
      {
        while (solver.time() < sample - 1e-9 * dt)
          solver.advance();
        samples.push_back(solver.displacement());
      }
      return samples;
    }


    std::string
    format(const double value)
    {
      std::ostringstream out;
      out << std::setprecision(6) << value;
      return out.str();
    }


    /// The lowest frequencies at 4 digits: the subspace iteration converges to far
    /// better than that, so the printout is the same on any number of ranks.
    void
    print_frequencies(std::ostream              &out,
                      const std::string         &label,
                      const std::vector<double> &frequencies)
    {
      out << "  frequencies [Hz] " << std::left << std::setw(27) << label
          << std::setprecision(4);
      for (const double f : frequencies)
        out << ' ' << f;
      out << std::setprecision(6) << "\n";
    }


    /// The variant's name in study.csv, blanks as underscores; @p nu < 0: not named.
    std::string
    variant_name(const std::string &model,
                 const unsigned int refinement,
                 const std::string &integrator,
                 const double       dt,
                 const double       nu)
    {
      std::string name = model + " x" + std::to_string(refinement) + " " + integrator;
      if (dt > 0)
        name += " dt=" + format(dt);
      if (nu >= 0)
        name += " nu=" + format(nu);
      for (char &c : name)
        if (c == ' ')
          c = '_';
      return name;
    }


    void
    print_row(std::ostream &out, const StudyRow &row, const bool test_mode)
    {
      out << "  " << std::left << std::setw(44) << row.variant << " tets " << std::setw(7)
          << row.tets << " error L2 " << std::setw(10) << format(row.error_l2) << " max "
          << std::setw(10) << format(row.error_max);
      if (!test_mode)
        out << " wall " << format(row.wall_time) << " s";
      out << "\n";
    }


    /// A variant's samples and the wall time it took to compute them.
    struct TimedSamples
    {
      Samples samples;
      double  seconds = 0;
    };


    /// FEM of degree @p degree on @p scene: static (dt = 0) or Newmark with step dt,
    /// timed from the solver's set-up on.
    TimedSamples
    run_fem(scene::Scene              &scene,
            const unsigned int         degree,
            const double               dt,
            const std::vector<double> &sample_times)
    {
      SolverParameters parameters;
      parameters.degree = degree;
      MPI_Barrier(MPI_COMM_WORLD);
      const auto              start = Clock::now();
      ElasticitySolver        solver(problem_from_scene(scene), parameters);
      std::vector<NodalField> fields =
        dt > 0 ? run_newmark(solver, dt, sample_times)
               : std::vector<NodalField>{solver.solve_static(sample_times.back())};
      TimedSamples timed;
      timed.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      for (const auto &field : fields)
        timed.samples.push_back(field.vertex);
      return timed;
    }


    /// A particle model on @p scene by @p integrator: 'direct' and 'relaxation' from
    /// the prescribed particles at the last sample time, an explicit integrator with
    /// step dt from rest; timed from the built scene on.
    TimedSamples
    run_particles(dealii::ParameterHandler  &prm,
                  scene::Scene              &scene,
                  const std::string         &integrator,
                  const double               dt,
                  const std::vector<double> &sample_times)
    {
      physics::ParticleSystem &system   = *scene.system;
      const double             end_time = sample_times.back();
      scene.update_loads(end_time);
      system.enforce_constraints(end_time,
                                 system.position.data(),
                                 system.velocity.data());
      const auto   start = Clock::now();
      TimedSamples timed;
      if (integrator == "direct")
        timed.samples.push_back(solve_linearised_springs(system));
      else if (integrator == "relaxation")
        timed.samples.push_back(relax_springs(system).displacement);
      else
      {
        system.position = system.rest_position();
        std::fill(system.velocity.begin(), system.velocity.end(), 0.0);
        system.enforce_constraints(0, system.position.data(), system.velocity.data());
        timed.samples = run_explicit(prm, scene, integrator, dt, sample_times);
      }
      timed.seconds = std::chrono::duration<double>(Clock::now() - start).count();
      return timed;
    }
  } // namespace


  std::unique_ptr<scene::Scene>
  make_study_scene(dealii::ParameterHandler &prm,
                   const unsigned int        factor,
                   const std::string        &model)
  {
    const bool fitted = model == "fitted springs";
    prm.enter_subsection("Mesh");
    if (prm.get("Source") != "box")
      throw_error("Study: 'Refinements' multiply 'Mesh/Box/Repetitions', so the scene "
                  "must use 'Mesh/Source' = box (it uses '",
                  prm.get("Source"),
                  "').");
    prm.enter_subsection("Box");
    const std::string base = prm.get("Repetitions");
    std::string       refined;
    for (const int n :
         dealii::Utilities::string_to_int(dealii::Utilities::split_string_list(base)))
      refined += (refined.empty() ? "" : ", ") + std::to_string(n * factor);
    prm.set("Repetitions", refined);
    prm.leave_subsection();
    prm.leave_subsection();
    prm.enter_subsection("Material");
    const std::string stiffness = prm.get("Spring stiffness");
    prm.set("Spring stiffness", fitted ? "fitted" : "paper");
    prm.leave_subsection();
    prm.enter_subsection("Force model");
    const std::string force_model = prm.get("Model");
    prm.set("Model", force_model_of(model));
    prm.leave_subsection();

    auto scene = std::make_unique<scene::Scene>(prm, 1);

    prm.enter_subsection("Force model");
    prm.set("Model", force_model);
    prm.leave_subsection();

    prm.enter_subsection("Mesh");
    prm.enter_subsection("Box");
    prm.set("Repetitions", base);
    prm.leave_subsection();
    prm.leave_subsection();
    prm.enter_subsection("Material");
    prm.set("Spring stiffness", stiffness);
    prm.leave_subsection();
    return scene;
  }


  SolverParameters
  study_reference_parameters()
  {
    SolverParameters p2;
    p2.degree    = 2;
    p2.tolerance = 1e-11;
    return p2;
  }


  void
  Study::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Study");
    prm.declare_entry(
      "Analysis",
      "static",
      dealii::Patterns::Selection("static|dynamic"),
      "'static': the equilibrium under the scene's loads and constraints at 'End "
      "time'; 'dynamic': the motion from rest, compared at 'Number of samples' times.");
    prm.declare_entry(
      "Refinements",
      "1, 2",
      dealii::Patterns::List(dealii::Patterns::Integer(1, 16), 1, 16, ","),
      "Mesh resolutions of the variants, as factors on "
      "'Mesh/Box/Repetitions' (the scene must use the box source).");
    prm.declare_entry(
      "Models",
      "springs, fitted springs, fem p1, fem p2",
      dealii::Patterns::MultipleSelection(
        "springs|fitted springs|volume springs|corotated fem|fem p1|fem p2"),
      "Models of the variants: the paper's springs (k = E V/|e|^2), "
      "springs fitted to linear elasticity, the force models 'volume "
      "springs' and 'corotated fem' (with the scene's 'Force model' "
      "subsection for their parameters), FEM of degree 1 or 2.");
    prm.declare_entry(
      "Integrators",
      "direct, relaxation",
      dealii::Patterns::List(dealii::Patterns::Anything(), 1, 16, ","),
      "How the spring variants are solved: 'direct' (sparse solve of the linearised "
      "springs, static only), 'relaxation' (damped dynamic relaxation of the explicit "
      "model, static only), or the name of an explicit integrator ('Integrator/Scheme'), "
      "run from rest to 'End time' with each of 'Time steps'. FEM variants use CG-AMG "
      "(static) or Newmark with each of 'Time steps' (dynamic).");
    prm.declare_entry(
      "Time steps",
      "0",
      dealii::Patterns::List(dealii::Patterns::Double(0, 10), 1, 16, ","),
      "Time steps [s] of the time-stepping variants; 0 is the scene's "
      "'Time step'. They should divide 'End time' / 'Number of samples'.");
    prm.declare_entry("Reference refinement",
                      "2",
                      dealii::Patterns::Integer(1, 32),
                      "The reference is FEM P2 on the mesh refined this many times.");
    prm.declare_entry("Reference time step",
                      "0",
                      dealii::Patterns::Double(0, 10),
                      "Newmark time step [s] of the dynamic reference; 0 is half the "
                      "smallest of 'Time steps'.");
    prm.declare_entry("Number of samples",
                      "10",
                      dealii::Patterns::Integer(1, 10000),
                      "Dynamic analysis: the errors are taken over the nodes at this "
                      "many equally spaced times up to 'End time'.");
    prm.declare_entry("Number of frequencies",
                      "0",
                      dealii::Patterns::Integer(0, 20),
                      "How many of the lowest vibration frequencies (Hz, prescribed "
                      "vertices held) to print for the reference and for every model "
                      "and refinement: the springs linearised at rest against FEM. "
                      "0: none.");
    prm.declare_entry(
      "Poisson ratios",
      "",
      dealii::Patterns::List(dealii::Patterns::Double(0.0, 0.499), 0, 16, ","),
      "Run every variant and the reference at each of these Poisson ratios in turn, in "
      "place of 'Material/Poisson ratio' (the same range), the reference recomputed "
      "for each; study.csv's column poisson_ratio and one panel of study.png per "
      "ratio. Empty: the scene's 'Material/Poisson ratio' only.");
    prm.declare_entry("Plot",
                      "true",
                      dealii::Patterns::Bool(),
                      "Write study.png (log-log error against run time, Pareto front "
                      "marked) with python3 and matplotlib.");
    prm.declare_entry("Plot script",
                      LACERTA_PLOT_SCRIPT,
                      dealii::Patterns::FileName(),
                      "The script that turns study.csv into study.png.");
    prm.leave_subsection();
  }


  Study::Study(dealii::ParameterHandler &prm_in)
      : prm(prm_in)
  {
    output_directory = prm.get("Output directory");
    test_mode        = prm.get_bool("Test mode");
    prm.enter_subsection("Study");
    dynamic = prm.get("Analysis") == "dynamic";
    for (const int r : dealii::Utilities::string_to_int(
           dealii::Utilities::split_string_list(prm.get("Refinements"))))
      refinements.push_back(r);
    models      = dealii::Utilities::split_string_list(prm.get("Models"));
    integrators = dealii::Utilities::split_string_list(prm.get("Integrators"));
    time_steps  = dealii::Utilities::string_to_double(
      dealii::Utilities::split_string_list(prm.get("Time steps")));
    reference_refinement = prm.get_integer("Reference refinement");
    reference_time_step  = prm.get_double("Reference time step");
    n_samples            = prm.get_integer("Number of samples");
    n_frequencies        = prm.get_integer("Number of frequencies");
    poisson_ratios       = dealii::Utilities::string_to_double(
      dealii::Utilities::split_string_list(prm.get("Poisson ratios")));
    plot        = prm.get_bool("Plot");
    plot_script = prm.get("Plot script");
    prm.leave_subsection();

    const double end_time = prm.get_double("End time");
    if (dynamic)
      for (unsigned int k = 1; k <= n_samples; ++k)
        sample_times.push_back(end_time * k / n_samples);
    else
      sample_times.push_back(end_time);

    const double scene_step = prm.get_double("Time step");
    for (double &dt : time_steps)
      if (dt == 0)
        dt = scene_step;
    if (reference_time_step == 0)
      reference_time_step = 0.5 * *std::min_element(time_steps.begin(), time_steps.end());
    for (const std::string &name : integrators)
      if (name != "direct" && name != "relaxation"
          && physics::IntegratorRegistry::plugins().count(name) == 0)
        throw_error("Study/Integrators: unknown '",
                    name,
                    "'. Known: direct, relaxation, ",
                    physics::IntegratorRegistry::selection_pattern(),
                    ".");
  }


  struct Study::Reference
  {
    std::unique_ptr<scene::Scene> scene;
    std::vector<NodalField>       fields;
  };


  std::vector<StudyRow>
  Study::run()
  {
    const bool    root = dealii::Utilities::MPI::this_mpi_process(MPI_COMM_WORLD) == 0;
    std::ostream  null_stream(nullptr);
    std::ostream &out = root ? std::cout : null_stream;

    prm.enter_subsection("Material");
    const std::string scene_ratio = prm.get("Poisson ratio");
    const double      scene_nu    = prm.get_double("Poisson ratio");
    prm.leave_subsection();
    std::vector<StudyRow> rows;
    for (const double nu :
         poisson_ratios.empty() ? std::vector<double>{scene_nu} : poisson_ratios)
    {
      prm.enter_subsection("Material");
      prm.set("Poisson ratio", nu);
      prm.leave_subsection();
      const std::vector<StudyRow> at_nu = run_at_poisson_ratio(nu, out);
      rows.insert(rows.end(), at_nu.begin(), at_nu.end());
    }
    prm.enter_subsection("Material");
    prm.set("Poisson ratio", scene_ratio);
    prm.leave_subsection();

    if (root)
      write_results(rows, out);
    return rows;
  }


  std::vector<StudyRow>
  Study::run_at_poisson_ratio(const double nu, std::ostream &out)
  {
    const double end_time = sample_times.back();
    Reference    reference;
    reference.scene = make_study_scene(prm, reference_refinement, "springs");
    ElasticitySolver reference_solver(problem_from_scene(*reference.scene),
                                      study_reference_parameters());
    reference.fields =
      dynamic ? run_newmark(reference_solver, reference_time_step, sample_times)
              : std::vector<NodalField>{reference_solver.solve_static(end_time)};
    out << "Study: " << (dynamic ? "dynamic" : "static")
        << " analysis; reference FEM P2 on " << reference.scene->mesh.n_tets()
        << " tetrahedra, " << reference_solver.n_dofs() << " dofs"
        << (dynamic ? ", Newmark time step " + format(reference_time_step) + " s" : "")
        << (poisson_ratios.empty() ? "" : ", Poisson ratio " + format(nu)) << "\n";
    // To solver tolerance, whatever the number of MPI ranks (a regression test runs
    // this on one and on two).
    double largest = 0;
    for (const auto &field : reference.fields)
      for (unsigned int v = 0; v < reference.scene->mesh.n_vertices(); ++v)
        largest = std::max(largest,
                           std::sqrt(field.at_vertex(v)[0] * field.at_vertex(v)[0]
                                     + field.at_vertex(v)[1] * field.at_vertex(v)[1]
                                     + field.at_vertex(v)[2] * field.at_vertex(v)[2]));
    out << "Reference: largest vertex displacement " << std::setprecision(9) << largest
        << " m" << std::setprecision(6) << "\n";
    if (n_frequencies > 0)
      print_frequencies(out,
                        "reference fem p2",
                        reference_solver.lowest_frequencies(n_frequencies));

    std::vector<StudyRow> rows;
    for (const unsigned int refinement : refinements)
      for (const std::string &model : models)
      {
        const std::vector<StudyRow> of_model =
          run_model(model, refinement, nu, reference, out);
        rows.insert(rows.end(), of_model.begin(), of_model.end());
      }
    return rows;
  }


  std::vector<StudyRow>
  Study::run_model(const std::string &model,
                   const unsigned int refinement,
                   const double       nu,
                   const Reference   &reference,
                   std::ostream      &out)
  {
    const bool         fem    = model.rfind("fem", 0) == 0;
    const unsigned int degree = model == "fem p2" ? 2 : 1;
    auto               scene  = make_study_scene(prm, refinement, model);
    if (n_frequencies > 0)
    {
      const std::string label = model + " x" + std::to_string(refinement);
      if (fem)
      {
        SolverParameters parameters;
        parameters.degree = degree;
        print_frequencies(out,
                          label,
                          ElasticitySolver(problem_from_scene(*scene), parameters)
                            .lowest_frequencies(n_frequencies));
      }
      else
        print_frequencies(out, label, spring_frequencies(*scene->system, n_frequencies));
    }
    const auto                            &vertices = scene->mesh.get_vertices();
    std::vector<std::vector<mesh::Point3>> expected;
    for (const auto &field : reference.fields)
      expected.push_back(evaluate(reference.scene->mesh, field, vertices));

    std::vector<StudyRow> rows;
    const auto            add_row =
      [&](const std::string &integrator, const double dt, const TimedSamples &timed)
    {
      NodalError error;
      for (std::size_t s = 0; s < timed.samples.size(); ++s)
        error.add(nodal_error(timed.samples[s], expected[s]));
      StudyRow row;
      row.model         = model;
      row.integrator    = integrator;
      row.tets          = scene->mesh.n_tets();
      row.time_step     = dt;
      row.wall_time     = timed.seconds;
      row.error_l2      = error.relative_l2();
      row.error_max     = error.relative_max();
      row.poisson_ratio = nu;
      row.variant =
        variant_name(model, refinement, integrator, dt, poisson_ratios.empty() ? -1 : nu);
      rows.push_back(row);
      print_row(out, row, test_mode);
    };

    if (fem)
    {
      for (const double dt : dynamic ? time_steps : std::vector<double>{0.0})
        add_row(dynamic ? "newmark" : "cg-amg",
                dt,
                run_fem(*scene, degree, dt, sample_times));
      return rows;
    }
    for (const std::string &integrator : integrators)
    {
      const bool explicit_scheme = integrator != "direct" && integrator != "relaxation";
      if (dynamic && !explicit_scheme)
        continue;
      for (const double dt : explicit_scheme ? time_steps : std::vector<double>{0.0})
      {
        auto variant = make_study_scene(prm, refinement, model);
        add_row(integrator,
                dt,
                run_particles(prm, *variant, integrator, dt, sample_times));
      }
    }
    return rows;
  }


  void
  Study::write_results(const std::vector<StudyRow> &rows, std::ostream &out) const
  {
    create_output_directory(output_directory);
    const std::string  csv = output_directory + "/study.csv";
    std::ostringstream file;
    file << "variant,model,tets,integrator,time_step,wall_time_s,error_rel_l2,error_max,"
            "poisson_ratio\n";
    file << std::setprecision(8);
    for (const auto &row : rows)
      file << row.variant << ',' << row.model << ',' << row.tets << ',' << row.integrator
           << ',' << row.time_step << ',' << (test_mode ? 0.0 : row.wall_time) << ','
           << row.error_l2 << ',' << row.error_max << ',' << row.poisson_ratio << '\n';
    write_file_atomically(csv, file.str());
    out << "Wrote " << (test_mode ? std::string("study.csv") : csv) << "\n";
    if (!plot)
      return;
    const std::string command = std::string(LACERTA_PYTHON) + " '" + plot_script + "' '"
                                + csv + "' '" + output_directory + "/study.png'";
    if (std::system(command.c_str()) != 0)
      throw_error("Study: the plot command failed: ",
                  command,
                  " (set 'Study/Plot' = false to skip the picture).");
    out << "Wrote "
        << (test_mode ? std::string("study.png") : output_directory + "/study.png")
        << "\n";
  }
} // namespace lacerta::fem
