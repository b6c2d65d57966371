// Postprocessor `fem comparison`: the running spring model against the FEM reference
// integrated alongside it with Newmark, on the same mesh, constraints and loads.

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
     * Integrates the FEM reference with Newmark and the run's time step, and after
     * every step measures the spring model's error against it: relative L2 and largest
     * error over the nodes, the displacement at probe points (nearest vertex) over time;
     * at the start, the lowest vibration frequencies of both.
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
        print_interval = prm.get_double("Time between prints");
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
        const physics::ParticleSystem &system = *state.system;
        if (state.step == 0)
        {
          start(state);
          return;
        }
        if (!solver)
        {
          solver = std::make_unique<ElasticitySolver>(problem, parameters);
          solver->start_dynamic(state.time_step);
        }
        while (solver->time() < state.time - 1e-9 * state.time_step)
          solver->advance();
        const NodalField    fem = solver->displacement();
        std::vector<double> springs(system.position.size());
        for (std::size_t k = 0; k < springs.size(); ++k)
          springs[k] = system.position[k] - system.rest_position()[k];
        std::vector<mesh::Point3> expected(system.n_particles());
        for (unsigned int v = 0; v < system.n_particles(); ++v)
          expected[v] = fem.at_vertex(v);
        const NodalError error = nodal_error(springs, expected);
        total.add(error);

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

      SolverParameters                  parameters;
      std::vector<mesh::Point3>         probes;
      std::vector<unsigned int>         probe_vertices;
      unsigned int                      n_frequencies  = 0;
      double                            print_interval = 0.05, next_print = 0;
      double                            field_interval = 0;
      postprocess::OutputSchedule       fields;
      unsigned int                      n_fields = 0;
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
    "mesh, constraints and loads, and writes comparison.csv: relative L2 and largest "
    "nodal error of the springs against it after every step, and probe displacements "
    "of both; prints the lowest vibration frequencies of both if asked.");
} // namespace lacerta::fem
