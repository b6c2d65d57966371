#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/predicates.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/function.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>

namespace lacerta::cut
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

  } // namespace


  void
  Cutter::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Cut");
    prm.declare_entry(
      "Snap fraction",
      "0.05",
      dealii::Patterns::Double(0.001, 0.45),
      "A cut point closer to an end of its edge than this fraction of the "
      "size of the cells around the edge (their longest edge at rest) "
      "snaps onto that end (doc/cutting.md, step 5): no sliver is "
      "created, and a layer an earlier cut left thin is not cut thinner.");
    prm.declare_entry("Max advance",
                      "0.5",
                      dealii::Patterns::Double(0.01, 10.0),
                      "A blade motion is split into sweeps that advance at most this "
                      "fraction of the local edge length, so that a fast scalpel never "
                      "crosses an element undetected.");
    prm.leave_subsection();
  }


  Cutter::Parameters
  Cutter::parse_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Cut");
    Parameters p;
    p.snap_fraction = prm.get_double("Snap fraction");
    p.max_advance   = prm.get_double("Max advance");
    prm.leave_subsection();
    return p;
  }


  Cutter::Cutter(mesh::TetMesh                     &mesh_in,
                 physics::ParticleSystem           &system_in,
                 const dealii::Function<3, double> &density_in,
                 const dealii::Function<3, double> &youngs_modulus_in,
                 double                            &integral,
                 const Parameters                  &parameters_in,
                 const Blade                       &initial)
      : mesh(mesh_in)
      , system(system_in)
      , topology(mesh_in, system_in, density_in, youngs_modulus_in)
      , integral_of_density(integral)
      , parameters(parameters_in)
      , current(initial)
      , decisions(mesh_in, system_in, parameters_in.snap_fraction)
      , search(mesh_in, system_in)
      , children(mesh_in, system_in)
      , selection(mesh_in)
  {
    // The split table is built on first use (about 10 ms): now, so that the first cut
    // of a run does not wait for it.
    split_table_entries();
    mesh.enable_local_updates();
    // Room for half as much again, so that the cuts of a stroke copy no mesh-sized
    // array (past it, the arrays double as usual: one copy, amortised).
    const auto room = [](const std::size_t n)
    { return static_cast<unsigned int>(n + n / 2 + 4096); };
    mesh.reserve(room(mesh.n_vertices()), room(mesh.n_tets()));
    system.reserve(room(system.n_particles()));
    system.springs.reserve(room(system.springs.size()));
    decisions.reserve(room(mesh.n_vertices()), room(mesh.n_edges()));
    children.reserve(room(mesh.n_vertices()), room(mesh.n_edges()));
    search.reserve(room(mesh.n_tets()), room(mesh.n_edges()));
    selection.reserve(room(mesh.n_tets()), room(mesh.n_vertices()));
    std::vector<double> lengths;
    for (const auto &e : mesh.get_edges())
      lengths.push_back(norm(sub(mesh.vertex(e[1]), mesh.vertex(e[0]))));
    std::nth_element(lengths.begin(),
                     lengths.begin() + lengths.size() / 2,
                     lengths.end());
    typical_edge = lengths[lengths.size() / 2];
  }


  Point
  Cutter::position(const unsigned int v) const
  {
    return system.current_position(v);
  }


  CutStepStatistics
  Cutter::move_blade(const Blade &next)
  {
    CutStepStatistics statistics;
    const double      advance =
      std::max(norm(sub(next.tail, current.tail)), norm(sub(next.head, current.head)));
    if (!(advance > 0))
      return statistics;
    const auto t_refit = Clock::now();
    search.refit();
    statistics.search_seconds +=
      std::chrono::duration<double>(Clock::now() - t_refit).count();
    // The local element size: the median edge of the active cells (deformed), or of
    // the mesh when the blade is outside. Not the shortest: cells a cut made small
    // must not multiply the sweeps, each of which re-splits the cells at the front.
    double h = typical_edge;
    if (!search.active().empty())
    {
      std::vector<double> lengths;
      for (const unsigned int t : search.active())
        for (const auto &e : tet_edge_vertices)
          lengths.push_back(
            norm(sub(position(mesh.tet(t)[e[1]]), position(mesh.tet(t)[e[0]]))));
      std::nth_element(lengths.begin(),
                       lengths.begin() + lengths.size() / 2,
                       lengths.end());
      h = std::max(lengths[lengths.size() / 2], 0.1 * typical_edge);
    }
    const double sweeps = std::ceil(advance / (parameters.max_advance * h));
    if (!(sweeps <= max_sweeps_per_motion))
      throw_error("Cutter: the blade moves ",
                  advance,
                  " m in one motion, which needs ",
                  sweeps,
                  " sweeps of at most ",
                  parameters.max_advance * h,
                  " m ('Cut/Maximum advance' times the element size around the blade, ",
                  h,
                  " m), more than ",
                  max_sweeps_per_motion,
                  ": the tool's path jumps, or the tissue around the blade has blown "
                  "up.");
    const unsigned int n     = std::max(1u, static_cast<unsigned int>(sweeps));
    const Blade        start = current;
    // The tissue moves between blade motions: a crossing just ahead of where the last
    // motion ended can be carried behind where this one starts, and no sweep would
    // meet it. The first sweep therefore starts behind the blade by as far as the
    // tissue around it moved since (the overlap is harmless: a crossing seen twice
    // the same way is one crossing).
    Blade  from = start;
    double back = 0;
    for (const auto &[v, x] : blade_cell_positions)
      if (v < mesh.n_vertices())
        back = std::max(back, norm(sub(position(v), x)));
    const Point motion =
      sub(scale(0.5, add(next.tail, next.head)), scale(0.5, add(start.tail, start.head)));
    if (back > 0 && norm(motion) > 0)
    {
      const Point shift = scale(back / norm(motion), motion);
      from.tail         = sub(from.tail, shift);
      from.head         = sub(from.head, shift);
    }
    for (unsigned int k = 1; k <= n; ++k)
    {
      const double s  = double(k) / n;
      const Blade  to = {lerp(start.tail, next.tail, s), lerp(start.head, next.head, s)};
      sweep(from, to, statistics);
      from = to;
    }
    current = next;
    // The blade has left the tissue (it is in no cell): the stroke is over.
    if (search.active().empty())
      decisions.end_stroke();
    blade_cell_positions.clear();
    for (const unsigned int t : search.active())
      for (const unsigned int v : mesh.tet(t))
        blade_cell_positions.push_back({v, position(v)});
    if (statistics.changed)
    {
      const auto t0 = Clock::now();
      topology.notify_force_model();
      statistics.reinit_seconds =
        std::chrono::duration<double>(Clock::now() - t0).count();
    }
    return statistics;
  }


  void
  Cutter::sweep(const Blade &from, const Blade &to, CutStepStatistics &statistics)
  {
    ++statistics.sweeps;
    const std::array<std::array<Point, 3>, 2> swept_triangles = {
      {{{from.tail, from.head, to.tail}}, {{to.tail, from.head, to.head}}}};
    const auto t_search = Clock::now();
    search.find(swept_triangles, to);
    statistics.search_seconds +=
      std::chrono::duration<double>(Clock::now() - t_search).count();
    if (search.cells().empty())
    {
      // Out of the tissue: the stroke is over.
      decisions.end_stroke();
      return;
    }
    const auto t_start = Clock::now();
    lap_start          = t_start;
    decisions.prepare();
    decisions.record_sweep(search.cells(), swept_triangles);
    selection.select(decisions);
    lap(statistics.analysis_seconds);
    if (!selection.removed().empty())
    {
      const std::vector<TetCut> &cuts = selection.cuts();
      results.resize(cuts.size());
      for (std::size_t k = 0; k < cuts.size(); ++k)
        split_tetrahedron(cuts[k], results[k], parameters.snap_fraction);
      lap(statistics.split_seconds);
      decisions.forget_applied();
      apply(to, statistics);
    }
    statistics.update_seconds +=
      std::chrono::duration<double>(Clock::now() - t_start).count();
  }


  void
  Cutter::clamp_rounded_masses()
  {
    // A vertex that lost all its cells cannot happen (copies take over whole stars),
    // but a mass that rounding left a hair below zero would be nonsense: clamp. A mass
    // further below zero is a particle that gave mass to its neighbours
    // (physics::MassBalancer) and lost cells since: the balancer raises it again, and
    // clamping it would add mass.
    const double rounding = 1e-12 * std::abs(integral_of_density);
    for (const unsigned int v : topology.touched_particles())
      if (system.mass[v] < 0 && system.mass[v] > -rounding)
        system.mass[v] = 0;
  }


  void
  Cutter::apply(const Blade &end, CutStepStatistics &statistics)
  {
    // The terms of the cells that go, from the masses and from the springs of their
    // edges (by edge id, before the mesh update moves the ids; a spring whose edge
    // dies is retired with it). Every spring gets these terms first and those of the
    // new cells after, in the order of the cells.
    topology.clear_touched();
    const double                     mass_before = topology.mass_delta();
    const std::vector<unsigned int> &removed     = selection.removed();
    topology.take_out(removed);
    lap(statistics.physics_seconds);

    // The record of this sweep for the Multi-Triangulation (set_recorder()).
    CutRecord *record = recorder ? &recorder->emplace_back() : nullptr;
    if (record)
    {
      record->cuts          = selection.cuts();
      record->snap_fraction = parameters.snap_fraction;
    }
    children.build(removed,
                   selection.cuts(),
                   results,
                   selection.separated(),
                   decisions,
                   statistics,
                   record);
    lap(statistics.children_seconds);

    // The mesh, locally.
    added_ids = topology.replace(removed, children.children(), children.face_ids());
    lap(statistics.mesh_seconds);

    decisions.prepare();
    clamp_rounded_masses();
    integral_of_density += topology.mass_delta() - mass_before;
    search.follow_replacement(removed, added_ids, end);
    statistics.changed = true;
    lap(statistics.physics_seconds);
  }


  void
  Cutter::lap(double &phase)
  {
    const auto now = Clock::now();
    phase += std::chrono::duration<double>(now - lap_start).count();
    lap_start = now;
  }


  void
  Cutter::adopt_crack(const std::vector<unsigned int> &crack)
  {
    // Their copies are decided again in the next sweep (the faces between them lie
    // in the cut): where the crack was closed, it opens.
    decisions.adopt(crack);
  }


  void
  Cutter::serialize(Archive &archive)
  {
    // What a blade motion leaves for the next one; the rest is scratch of a motion.
    archive.section("cutter");
    archive(current, typical_edge, blade_cell_positions);
    search.serialize(archive);
    decisions.serialize(archive);
  }
} // namespace lacerta::cut
