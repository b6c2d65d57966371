// Postprocessor `cut tables`: the paper's Tables 1 and 2 and the log of the tears, on
// the screen.

#include <lacerta/base/archive.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/scene/scene.h>

#include <iostream>
#include <vector>

namespace lacerta::postprocess
{
  namespace
  {
    /**
     * Prints a line for every tear and for every MT update after a stroke while the run
     * goes, and at its end the paper's Table 1 (averages over the steps that cut: MS,
     * CuT, CrT, UpdT, RxT), Table 2's totals on a multiresolution model (SF, MT
     * tetrahedra cut and created, TetUp and MT-DAGUpd per stroke), the pieces' rest
     * volumes and the laceration summary. In test mode no wall time is printed. The
     * lines of a change are printed when it happens (it subscribes to
     * Scene::system_changed), so that they precede any error the change causes.
     */
    class CutTables : public Postprocessor
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const std::string &, const bool test) override
      {
        test_mode = test;
      }

      void
      subscribe(scene::Scene &s) override
      {
        scene = &s;
        s.system_changed.connect([this](const scene::SystemChange &change)
                                 { report(change); });
        s.multi_triangulation_cut.connect([this](const scene::MultiresolutionCut &mt_cut)
                                          { report_multiresolution_cut(mt_cut); });
      }

      void
      execute(const RunState &state) override
      {
        if (state.cut_tets == 0)
          return;
        ++table1.cutting_steps;
        table1.cut += state.cut_tets;
        table1.created += state.created_tets;
        table1.update_seconds += state.update_seconds;
        table1.relax_seconds += state.integration_seconds;
      }

      void
      finish(const RunState &state) override
      {
        if (scene->cutter)
          print_table1(*state.mesh);
        if (scene->lacerator)
        {
          std::cout << "Laceration summary: " << tears.count << " tears, " << tears.cut
                    << " tetrahedra split into " << tears.created;
          if (!test_mode && tears.count > 0)
            std::cout << ", " << 1e3 * tears.seconds / tears.count << " ms per tear";
          std::cout << "; mesh " << state.mesh->n_tets() << " tetrahedra, components "
                    << cut::count_components(*state.mesh) << "\n";
        }
      }

    private:
      /// A change as it happens, before anything it causes: Table 2 counts the work
      /// of the cutter and the tears on the level of detail during a stroke
      /// (doc/lacerations.md), and the tears and MT updates get a line each.
      void
      report(const scene::SystemChange &change)
      {
        if (change.cut)
        {
          stroke.cut += change.cut->cut_tets;
          stroke.created += change.cut->created_tets;
          stroke.update_seconds += change.cut->update_seconds;
        }
        if (change.tear)
        {
          stroke.cut += change.tear->cut_tets;
          stroke.created += change.tear->created_tets;
          stroke.update_seconds += change.tear->update_seconds;
          report_tear(change.time, *change.tear);
        }
      }

      void
      report_tear(const double time, const cut::LacerationStatistics &tear)
      {
        ++tears.count;
        tears.cut += tear.cut_tets;
        tears.created += tear.created_tets;
        tears.seconds += tear.update_seconds;
        std::cout << "Laceration at t = " << time
                  << " s: " << (tear.continued ? "continued" : "started")
                  << " at the spring " << tear.seed_a << "-" << tear.seed_b << " ("
                  << tear.seed_ratio << " times its maximum elongation, "
                  << tear.over_limit << " surface springs past their limit); "
                  << tear.advances << " advances, "
                  << (tear.complete ? "through" : "stopped inside") << "; "
                  << tear.cut_tets << " tetrahedra split into " << tear.created_tets
                  << "; mesh components " << cut::count_components(scene->active_mesh());
        if (!test_mode)
          std::cout << "; " << 1e3 * tear.update_seconds << " ms";
        std::cout << "\n";
      }

      void
      report_multiresolution_cut(const scene::MultiresolutionCut &mt_cut)
      {
        ++table2.updates;
        table2.split_fragments += mt_cut.update.split_fragments;
        table2.cut += mt_cut.update.cut_tets;
        table2.created += mt_cut.update.created_tets;
        table2.tet_update_seconds += stroke.update_seconds;
        table2.mt_update_seconds += mt_cut.update.seconds;
        std::cout << "MT update after the stroke at t = " << mt_cut.time << " s: SF "
                  << mt_cut.update.split_fragments << ", CuT " << stroke.cut << ", CrT "
                  << stroke.created;
        if (!test_mode)
          std::cout << ", TetUp " << 1e3 * stroke.update_seconds << " ms, MT-DAGUpd "
                    << 1e3 * mt_cut.update.seconds << " ms";
        std::cout << "; MT tetrahedra cut " << mt_cut.update.cut_tets << ", created "
                  << mt_cut.update.created_tets << ", vertices added "
                  << mt_cut.update.new_vertices << ", nodes pinned "
                  << mt_cut.update.pinned_applied << " applied and "
                  << mt_cut.update.pinned_undone << " undone; level of detail "
                  << mt_cut.n_tets << " tetrahedra, " << mt_cut.n_particles
                  << " particles, mesh components " << mt_cut.pieces << "\n";
        stroke = {};
      }

      void
      print_table1(const mesh::TetMesh &mesh) const
      {
        const unsigned int n = table1.cutting_steps;
        std::cout << "Cut summary (Table 1 columns, averages over the " << n
                  << " steps that cut): MS " << mesh.n_tets() << ", CuT "
                  << (n ? table1.cut / n : 0.0) << ", CrT "
                  << (n ? table1.created / n : 0.0);
        if (!test_mode && n > 0)
          std::cout << ", UpdT " << 1e3 * table1.update_seconds / n << " ms, RxT "
                    << 1e3 * table1.relax_seconds / n << " ms";
        if (scene->multiresolution)
          std::cout << "; " << table2.updates
                    << " MT updates (Table 2 columns: totals, times per stroke): SF "
                    << table2.split_fragments << ", MT tetrahedra cut " << table2.cut
                    << ", created " << table2.created
                    << (scene->cut_pending() ? " (a stroke still waits for its update)"
                                             : "");
        if (!test_mode && table2.updates > 0)
          std::cout << ", TetUp " << 1e3 * table2.tet_update_seconds / table2.updates
                    << " ms, MT-DAGUpd "
                    << 1e3 * table2.mt_update_seconds / table2.updates << " ms";
        // The pieces' rest volumes show what a cut separated (a punched hole).
        const std::vector<double> pieces = cut::component_volumes(mesh);
        std::cout << "; mesh components " << pieces.size() << ", rest volumes (m^3)";
        for (const double v : pieces)
          std::cout << " " << v;
        std::cout << "\n";
      }

      /// The tables' sums so far.
      void
      serialize(Archive &archive) override
      {
        archive(table1, stroke, table2, tears);
      }

      const scene::Scene *scene     = nullptr;
      bool                test_mode = false;
      /// Table 1: the steps that cut, what they cut and created, and their times.
      struct
      {
        unsigned int cutting_steps = 0;
        double       cut = 0, created = 0, update_seconds = 0, relax_seconds = 0;
      } table1;
      /// The current stroke's work on the level of detail (Table 2's CuT, CrT, TetUp).
      struct Stroke
      {
        unsigned int cut = 0, created = 0;
        double       update_seconds = 0;
      } stroke;
      /// Table 2 over the run.
      struct
      {
        unsigned int updates = 0, split_fragments = 0, cut = 0, created = 0;
        double       tet_update_seconds = 0, mt_update_seconds = 0;
      } table2;
      /// The tears.
      struct
      {
        unsigned int count = 0, cut = 0, created = 0;
        double       seconds = 0;
      } tears;
    };
  } // namespace


  LACERTA_REGISTER_POSTPROCESSOR(
    CutTables,
    "cut tables",
    "The paper's Tables 1 and 2 on the screen: a line for every tear and every MT "
    "update after a stroke, and at the end the averages over the steps that cut (MS, "
    "CuT, CrT, UpdT, RxT), the MT updates' totals and the pieces' rest volumes. Added "
    "to every scene with a tool or lacerations.");
} // namespace lacerta::postprocess
