// lacerta-bench cut: the paper's Table 1 on this machine, and how the mesh update
// time grows with the number of tetrahedra cut and with the mesh size.
#include <lacerta/cut/cutter.h>
#include <lacerta/mesh/triangulation_conversion.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/mass_balancer.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/stability_bound.h>

#include <deal.II/base/function.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria.h>

#include "bench_support.h"
#include "benchmark_registry.h"
#include <algorithm>
#include <array>
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
      /// The simulator's response to the cut (the mass redistribution, the stability
      /// bound and the blow-up monitor follow the changed particles), and the whole cut
      /// step: search, UpdT, ReinitT and the response.
      double response_ms = 0, whole_ms = 0;
      /// The phases of CutStepStatistics: search (not in UpdT), then the parts of
      /// UpdT: analysis, split, children, mesh, physics.
      std::array<double, 6> phase_ms{};
    };

    /**
     * What runs between two cuts of a stroke. The update's cost per cell depends on
     * what is still in the cache when it starts, and that depends on what ran before
     * it more than on the mesh: the choice isolates the two.
     */
    enum class Between
    {
      /// One RK4 step of the whole system, timed (RxT): as in a simulation.
      relax,
      /// Nothing: the update finds the previous update's data in the cache.
      nothing,
      /// 64 MiB read and written, twice the last-level cache: every line the update
      /// touches comes from memory, whatever the mesh size.
      flush
    };

    /**
     * A slab of n x n x 3 hexahedra (5 tetrahedra each, as the scenes) cut across by
     * a vertical blade in @p n_steps steps with force model @p model (at ν = 0.45);
     * @p between runs after every cut.
     */
    Row
    run(const unsigned int n,
        const unsigned int n_steps,
        const bool         partial,
        const Between      between = Between::relax,
        const std::string &model   = "linear springs")
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
      // The mesh as the scene sets it (the stability bound's local update walks its
      // stars).
      system.mesh = &mesh;
      if (model != "linear springs")
      {
        system.youngs_modulus = &youngs;
        system.poisson_ratio  = 0.45;
        system.set_force_model(physics::ForceModelRegistry::create(model), 1);
      }
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
      // What the Simulator does after every cut step (Simulator::on_system_changed()):
      // the mass redistribution (on by default), the blow-up monitor, the bound.
      physics::MassBalancer   balancer(system, 3);
      physics::StabilityBound bound;
      bound.compute(system);
      system.clear_changes();
      physics::BlowUpMonitor monitor(system, 1.0);
      Row                    row;
      const double           end = partial ? 0.0 : -0.06;
      std::vector<double> flush_buffer(between == Between::flush ? (64u << 20) / 8 : 0);
      for (unsigned int k = 1; k <= n_steps; ++k)
      {
        const auto s = cutter.move_blade(blade(0.06 + (end - 0.06) * k / n_steps));
        if (!s.changed)
          continue;
        const auto r0 = Clock::now();
        balancer.rebalance(system, system.changed_particles());
        monitor.note_local_change(system, system.changed_particles(), k, 0.0, "the cut");
        bound.update(system, system.changed_particles());
        system.clear_changes();
        const double response =
          1e3 * std::chrono::duration<double>(Clock::now() - r0).count();
        row.response_ms += response;
        row.whole_ms +=
          1e3 * (s.search_seconds + s.update_seconds + s.reinit_seconds) + response;
        const auto t0 = Clock::now();
        if (between == Between::relax)
        {
          rk4->initialize(system);
          rk4->step(system, 0.0, 1e-6);
        }
        else if (between == Between::flush)
          for (double &x : flush_buffer)
            x += 1.0;
        ++row.steps;
        row.cut += s.cut_tets;
        row.created += s.created_tets;
        row.update_ms += 1e3 * s.update_seconds;
        row.reinit_ms += 1e3 * s.reinit_seconds;
        row.relax_ms += 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
        const std::array<double, 6> phases{{s.search_seconds,
                                            s.analysis_seconds,
                                            s.split_seconds,
                                            s.children_seconds,
                                            s.mesh_seconds,
                                            s.physics_seconds}};
        for (unsigned int i = 0; i < 6; ++i)
          row.phase_ms[i] += 1e3 * phases[i];
      }
      row.mesh_size = 5 * n * n * 3;
      if (row.steps > 0)
      {
        row.cut /= row.steps;
        row.created /= row.steps;
        row.update_ms /= row.steps;
        row.reinit_ms /= row.steps;
        row.relax_ms /= row.steps;
        row.response_ms /= row.steps;
        row.whole_ms /= row.steps;
        for (double &t : row.phase_ms)
          t /= row.steps;
      }
      return row;
    }

    /// The run with the least update time of three: the machine is shared, and the
    /// least disturbed run is the closest to the cost of the update itself.
    Row
    best_of_three(const unsigned int n,
                  const unsigned int n_steps,
                  const bool         partial,
                  const Between      between = Between::relax,
                  const std::string &model   = "linear springs")
    {
      Row best = run(n, n_steps, partial, between, model);
      for (unsigned int k = 1; k < 3; ++k)
      {
        const Row r = run(n, n_steps, partial, between, model);
        if (r.update_ms < best.update_ms)
          best = r;
      }
      return best;
    }


    void
    print_header()
    {
      std::printf("%8s %8s %8s %10s %10s %10s %10s %10s\n",
                  "MS",
                  "CuT",
                  "CrT",
                  "UpdT",
                  "ReinitT",
                  "RespT",
                  "CutStep",
                  "RxT");
    }

    void
    print(const Row &r)
    {
      std::printf("%8u %8.1f %8.1f %10.3f %10.3f %10.3f %10.3f %10.3f\n",
                  r.mesh_size,
                  r.cut,
                  r.created,
                  r.update_ms,
                  r.reinit_ms,
                  r.response_ms,
                  r.whole_ms,
                  r.relax_ms);
    }

    void
    print_phases(const Row &r)
    {
      std::printf("%8u %8.1f", r.mesh_size, r.cut);
      for (const double t : r.phase_ms)
        std::printf(" %9.3f", t);
      std::printf(" %9.2f\n", r.cut > 0 ? 1e3 * r.update_ms / r.cut : 0.0);
    }


    void
    print_phase_header()
    {
      std::printf("%8s %8s %9s %9s %9s %9s %9s %9s %9s\n",
                  "MS",
                  "CuT",
                  "search",
                  "analysis",
                  "split",
                  "children",
                  "mesh",
                  "physics",
                  "us/CuT");
    }


    int
    bench_cut(const std::vector<std::string> &arguments)
    {
      if (arguments.size() >= 2 && arguments.size() <= 5)
      {
        // One stroke (for profilers and for the cache study): n, steps, and
        // optionally "partial" and what runs between the cuts.
        const unsigned int n       = static_cast<unsigned int>(std::stoul(arguments[0]));
        const unsigned int steps   = static_cast<unsigned int>(std::stoul(arguments[1]));
        bool               partial = false, between_given = false;
        bool               valid   = n >= 1 && n <= 200 && steps >= 1 && steps <= 100000;
        Between            between = Between::relax;
        std::string        model   = "linear springs";
        for (std::size_t i = 2; i < arguments.size(); ++i)
        {
          const std::string &a = arguments[i];
          if (a.rfind("model=", 0) == 0 && model == "linear springs")
          {
            // model=volume_springs, model=corotated_fem: underscores for spaces.
            model = a.substr(6);
            std::replace(model.begin(), model.end(), '_', ' ');
            valid &= physics::ForceModelRegistry::plugins().count(model) > 0;
          }
          else if (a == "partial" && !partial)
            partial = true;
          else if ((a == "relax" || a == "nothing" || a == "flush") && !between_given)
          {
            between_given = true;
            between       = a == "relax"     ? Between::relax
                            : a == "nothing" ? Between::nothing
                                             : Between::flush;
          }
          else
            valid = false;
        }
        if (!valid)
        {
          std::fprintf(stderr,
                       "lacerta-bench cut: expected n (1-200), steps (1-100000), "
                       "optionally 'partial', and optionally what runs between the "
                       "cuts: 'relax' (an RK4 step, the default), 'nothing' or "
                       "'flush' (64 MiB through the cache), and optionally "
                       "'model=NAME' (a force model, '_' for spaces)\n");
          return 1;
        }
        const Row r = best_of_three(n, steps, partial, between, model);
        print_header();
        print(r);
        print_phase_header();
        print_phases(r);
        return 0;
      }
      if (!arguments.empty())
      {
        std::fprintf(stderr,
                     "lacerta-bench cut: expected no argument, or n steps [partial] "
                     "[relax|nothing|flush] [model=NAME]\n");
        return 1;
      }
      std::printf("Table 1 (averages over the steps that cut, the run with the least "
                  "UpdT of three; times in ms; RespT: the mass redistribution, the "
                  "stability bound and the blow-up monitor after the cut; CutStep: "
                  "search + UpdT + ReinitT + RespT, the whole cut step):\n");
      print_header();
      // Slow and fast strokes on the paper's three sizes (2x2, 6x6, 20x20 x 3 hexahedra).
      for (const auto &[n, steps] : std::vector<std::pair<unsigned, unsigned>>{
             {2, 40}, {2, 2}, {6, 60}, {6, 3}, {20, 120}, {20, 4}})
        print(best_of_three(n, steps, true));
      std::printf("\nUpdate time against tetrahedra cut per step (complete cut, 6000 and "
                  "60000 tetrahedra):\n");
      print_header();
      std::vector<Row> rows;
      for (const unsigned int n : {20u, 63u})
        for (const unsigned int steps : {64u, 32u, 16u, 8u})
        {
          rows.push_back(best_of_three(n, steps, false));
          print(rows.back());
        }
      std::printf("\nWhere the time goes (ms per step; search is not part of UpdT, the "
                  "other phases add up to it):\n");
      print_phase_header();
      for (const Row &r : rows)
        print_phases(r);
      return 0;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK("cut",
                             "the paper's Table 1: mesh size, tetrahedra cut and created "
                             "per step, mesh update and relaxation time; update time "
                             "against cut size and mesh size, per phase (arguments: "
                             "none, or n steps [partial] [relax|nothing|flush] "
                             "[model=NAME] for one stroke across a slab of n x n x 3 x 5 "
                             "tetrahedra, with an RK4 step, nothing, or 64 MiB of memory "
                             "traffic between the cuts, and force model NAME, '_' for "
                             "spaces)",
                             bench_cut);
} // namespace lacerta::bench
