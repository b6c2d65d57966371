// lacerta-bench tear: lacerations per second on slabs of a few sizes, with the cost of
// the per-step check of the surface springs and of one tear.
#include <lacerta/cut/lacerator.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <deal.II/base/parameter_handler.h>

#include "benchmark_registry.h"
#include <chrono>
#include <cstdio>
#include <string>

namespace lacerta::bench
{
  namespace
  {
    using Clock   = std::chrono::steady_clock;
    using Seconds = std::chrono::duration<double>;

    /**
     * The scene of square_tear.prm at n x n x 3 hexahedra (5 tetrahedra each), with
     * @p limit as maximum elongation, stretched by 0.4 along x (about x = 0) without
     * dynamics: every surface spring along x is past a limit of 0.3.
     */
    std::unique_ptr<scene::Scene>
    stretched_slab(const unsigned int n, const std::string &limit)
    {
      dealii::ParameterHandler prm;
      scene::Scene::declare_parameters(prm, {});
      prm.enter_subsection("Mesh");
      prm.set("Source", "box");
      prm.enter_subsection("Box");
      prm.set("Lower corner", "-0.05, -0.05, 0");
      prm.set("Upper corner", "0.05, 0.05, 0.02");
      prm.set("Repetitions", std::to_string(n) + ", " + std::to_string(n) + ", 3");
      prm.leave_subsection();
      prm.leave_subsection();
      prm.enter_subsection("Material");
      prm.set("Youngs modulus", "5e4");
      prm.set("Maximum elongation", limit);
      prm.leave_subsection();
      prm.enter_subsection("Laceration");
      prm.set("Enabled", true);
      prm.leave_subsection();
      auto scene = std::make_unique<scene::Scene>(prm, 1);
      for (unsigned int i = 0; i < scene->system->n_particles(); ++i)
        scene->system->position[3 * i] *= 1.4;
      return scene;
    }

    /// One row: a tear on a fresh slab, after timing the checks that do not tear.
    void
    run(const unsigned int n, const bool partial, const unsigned int repetitions)
    {
      // Partial: strong tissue away from the edge y = 0.05, so the tear stops halfway.
      const std::string limit         = partial ? "0.3 + 200*(0.05 - y)^2" : "0.3";
      double            check_seconds = 0, tear_seconds = 0, search_seconds = 0;
      unsigned int      tets = 0, split = 0, created = 0, springs = 0;
      bool              complete = false;
      for (unsigned int r = 0; r < repetitions; ++r)
      {
        auto scene = stretched_slab(n, limit);
        tets       = scene->mesh.n_tets();
        // The per-step check alone: below the threshold nothing tears.
        cut::Lacerator::Parameters high;
        high.threshold = 1000000;
        cut::Lacerator watcher(scene->mesh,
                               *scene->system,
                               scene->material.density(),
                               scene->material.youngs_modulus(),
                               scene->material.maximum_elongation(),
                               scene->integral_of_density,
                               cut::Cutter::Parameters(),
                               high);
        const auto     t0 = Clock::now();
        const auto     c  = watcher.check();
        check_seconds += Seconds(Clock::now() - t0).count();
        springs = c.surface_springs;
        // The tear: the check that finds the threshold reached and tears.
        const auto t1 = Clock::now();
        const auto s  = scene->lacerator->check();
        tear_seconds += Seconds(Clock::now() - t1).count();
        search_seconds += s.search_seconds;
        split    = s.cut_tets;
        created  = s.created_tets;
        complete = s.complete;
      }
      check_seconds /= repetitions;
      tear_seconds /= repetitions;
      search_seconds /= repetitions;
      std::printf("%8u %8u %9s %8u %8u %10.3f %10.2f %10.3f %10.1f\n",
                  tets,
                  springs,
                  complete ? "through" : "partial",
                  split,
                  created,
                  1e3 * check_seconds,
                  1e3 * tear_seconds,
                  1e3 * search_seconds,
                  1.0 / tear_seconds);
    }

    int
    bench_tear(const std::vector<std::string> &)
    {
      std::printf(
        "Lacerations on slabs of n x n x 3 hexahedra stretched by 0.4 (limit 0.3, "
        "h = 3); times in ms (search: finding the springs that cross the tear's "
        "plane, part of tear), averages over repetitions:\n");
      std::printf("%8s %8s %9s %8s %8s %10s %10s %10s %10s\n",
                  "MS",
                  "surface",
                  "tear",
                  "split",
                  "created",
                  "check",
                  "tear",
                  "search",
                  "tears/s");
      for (const auto &[n, repetitions] :
           std::vector<std::pair<unsigned int, unsigned int>>{
             {2, 20}, {6, 10}, {20, 3}, {40, 1}})
        for (const bool partial : {false, true})
          run(n, partial, repetitions);
      return 0;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK("tear",
                             "lacerations per second on stretched slabs of 60 to 24000 "
                             "tetrahedra: the per-step check of the surface springs, "
                             "tetrahedra split and created by a tear through and a "
                             "partial tear, the time of one tear and of its search for "
                             "the springs crossing its plane",
                             bench_tear);
} // namespace lacerta::bench
