// lacerta-bench cut: the paper's Table 1 on this machine, and how the mesh update
// time grows with the number of tetrahedra cut and with the mesh size.
#include <lacerta/cut/cutter.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

#include "bench_support.h"
#include "benchmark_registry.h"
#include <chrono>
#include <cstdio>

namespace lacerta::bench
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    /// Averages over the steps of one stroke that cut something.
    struct Row
    {
      unsigned int mesh_size = 0, steps = 0;
      double       cut = 0, created = 0, update_ms = 0, reinit_ms = 0, relax_ms = 0;
    };

    /**
     * A slab of n x n x 3 hexahedra (5 tetrahedra each, as the scenes) cut across by
     * a vertical blade in @p n_steps steps; one RK4 step is timed after every cut.
     */
    Row
    run(const unsigned int n, const unsigned int n_steps, const bool partial)
    {
      dealii::Triangulation<3> tria;
      dealii::GridGenerator::subdivided_hyper_rectangle_with_simplices(
        tria,
        {n, n, 3},
        dealii::Point<3>(-0.05, -0.05, 0),
        dealii::Point<3>(0.05, 0.05, 0.02));
      mesh::TetMesh mesh = mesh::tet_mesh_from_triangulation(tria, "benchmark slab");
      mesh.sort_spatially();
      const dealii::Functions::ConstantFunction<3> density(1000), youngs(5e4);
      const auto               particles = make_particle_system(mesh, density, youngs);
      physics::ParticleSystem &system    = *particles;
      double                   integral  = physics::integrate_over_mesh(mesh, density);
      std::unique_ptr<physics::Integrator> rk4 =
        physics::IntegratorRegistry::create("rk4");
      rk4->initialize(system);
      const auto blade = [](const double y) {
        return cut::Blade{{{0.003, y, 0.03}}, {{0.003, y, -0.01}}};
      };
      cut::Cutter::Parameters parameters;
      parameters.max_advance = 100; // one sweep per step: CuT grows with the step
      cut::Cutter cutter(
        mesh, system, density, youngs, integral, parameters, blade(0.06));
      Row          row;
      const double end = partial ? 0.0 : -0.06;
      for (unsigned int k = 1; k <= n_steps; ++k)
      {
        const auto s = cutter.move_blade(blade(0.06 + (end - 0.06) * k / n_steps));
        if (s.cut_tets == 0)
          continue;
        rk4->initialize(system);
        const auto t0 = Clock::now();
        rk4->step(system, 0.0, 1e-6);
        ++row.steps;
        row.cut += s.cut_tets;
        row.created += s.created_tets;
        row.update_ms += 1e3 * s.update_seconds;
        row.reinit_ms += 1e3 * s.reinit_seconds;
        row.relax_ms += 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
      }
      row.mesh_size = 5 * n * n * 3;
      if (row.steps > 0)
      {
        row.cut /= row.steps;
        row.created /= row.steps;
        row.update_ms /= row.steps;
        row.reinit_ms /= row.steps;
        row.relax_ms /= row.steps;
      }
      return row;
    }

    void
    print(const Row &r)
    {
      std::printf("%8u %8.1f %8.1f %10.3f %10.3f %10.3f\n",
                  r.mesh_size,
                  r.cut,
                  r.created,
                  r.update_ms,
                  r.reinit_ms,
                  r.relax_ms);
    }

    int
    bench_cut(const std::vector<std::string> &)
    {
      std::printf("Table 1 (averages over the steps that cut; times in ms):\n");
      std::printf(
        "%8s %8s %8s %10s %10s %10s\n", "MS", "CuT", "CrT", "UpdT", "ReinitT", "RxT");
      // Slow and fast strokes on the paper's three sizes (2x2, 6x6, 20x20 x 3 hexahedra).
      for (const auto &[n, steps] : std::vector<std::pair<unsigned, unsigned>>{
             {2, 40}, {2, 2}, {6, 60}, {6, 3}, {20, 120}, {20, 4}})
        print(run(n, steps, true));
      std::printf("\nUpdate time against tetrahedra cut per step (complete cut, 6000 and "
                  "60000 tetrahedra):\n");
      std::printf(
        "%8s %8s %8s %10s %10s %10s\n", "MS", "CuT", "CrT", "UpdT", "ReinitT", "RxT");
      for (const unsigned int n : {20u, 63u})
        for (const unsigned int steps : {64u, 32u, 16u, 8u})
          print(run(n, steps, false));
      return 0;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK("cut",
                             "the paper's Table 1: mesh size, tetrahedra cut and created "
                             "per step, mesh update and relaxation time; update time "
                             "against cut size and mesh size",
                             bench_cut);
} // namespace lacerta::bench
