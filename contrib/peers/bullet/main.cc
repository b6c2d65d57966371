// lacerta-peer-bullet: Bullet 3.24's implicit corotated FEM on the study's cantilever
// meshes, with the study's reference and error measure (contrib/peers/bullet/README.md).

#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/fem/elasticity.h>
#include <lacerta/fem/nodal_field.h>
#include <lacerta/fem/scene_problem.h>
#include <lacerta/fem/study.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>

#include "bullet_peer.h"
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
  using namespace lacerta;

  constexpr const char *usage =
    "Usage: lacerta-peer-bullet <study.prm> [--output file.csv] [--time-step s[,s...]]\n"
    "                           [--mass-damping c] [--max-steps n]\n"
    "Runs Bullet 3.24's implicit corotated FEM on the meshes of the static study in\n"
    "<study.prm> (Study/Refinements), stepping from rest until no node moves more than\n"
    "1e-8 of the largest displacement in a step, and measures its error against the\n"
    "study's FEM P2 reference. Defaults: --time-step 0.01 (a list runs each),\n"
    "--mass-damping the scene's Material/Mass damping (1/s), --max-steps 20000,\n"
    "--output <Output directory>/peer_bullet.csv.\n";

  /// The command line.
  struct Options
  {
    std::string                   parameter_file, output;
    peers::bullet::BulletSettings settings;
    /// The time steps to run, each with the other settings.
    std::vector<double> time_steps = {1e-2};
  };


  /// A positive (or, with @p zero_allowed, non-negative) number from the command line,
  /// or an Error naming the option.
  double
  positive_number(const std::string &option,
                  const std::string &text,
                  const bool         zero_allowed = false)
  {
    std::size_t end   = 0;
    double      value = 0;
    try
    {
      value = std::stod(text, &end);
    }
    catch (const std::exception &)
    {
      end = 0;
    }
    if (end != text.size() || !(value > 0 || (zero_allowed && value == 0)))
      throw_error("lacerta-peer-bullet: ",
                  option,
                  zero_allowed ? " needs a number >= 0" : " needs a positive number",
                  ", not '",
                  text,
                  "'.");
    return value;
  }


  Options
  parse_command_line(const std::vector<std::string> &arguments)
  {
    Options options;
    for (std::size_t k = 0; k < arguments.size(); ++k)
    {
      const std::string &a = arguments[k];
      if (a.rfind("--", 0) != 0)
      {
        if (!options.parameter_file.empty())
          throw_error("lacerta-peer-bullet: one parameter file, not '",
                      options.parameter_file,
                      "' and '",
                      a,
                      "'.\n",
                      usage);
        options.parameter_file = a;
        continue;
      }
      if (k + 1 == arguments.size())
        throw_error("lacerta-peer-bullet: ", a, " needs a value.\n", usage);
      const std::string &value = arguments[++k];
      if (a == "--output")
        options.output = value;
      else if (a == "--time-step")
      {
        options.time_steps.clear();
        for (const std::string &step : dealii::Utilities::split_string_list(value))
          options.time_steps.push_back(positive_number(a, step));
        if (options.time_steps.empty())
          throw_error("lacerta-peer-bullet: --time-step needs at least one step.");
      }
      else if (a == "--mass-damping")
        options.settings.mass_damping = positive_number(a, value, true);
      else if (a == "--max-steps")
        options.settings.max_steps = static_cast<unsigned int>(positive_number(a, value));
      else
        throw_error("lacerta-peer-bullet: unknown option '", a, "'.\n", usage);
    }
    if (options.parameter_file.empty())
      throw_error("lacerta-peer-bullet: no parameter file.\n", usage);
    return options;
  }


  /// The study's reference: FEM P2 on the scene refined `Reference refinement` times.
  struct Reference
  {
    std::unique_ptr<scene::Scene> scene;
    fem::NodalField               field;
  };


  Reference
  compute_reference(dealii::ParameterHandler &prm, const unsigned int refinement)
  {
    Reference reference;
    reference.scene = fem::make_study_scene(prm, refinement, "springs");
    fem::ElasticitySolver solver(fem::problem_from_scene(*reference.scene),
                                 fem::study_reference_parameters());
    reference.field = solver.solve_static(prm.get_double("End time"));
    std::cout << "Reference: FEM P2 on " << reference.scene->mesh.n_tets()
              << " tetrahedra, " << solver.n_dofs() << " dofs\n";
    return reference;
  }


  /// One peer row of the study's table (with its Poisson ratio) and Bullet's run.
  struct PeerRow
  {
    fem::StudyRow               row;
    peers::bullet::BulletResult run;
  };


  /// Runs Bullet on the study's mesh of @p refinement and measures its error.
  PeerRow
  run_refinement(dealii::ParameterHandler            &prm,
                 const unsigned int                   refinement,
                 const Reference                     &reference,
                 const peers::bullet::BulletSettings &settings)
  {
    const double             end_time = prm.get_double("End time");
    auto                     scene    = fem::make_study_scene(prm, refinement, "springs");
    physics::ParticleSystem &system   = *scene->system;
    scene->update_loads(end_time);
    system.enforce_constraints(end_time, system.position.data(), system.velocity.data());

    PeerRow peer;
    peer.run =
      peers::bullet::solve_with_bullet(peers::bullet::input_from_scene(*scene), settings);
    if (!peer.run.settled)
      throw_error("lacerta-peer-bullet: Bullet did not settle on ",
                  scene->mesh.n_tets(),
                  " tetrahedra in ",
                  peer.run.steps,
                  " steps of ",
                  settings.time_step,
                  " s (the last step moved a node by ",
                  peer.run.last_change,
                  " of the largest displacement); raise --max-steps or the time step.");
    const fem::NodalError error = fem::nodal_error(
      peer.run.displacement,
      fem::evaluate(reference.scene->mesh, reference.field, scene->mesh.get_vertices()));

    std::ostringstream dt, nu;
    dt << settings.time_step;
    nu << scene->material.poisson_ratio;
    peer.row.model      = "bullet corotated";
    peer.row.integrator = "bullet implicit";
    peer.row.variant    = "bullet_corotated_x" + std::to_string(refinement)
                       + "_bullet_implicit_dt=" + dt.str() + "_nu=" + nu.str();
    peer.row.tets          = scene->mesh.n_tets();
    peer.row.time_step     = settings.time_step;
    peer.row.wall_time     = peer.run.wall_time;
    peer.row.error_l2      = error.relative_l2();
    peer.row.error_max     = error.relative_max();
    peer.row.poisson_ratio = scene->material.poisson_ratio;
    return peer;
  }


  /// A line of the table, as the study prints its rows, with the steps taken.
  void
  print_row(const PeerRow &p)
  {
    std::cout << "  " << std::left << std::setw(44) << p.row.variant << " tets "
              << std::setw(7) << p.row.tets << " error L2 " << std::setw(10)
              << p.row.error_l2 << " max " << std::setw(10) << p.row.error_max << " wall "
              << p.row.wall_time << " s, " << p.run.steps << " steps"
              << (p.run.settled ? "" : ", NOT settled") << " (last change "
              << p.run.last_change << ")\n";
  }


  void
  write_csv(const std::string &file_name, const std::vector<PeerRow> &rows)
  {
    std::ostringstream file;
    file << "variant,model,tets,integrator,time_step,wall_time_s,error_rel_l2,error_max,"
            "poisson_ratio\n"
         << std::setprecision(8);
    for (const auto &peer : rows)
    {
      const fem::StudyRow &r = peer.row;
      file << r.variant << ',' << r.model << ',' << r.tets << ',' << r.integrator << ','
           << r.time_step << ',' << r.wall_time << ',' << r.error_l2 << ',' << r.error_max
           << ',' << r.poisson_ratio << '\n';
    }
    write_file_atomically(file_name, file.str());
  }


  int
  run(const Options &options)
  {
    dealii::ParameterHandler prm;
    Simulator::read_parameters(options.parameter_file, prm);
    if (prm.get("Mode") != "study")
      throw_error("lacerta-peer-bullet: '",
                  options.parameter_file,
                  "' is not a study (set Mode = study, as in "
                  "prm/cantilever_accuracy.prm).");
    const std::string output_directory = prm.get("Output directory");
    prm.enter_subsection("Study");
    const bool             dynamic     = prm.get("Analysis") != "static";
    const std::vector<int> refinements = dealii::Utilities::string_to_int(
      dealii::Utilities::split_string_list(prm.get("Refinements")));
    const unsigned int reference_refinement = prm.get_integer("Reference refinement");
    prm.leave_subsection();
    if (dynamic)
      throw_error("lacerta-peer-bullet: '",
                  options.parameter_file,
                  "' asks for a dynamic study; the Bullet peer computes the static "
                  "equilibrium only (Study/Analysis = static).");
    // The study's Poisson ratio sweep (empty: the scene's ratio), each ν with its own
    // reference, as the study runs it.
    prm.enter_subsection("Study");
    std::vector<double> ratios = dealii::Utilities::string_to_double(
      dealii::Utilities::split_string_list(prm.get("Poisson ratios")));
    prm.leave_subsection();
    prm.enter_subsection("Material");
    if (ratios.empty())
      ratios.push_back(prm.get_double("Poisson ratio"));
    prm.leave_subsection();

    std::vector<PeerRow> rows;
    for (const double nu : ratios)
    {
      prm.enter_subsection("Material");
      prm.set("Poisson ratio", nu);
      prm.leave_subsection();
      const Reference reference = compute_reference(prm, reference_refinement);
      for (const int refinement : refinements)
        for (const double dt : options.time_steps)
        {
          peers::bullet::BulletSettings settings = options.settings;
          settings.time_step                     = dt;
          rows.push_back(run_refinement(prm, refinement, reference, settings));
          print_row(rows.back());
        }
    }

    const std::string csv =
      options.output.empty() ? output_directory + "/peer_bullet.csv" : options.output;
    if (options.output.empty())
      create_output_directory(output_directory);
    write_csv(csv, rows);
    std::cout << "Wrote " << csv << "\n";
    return 0;
  }
} // namespace


int
main(int argc, char **argv)
{
  dealii::Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  dealii::deal_II_exceptions::disable_abort_on_exception();
  dealii::deal_II_exceptions::suppress_stacktrace_in_exceptions();
  const std::vector<std::string> arguments(argv + 1, argv + argc);
  if (!arguments.empty() && (arguments[0] == "--help" || arguments[0] == "-h"))
  {
    std::cout << usage;
    return 0;
  }
  return lacerta::run_reporting_errors([&]
                                       { return run(parse_command_line(arguments)); });
}
