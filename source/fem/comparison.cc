// Postprocessor `fem comparison`: the running spring model against the FEM reference
// on the same mesh, constraints and loads: integrated alongside it with Newmark, or
// solved for static equilibrium at given times on the mesh of that time (after cuts,
// the cut mesh).

#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/fem/elasticity.h>
#include <lacerta/fem/scene_problem.h>
#include <lacerta/fem/spring_statics.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/postprocess/output_schedule.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/postprocess/vtu_file.h>
#include <lacerta/scene/material.h>
#include <lacerta/scene/scene.h>
#include <lacerta/scene/system_change.h>

#include <deal.II/base/utilities.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace lacerta::fem
{
  namespace
  {
    /**
     * Measures the spring model's error against the FEM reference: relative L2 and
     * largest error over the nodes, and the displacement at probe points (nearest
     * vertex). The reference is either integrated with Newmark and the run's time step
     * and compared after every step (on the mesh of the start, so a cut or tear stops
     * the run with a message), or solved for static equilibrium at given times on the
     * mesh of that time: after a cut the FEM mesh is the cut one, every duplicated
     * particle its own FEM vertex and the crack's faces free boundaries. At the start,
     * the lowest vibration frequencies of both.
     */
    class FemComparison : public postprocess::Postprocessor
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        SolverParameters::declare_parameters(prm);
        prm.declare_entry("Probe points",
                          "",
                          dealii::Patterns::Anything(),
                          "Points [m] whose displacement is written over time, as "
                          "'x, y, z; x, y, z'; each is taken at the nearest vertex.");
        prm.declare_entry("Number of frequencies",
                          "0",
                          dealii::Patterns::Integer(0, 50),
                          "How many of the lowest vibration frequencies of the springs "
                          "and of FEM to compute and print at the start.");
        prm.declare_entry("Time between fields",
                          "0",
                          dealii::Patterns::Double(0, 1e6),
                          "Simulated time [s] between two files comparison-NNNNN.vtu "
                          "(the mesh at rest with the displacement of the springs and "
                          "of FEM at every vertex, and their difference); 0 writes "
                          "none.");
        prm.declare_entry(
          "Reference",
          "dynamic",
          dealii::Patterns::Selection("dynamic|static"),
          "'dynamic': FEM Newmark from the start alongside the run, compared after "
          "every step (it cannot follow a cut or tear: the run stops if the mesh "
          "changes). 'static': at each of 'Static comparison times', FEM's static "
          "equilibrium under the loads and prescribed motion of that time, on the mesh "
          "of that time (after a cut, the cut mesh with the crack's faces free), "
          "compared with the springs' state; meaningful once the run has settled.");
        prm.declare_entry(
          "Static comparison times",
          "",
          dealii::Patterns::List(dealii::Patterns::Double(0, 1e6), 0, 100, ","),
          "Simulated times [s], increasing, at which 'Reference = "
          "static' compares (at the first step that reaches each).");
        prm.declare_entry("Time between prints",
                          "0.05",
                          dealii::Patterns::Double(0, 1e6),
                          "Simulated time [s] between two printed error lines (the "
                          "table comparison.csv has every step).");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        parameters.parse_parameters(prm);
        for (const std::string &point :
             dealii::Utilities::split_string_list(prm.get("Probe points"), ';'))
        {
          const auto values = dealii::Utilities::split_string_list(point, ',');
          if (values.size() != 3)
            throw_error("Postprocess/Fem comparison/Probe points: '",
                        point,
                        "' is not a point 'x, y, z'.");
          probes.push_back({dealii::Utilities::string_to_double(values[0]),
                            dealii::Utilities::string_to_double(values[1]),
                            dealii::Utilities::string_to_double(values[2])});
        }
        n_frequencies  = prm.get_integer("Number of frequencies");
        field_interval = prm.get_double("Time between fields");
        fields.set_interval(field_interval);
        print_interval   = prm.get_double("Time between prints");
        static_reference = prm.get("Reference") == "static";
        static_times.clear();
        for (const std::string &t :
             dealii::Utilities::split_string_list(prm.get("Static comparison times")))
        {
          static_times.push_back(dealii::Utilities::string_to_double(t));
          if (static_times.size() > 1 && static_times.back() <= static_times.end()[-2])
            throw_error("Postprocess/Fem comparison/Static comparison times: the times "
                        "must increase, '",
                        t,
                        "' does not.");
        }
        if (static_reference && static_times.empty())
          throw_error("Postprocess/Fem comparison: 'Reference = static' needs at least "
                      "one of 'Static comparison times'.");
      }

      void
      subscribe(scene::Scene &scene) override
      {
        scene.system_changed.connect([this](const scene::SystemChange &change)
                                     { on_change(change); });
      }

      void
      initialize(const std::string &output_directory, bool) override
      {
        directory = output_directory;
        table     = OutputFile(output_directory + "/comparison.csv");
      }

      void
      execute(const postprocess::RunState &state) override
      {
        if (state.step == 0)
        {
          start(state);
          return;
        }
        if (static_reference)
        {
          if (next_static < static_times.size()
              && state.time >= static_times[next_static] - 1e-9 * state.time_step)
          {
            ++next_static;
            compare_static(state);
          }
          return;
        }
        if (!solver)
        {
          solver = std::make_unique<ElasticitySolver>(problem, parameters);
          solver->start_dynamic(state.time_step);
        }
        while (solver->time() < state.time - 1e-9 * state.time_step)
          solver->advance();
        const NodalField fem   = solver->displacement();
        const NodalError error = record(state, fem);
        total.add(error);
        if (state.time >= next_print - 1e-9 * state.time_step)
        {
          next_print += print_interval;
          std::cout << "Comparison at t = " << state.time << " s: springs against FEM P"
                    << parameters.degree << ": relative L2 " << error.relative_l2()
                    << ", max " << error.max_error << " m; over all steps so far "
                    << total.relative_l2() << "\n";
        }
      }

    private:
      /// A cut or tear changed the mesh: the Newmark reference, set up on the mesh of
      /// the start, cannot follow it (its state would have to move to the new mesh).
      void
      on_change(const scene::SystemChange &change)
      {
        if (!static_reference)
          throw_error("Postprocess/Fem comparison: ",
                      change.describe(),
                      " at t = ",
                      change.time,
                      " s changed the mesh, which the Newmark reference ('Reference = "
                      "dynamic') cannot follow; compare after the change with "
                      "'Reference = static'.");
      }

      /// Solves FEM's static equilibrium on the mesh of @p state under the loads and
      /// prescribed motion of its time, and compares the springs' state with it.
      void
      compare_static(const postprocess::RunState &state)
      {
        problem = problem_from_system(*state.mesh, *state.material, *state.system);
        ElasticitySolver solver_now(problem, parameters);
        const NodalField fem   = solver_now.solve_static(state.time);
        const NodalError error = record(state, fem);
        std::cout << "Static comparison at t = " << state.time << " s on "
                  << state.mesh->n_tets() << " tetrahedra, " << state.mesh->n_vertices()
                  << " vertices: springs against FEM P" << parameters.degree
                  << ": relative L2 " << error.relative_l2() << ", max "
                  << error.relative_max() << " of FEM's largest displacement "
                  << error.max_reference << " m\n";
      }

      /**
       * The springs' nodal error against the FEM displacement @p fem on the mesh of
       * @p state (vertex v is particle v), with a row of comparison.csv and, when due,
       * the field file.
       */
      NodalError
      record(const postprocess::RunState &state, const NodalField &fem)
      {
        const physics::ParticleSystem &system = *state.system;
        std::vector<double>            springs(system.position.size());
        for (std::size_t k = 0; k < springs.size(); ++k)
          springs[k] = system.position[k] - system.rest_position()[k];
        std::vector<mesh::Point3> expected(system.n_particles());
        for (unsigned int v = 0; v < system.n_particles(); ++v)
          expected[v] = fem.at_vertex(v);
        const NodalError error = nodal_error(springs, expected);

        std::ostringstream row;
        row << state.time << ',' << error.relative_l2() << ',' << error.max_error;
        for (const unsigned int v : probe_vertices)
          for (unsigned int d = 0; d < 3; ++d)
            row << ',' << springs[3 * v + d] << ',' << fem.vertex[3 * v + d];
        row << '\n';
        table.append(row.str());
        if (field_interval > 0 && fields.due(state.time))
        {
          write_fields(state, springs, fem.vertex);
          fields.written(state.time);
        }
        return error;
      }

      /// Writes comparison-NNNNN.vtu: the mesh at rest, the displacements @p springs
      /// and @p fem (3 per vertex) and springs - fem.
      void
      write_fields(const postprocess::RunState &state,
                   const std::vector<double>   &springs,
                   const std::vector<double>   &fem)
      {
        std::vector<double> difference(springs.size());
        for (std::size_t k = 0; k < springs.size(); ++k)
          difference[k] = springs[k] - fem[k];
        char name[64];
        std::snprintf(name, sizeof(name), "/comparison-%05u.vtu", n_fields++);
        postprocess::write_vtu_file(directory + name,
                                    *state.mesh,
                                    state.system->rest_position(),
                                    {{"springs_displacement", 3, &springs},
                                     {"fem_displacement", 3, &fem},
                                     {"springs_minus_fem", 3, &difference}},
                                    {});
      }

      void
      start(const postprocess::RunState &state)
      {
        const physics::ParticleSystem &system = *state.system;
        // The loads are those the Simulator last set on the springs (it updates them
        // before every step), so both models see the loads of the same step.
        problem = problem_from_system(*state.mesh, *state.material, system);

        for (const auto &p : probes)
        {
          unsigned int best     = 0;
          double       distance = 1e300;
          for (unsigned int v = 0; v < state.mesh->n_vertices(); ++v)
          {
            const auto  &x = state.mesh->vertex(v);
            const double d = std::hypot(x[0] - p[0], x[1] - p[1], x[2] - p[2]);
            if (d < distance)
            {
              distance = d;
              best     = v;
            }
          }
          probe_vertices.push_back(best);
        }
        std::ostringstream header;
        header << "time,error_rel_l2,error_max";
        for (unsigned int i = 0; i < probe_vertices.size(); ++i)
          for (const char *d : {"x", "y", "z"})
            header << ",probe" << i << "_springs_u" << d << ",probe" << i << "_fem_u"
                   << d;
        header << '\n';
        table.append(header.str());
        next_print = print_interval;

        if (n_frequencies > 0)
        {
          const auto springs = spring_frequencies(system, n_frequencies);
          const auto fem =
            ElasticitySolver(problem, parameters).lowest_frequencies(n_frequencies);
          std::cout << "Lowest frequencies [Hz] springs / FEM P" << parameters.degree
                    << ":";
          for (unsigned int i = 0; i < n_frequencies; ++i)
            std::cout << " " << springs[i] << "/" << fem[i];
          std::cout << "\n";
        }
      }

      /// Not resumable: the FEM reference's time integration lives in Trilinos
      /// vectors that a checkpoint does not hold.
      void
      serialize(Archive &) override
      {
        throw_error("Checkpoint: the 'fem comparison' postprocessor cannot be "
                    "checkpointed (its FEM reference is integrated in Trilinos vectors "
                    "a checkpoint does not hold); remove it from 'Postprocess/List' or "
                    "set 'Checkpoint/Steps between checkpoints' and 'Checkpoint/Seconds "
                    "between checkpoints' to 0.");
      }

      SolverParameters                  parameters;
      std::vector<mesh::Point3>         probes;
      std::vector<unsigned int>         probe_vertices;
      unsigned int                      n_frequencies  = 0;
      double                            print_interval = 0.05, next_print = 0;
      double                            field_interval = 0;
      postprocess::OutputSchedule       fields;
      unsigned int                      n_fields         = 0;
      bool                              static_reference = false;
      std::vector<double>               static_times;
      std::size_t                       next_static = 0;
      std::string                       directory;
      Problem                           problem;
      std::unique_ptr<ElasticitySolver> solver;
      NodalError                        total;
      OutputFile                        table;
    };
  } // namespace

  LACERTA_REGISTER_POSTPROCESSOR(
    FemComparison,
    "fem comparison",
    "Integrates the linear-elasticity FEM reference (Newmark, consistent mass, "
    "'subsection Fem comparison') alongside the springs with the same time step, "
    "mesh, constraints and loads, or with 'Reference = static' solves its static "
    "equilibrium at given times on the mesh of that time (after a cut, the cut mesh), "
    "and writes comparison.csv: relative L2 and largest nodal error of the springs "
    "against it after every step (or at those times), and probe displacements of "
    "both; prints the lowest vibration frequencies of both if asked.");
} // namespace lacerta::fem
