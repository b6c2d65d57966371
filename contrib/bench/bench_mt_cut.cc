// lacerta-bench mtcut: the paper's Table 2 on this machine: a stroke cuts the active
// level of detail (TetUp) and the Multi-Triangulation is updated after it (MT-DAGUpd:
// the cutter's records replayed and the nodes pinned, doc/mt-cutting.md).
#include <lacerta/cut/cutter.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/mt/builder.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>
#include <lacerta/mt/mt_cutter.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria.h>

#include "bench_support.h"
#include "benchmark_registry.h"
#include <chrono>
#include <cstdio>
#include <string>

namespace lacerta::bench
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /// The paper's Table 2 (kidney, 2000): tetrahedra cut, TetUp and MT-DAGUpd (ms).
    struct PaperRow
    {
      unsigned int cut;
      double       tet_update_ms, dag_update_ms;
    };
    constexpr PaperRow paper[2] = {{302, 63, 109}, {732, 250, 147}};

    /**
     * A slab of n x n x 3 hexahedra (5 tetrahedra each, interior jittered), 10 x 10 x
     * 3 cm, its
     * MT, the full-resolution level of detail, one complete vertical cut across it in
     * one blade motion, then the MT update. Prints one row of Table 2.
     */
    void
    run(const unsigned int n, const PaperRow &reference)
    {
      dealii::Triangulation<3> tria;
      dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(
        tria, {n, n, 3}, dealii::Point<3>(), dealii::Point<3>(0.1, 0.1, 0.03));
      dealii::GridTools::distort_random(0.2, tria, true, 1);
      mesh::TetMesh input = mesh::tet_mesh_from_triangulation(tria, "benchmark box");
      input.sort_spatially();
      mt::MultiTriangulation mt =
        mt::build_multi_triangulation(input, mt::BuilderParameters());

      dealii::ParameterHandler prm;
      mt::LodQueryRegistry::declare_all_in_subsections(prm);
      prm.enter_subsection("Uniform");
      prm.set("Cell size", "0");
      prm.leave_subsection();
      const auto finest = mt::LodQueryRegistry::create_and_parse("uniform", prm);
      mt::Lod    lod(mt);
      lod.extract(*finest);
      std::vector<std::uint32_t> mt_vertex_of = lod.active_vertices();
      mesh::TetMesh              mesh = lod.make_mesh(mt_vertex_of, "level of detail");

      const dealii::Functions::ConstantFunction<3> density(1000), youngs(5e4);
      const auto               particles = make_particle_system(mesh, density, youngs);
      physics::ParticleSystem &system    = *particles;
      double                   integral  = physics::integrate_over_mesh(mesh, density);
      const auto               blade     = [](const double x) {
        return cut::Blade{{{x, 0.047, 0.15}}, {{x, 0.053, -0.05}}};
      };
      cut::Cutter cutter(
        mesh, system, density, youngs, integral, cut::Cutter::Parameters(), blade(-0.02));
      std::vector<cut::CutRecord> records;
      cutter.set_recorder(&records);
      unsigned int cut_tets = 0, created_tets = 0;
      double       tet_update = 0;
      // One cut: the blade crosses the box in one motion (the cutter sub-divides it
      // into sweeps of at most half a cell).
      {
        const auto statistics = cutter.move_blade(blade(0.12));
        cut_tets += statistics.cut_tets;
        created_tets += statistics.created_tets;
        tet_update += statistics.update_seconds + statistics.reinit_seconds;
      }

      const auto   start = Clock::now();
      mt::MtCutter mt_cutter(mt);
      const double index  = std::chrono::duration<double>(Clock::now() - start).count();
      const auto   update = mt_cutter.apply(records, mt_vertex_of, lod);

      std::printf("%8u %8u %6u %6u %6u %9.1f %7u %7u %11.1f %8.1f   %5u %7.0f %9.0f\n",
                  input.n_tets(),
                  mt.n_nodes(),
                  update.split_fragments,
                  cut_tets,
                  created_tets,
                  1e3 * tet_update,
                  update.cut_tets,
                  update.created_tets,
                  1e3 * update.seconds,
                  1e3 * index,
                  reference.cut,
                  reference.tet_update_ms,
                  reference.dag_update_ms);
      const std::string prefix = "mtcut." + std::to_string(input.n_tets()) + ".";
      print_figure(prefix + "split_fragments", update.split_fragments, "");
      print_figure(prefix + "cut_tets", cut_tets, "");
      print_figure(prefix + "created_tets", created_tets, "");
      print_figure(prefix + "tet_update", 1e3 * tet_update, "ms");
      print_figure(prefix + "mt_cut_tets", update.cut_tets, "");
      print_figure(prefix + "mt_dag_update", 1e3 * update.seconds, "ms");
      print_figure(prefix + "mt_index", 1e3 * index, "ms");
      print_figure(prefix + "pinned_nodes",
                   update.pinned_applied + update.pinned_undone,
                   "");
    }


    int
    run_mtcut(const std::vector<std::string> &arguments)
    {
      // Slabs whose cut has about the paper's 302 and 732 tetrahedra (CuT 315, 690).
      unsigned int sizes[2] = {11, 24};
      for (std::size_t k = 0; k < 2 && k < arguments.size(); ++k)
        sizes[k] = static_cast<unsigned int>(std::stoul(arguments[k]));
      std::printf(
        "Table 2: one cut across a slab, full-resolution level of detail; "
        "SF split fragments, CuT/CrT tetrahedra cut/created in the level of "
        "detail by the cutter (TetUp: its update, ms) and in the MT (MT-DAGUpd, "
        "ms: the records replayed and the nodes pinned; the MT's vertex index is "
        "built once, before)\n");
      std::printf("%8s %8s %6s %6s %6s %9s %7s %7s %11s %8s | %5s %7s %9s\n",
                  "mesh",
                  "nodes",
                  "SF",
                  "CuT",
                  "CrT",
                  "TetUp",
                  "MT-CuT",
                  "MT-CrT",
                  "MT-DAGUpd",
                  "index",
                  "paper",
                  "TetUp",
                  "MT-DAGUpd");
      for (unsigned int k = 0; k < 2; ++k)
        run(sizes[k], paper[k]);
      return 0;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK(
    "mtcut",
    "the paper's Table 2: a cut of the level of detail, then "
    "the MT is updated (arguments: two slab sizes n, n x n x 3 x 5 "
    "tetrahedra; default 6 10)",
    run_mtcut);
} // namespace lacerta::bench
