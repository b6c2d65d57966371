// Postprocessor `statistics`: one row per step in statistics.csv.

#include <lacerta/base/archive.h>
#include <lacerta/base/output_file.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/postprocess/postprocessor.h>

#include <algorithm>
#include <cstdio>

namespace lacerta::postprocess
{
  namespace
  {
    /**
     * Writes statistics.csv: step, time, time step, sub-steps, energies, the work of
     * the loads, the wall time of the force evaluation and of the whole step, the cut
     * columns (Table 1) and the laceration columns.
     */
    class Statistics : public Postprocessor
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const std::string &output_directory, const bool test) override
      {
        file      = OutputFile(output_directory + "/statistics.csv");
        test_mode = test;
        file.append(
          "step,time,time_step,substeps,kinetic_energy,elastic_energy,"
          "body_force_energy,input_work,force_wall_s,step_wall_s,mesh_size,cut_tets,"
          "created_tets,update_wall_ms,over_limit,tears,torn_tets,tear_created_tets,"
          "tear_wall_ms,split_fragments,mt_update_wall_ms,cut_step_wall_ms\n");
      }

      bool
      needs_energies(double) const override
      {
        return true;
      }

      void
      execute(const RunState &s) override
      {
        char      line[640];
        const int length = std::snprintf(
          line,
          sizeof(line),
          "%u,%.9g,%.6g,%u,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%u,%u,%u,%.6g,%u,%u,"
          "%u,%u,%.6g,%u,%.6g,%.6g\n",
          s.step,
          s.time,
          s.time_step,
          s.substeps,
          s.kinetic_energy,
          s.elastic_energy,
          s.body_force_energy,
          s.input_work,
          test_mode ? 0.0 : s.force_seconds,
          test_mode ? 0.0 : s.step_seconds,
          s.mesh->n_tets(),
          s.cut_tets,
          s.created_tets,
          test_mode ? 0.0 : 1e3 * s.update_seconds,
          s.over_limit,
          s.tears,
          s.torn_tets,
          s.tear_created_tets,
          test_mode ? 0.0 : 1e3 * s.tear_seconds,
          s.split_fragments,
          test_mode ? 0.0 : 1e3 * s.mt_update_seconds,
          test_mode ? 0.0 : 1e3 * s.cut_step_seconds);
        file.append(
          std::string_view(line,
                           std::min(static_cast<std::size_t>(length), sizeof(line) - 1)));
      }

      /// The table written so far.
      void
      serialize(Archive &archive) override
      {
        archive &file;
      }

    private:
      OutputFile file;
      bool       test_mode = false;
    };
  } // namespace

  LACERTA_REGISTER_POSTPROCESSOR(
    Statistics,
    "statistics",
    "statistics.csv with one row per step: time, time step, "
    "sub-steps, kinetic, elastic and body-force energy, work of "
    "the loads, wall time of force evaluation (with the integrator's update "
    "and the constraints done in the same parallel pass) and of the step, and the "
    "paper's Table 1 columns: mesh size, tetrahedra cut and created, mesh "
    "update wall time (ms); and the laceration columns: surface springs past "
    "their limit, tears, tetrahedra torn and created, tear wall time (ms); and the "
    "Table 2 columns of a multiresolution model's MT update after a stroke: "
    "fragments split and the MT update's wall time (ms).");
} // namespace lacerta::postprocess
