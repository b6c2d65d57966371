#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/function.h>
#include <deal.II/base/point.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>

namespace lacerta::cut
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    constexpr double min_elongation = 1e-3, max_elongation = 100;

    constexpr unsigned int no_laceration = static_cast<unsigned int>(-1);

    Point
    midpoint(const Point &a, const Point &b)
    {
      return scale(0.5, add(a, b));
    }
  } // namespace


  void
  Lacerator::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Laceration");
    prm.declare_entry(
      "Enabled",
      "false",
      dealii::Patterns::Bool(),
      "Whether over-stretched tissue tears (Section 7): surface springs beyond "
      "'Material/Maximum elongation' are collected in a heap and a laceration is "
      "propagated from the most stretched one (doc/lacerations.md). Without it no "
      "laceration structure is built.");
    prm.declare_entry(
      "Threshold h",
      "3",
      dealii::Patterns::Integer(1, 1000),
      "The paper's h: no tear starts until at least this many surface springs "
      "exceed their maximum elongation.");
    prm.declare_entry(
      "Propagation fraction",
      "0.5",
      dealii::Patterns::Double(0.05, 1.0),
      "A laceration advances while the most stretched spring it is about to cross "
      "is elongated beyond this fraction of its maximum; it stops where the stress "
      "is lower.");
    prm.leave_subsection();
  }


  bool
  Lacerator::enabled(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Laceration");
    const bool on = prm.get_bool("Enabled");
    prm.leave_subsection();
    return on;
  }


  Lacerator::Parameters
  Lacerator::parse_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Laceration");
    Parameters p;
    p.threshold            = prm.get_integer("Threshold h");
    p.propagation_fraction = prm.get_double("Propagation fraction");
    prm.leave_subsection();
    return p;
  }


  Lacerator::Lacerator(mesh::TetMesh                     &mesh_in,
                       physics::ParticleSystem           &system_in,
                       const dealii::Function<3, double> &density_in,
                       const dealii::Function<3, double> &youngs_modulus_in,
                       const dealii::Function<3, double> &maximum_elongation_in,
                       double                            &integral,
                       const Cutter::Parameters          &cut_parameters_in,
                       const Parameters                  &parameters_in)
      : mesh(mesh_in)
      , system(system_in)
      , density(density_in)
      , youngs_modulus(youngs_modulus_in)
      , maximum_elongation(maximum_elongation_in)
      , integral_of_density(integral)
      , cut_parameters(cut_parameters_in)
      , parameters(parameters_in)
  {
    // The mesh is torn locally, like the scalpel's (and the mass redistribution finds
    // the springs around a particle through its cells).
    mesh.enable_local_updates();
    // A bad limit anywhere on the object is reported now, not at the first tear.
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      limit_at(mesh.vertex(v));
    collect_surface_springs();
    // The element size of the tissue as built: the mean surface spring at rest.
    for (const SurfaceSpring &spring : surface)
      typical_edge += spring.rest_length / surface.size();
    // The split table is built on first use (about 10 ms): now, so that the first tear
    // does not wait for it.
    split_table_entries();
  }


  Lacerator::~Lacerator() = default;


  double
  Lacerator::limit_at(const Point &x) const
  {
    const double limit = maximum_elongation.value(dealii::Point<3>(x[0], x[1], x[2]));
    if (!(limit >= min_elongation && limit <= max_elongation))
      throw_error("Material/Maximum elongation: the value ",
                  limit,
                  " at (",
                  x[0],
                  ", ",
                  x[1],
                  ", ",
                  x[2],
                  ") is outside [",
                  min_elongation,
                  ", ",
                  max_elongation,
                  "] (a strain).");
    return limit;
  }


  Point
  Lacerator::position(const unsigned int v) const
  {
    return system.current_position(v);
  }


  void
  Lacerator::collect_surface_springs()
  {
    // (a, b, a tetrahedron with the edge on a boundary face), a < b.
    std::vector<std::array<unsigned int, 3>> edges;
    edges.reserve(3 * mesh.get_boundary_faces().size());
    for (const auto &f : mesh.get_boundary_faces())
    {
      const auto &fv = mesh::TetMesh::face_vertices[f.face];
      for (unsigned int k = 0; k < 3; ++k)
      {
        const unsigned int a = mesh.tet(f.tet)[fv[k]],
                           b = mesh.tet(f.tet)[fv[(k + 1) % 3]];
        edges.push_back({{std::min(a, b), std::max(a, b), f.tet}});
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(),
                            edges.end(),
                            [](const std::array<unsigned int, 3> &x,
                               const std::array<unsigned int, 3> &y)
                            { return x[0] == y[0] && x[1] == y[1]; }),
                edges.end());
    surface.clear();
    surface.reserve(edges.size());
    for (const auto &[a, b, t] : edges)
    {
      const Point &xa = mesh.vertex(a), &xb = mesh.vertex(b);
      surface.push_back({a, b, norm(sub(xb, xa)), limit_at(midpoint(xa, xb)), t});
    }
    surface_valid = true;
  }


  double
  Lacerator::ratio(const unsigned int a, const unsigned int b) const
  {
    const Point &ra = mesh.vertex(a), &rb = mesh.vertex(b);
    const double rest = norm(sub(rb, ra));
    const double now  = norm(sub(position(b), position(a)));
    return (now - rest) / rest / limit_at(midpoint(ra, rb));
  }


  bool
  Lacerator::in_wake(const Point &x) const
  {
    for (const Laceration &l : lacerations)
    {
      const Point  r      = sub(x, l.origin);
      const double across = dot(l.across, r);
      if (std::abs(dot(l.normal, r)) <= l.edge
          && (l.complete || dot(l.advance, r) <= l.stop) && across >= l.across_lo - l.edge
          && across <= l.across_hi + l.edge)
        return true;
    }
    return false;
  }


  void
  Lacerator::mesh_changed()
  {
    surface_valid = false;
  }


  void
  Lacerator::set_recorder(std::vector<CutRecord> *records)
  {
    recorder = records;
    for (Laceration &l : lacerations)
      if (l.cutter)
        l.cutter->set_recorder(records);
  }


  void
  Lacerator::particles_replaced(const std::vector<std::uint8_t> &created_by_cut)
  {
    AssertDimension(created_by_cut.size(), system.n_particles());
    mesh.enable_local_updates();
    surface_valid = false;
    for (Laceration &l : lacerations)
      l.cutter.reset();
    // The particles the lacerations created, found again by their rest positions among
    // those cuts created (a new level of detail numbers its particles anew).
    // O(particles created by cuts x particles created by lacerations).
    sheet.assign(system.n_particles(), no_laceration);
    for (unsigned int v = 0; v < system.n_particles(); ++v)
      if (created_by_cut[v])
      {
        const Point &x    = mesh.vertex(v);
        double       best = std::numeric_limits<double>::infinity();
        for (unsigned int i = 0; i < lacerations.size(); ++i)
          for (const Point &y : lacerations[i].created_rest)
          {
            const double d = norm(sub(x, y));
            if (d <= lacerations[i].edge && d < best)
            {
              best     = d;
              sheet[v] = i;
            }
          }
      }
  }


  void
  Lacerator::find_crossings(const Laceration &l, const unsigned int seed_tet)
  {
    crossings.clear();
    const physics::SpringSet &springs = system.springs;
    AssertDimension(springs.size(), mesh.n_edges());
    // Spring s (the mesh's edge s) crosses the plane within the blade's extent: then
    // its crossing is appended. The same test as a scan over all springs would make.
    const auto crossing = [&](const unsigned int s)
    {
      const Point  xa = position(springs.a[s]), xb = position(springs.b[s]);
      const double da = dot(l.normal, sub(xa, l.origin));
      const double db = dot(l.normal, sub(xb, l.origin));
      if ((da > 0) == (db > 0) || da == db)
        return false;
      const Point  p      = lerp(xa, xb, da / (da - db));
      const double across = dot(l.across, sub(p, l.origin));
      if (across < l.across_lo - l.edge || across > l.across_hi + l.edge)
        return false;
      crossings.push_back(
        {p, dot(l.advance, sub(p, l.origin)), springs.a[s], springs.b[s], s});
      return true;
    };
    // Whether the vertices of tetrahedron t other than local vertex `skip` (4: none)
    // lie on both sides of the plane.
    const auto crosses = [&](const unsigned int t, const unsigned int skip)
    {
      bool above = false, below = false;
      for (unsigned int k = 0; k < 4; ++k)
        if (k != skip)
          (dot(l.normal, sub(position(mesh.tet(t)[k]), l.origin)) > 0 ? above : below) =
            true;
      return above && below;
    };

    // The section is walked from the seed's tetrahedron through the tetrahedra that
    // cross the plane, across the faces that cross it: the cost is that of the section
    // within the blade's extent, not of the mesh (doc/lacerations.md). If the seed's
    // tetrahedron does not cross the plane (a continuation's seed beside it), the
    // nearest that do are looked for up to a few face neighbours away.
    // Stamps instead of clearing: the arrays grow with the mesh, once. The rings
    // looked at around the seed are marked walk + 1, the tetrahedra the walk reached
    // walk; the next walk starts past both.
    tet_walk.resize(mesh.n_tets(), 0);
    edge_walk.resize(mesh.n_edges(), 0);
    edge_in_extent.resize(mesh.n_edges(), 0);
    walk += 2;
    if (walk < 2)
    {
      std::fill(tet_walk.begin(), tet_walk.end(), 0);
      std::fill(edge_walk.begin(), edge_walk.end(), 0);
      walk = 2;
    }
    const unsigned int looked = walk + 1;
    walk_queue.clear();
    walk_ring.assign(1, seed_tet);
    tet_walk[seed_tet] = looked;
    for (unsigned int ring = 0; ring < 4 && walk_queue.empty() && !walk_ring.empty();
         ++ring)
    {
      walk_next_ring.clear();
      for (const unsigned int t : walk_ring)
        if (crosses(t, 4))
          walk_queue.push_back(t);
        else
          for (unsigned int f = 0; f < 4; ++f)
          {
            const unsigned int n = mesh.neighbor(t, f);
            if (n != mesh::invalid_index && tet_walk[n] != looked)
            {
              tet_walk[n] = looked;
              walk_next_ring.push_back(n);
            }
          }
      walk_ring.swap(walk_next_ring);
    }
    for (const unsigned int t : walk_queue)
      tet_walk[t] = walk;
    if (walk_queue.empty())
    {
      // No tetrahedron near the seed meets the plane: every spring is tested.
      for (unsigned int s = 0; s < springs.size(); ++s)
        crossing(s);
      return;
    }
    for (std::size_t i = 0; i < walk_queue.size(); ++i)
    {
      const unsigned int t      = walk_queue[i];
      bool               inside = false;
      for (const unsigned int e : mesh.tet_edges(t))
      {
        if (edge_walk[e] != walk)
        {
          edge_walk[e]      = walk;
          edge_in_extent[e] = crossing(e);
        }
        inside |= edge_in_extent[e] != 0;
      }
      // Beyond the blade's extent the walk stops.
      if (!inside)
        continue;
      for (unsigned int f = 0; f < 4; ++f)
      {
        const unsigned int n = mesh.neighbor(t, f);
        if (n != mesh::invalid_index && tet_walk[n] != walk && crosses(t, f))
        {
          tet_walk[n] = walk;
          walk_queue.push_back(n);
        }
      }
    }
    // In spring order, as a scan would find them: the sums over them do not depend
    // on the walk.
    std::sort(crossings.begin(),
              crossings.end(),
              [](const Crossing &x, const Crossing &y) { return x.spring < y.spring; });
  }


  Blade
  Lacerator::blade_at(const Laceration &l, const double along) const
  {
    const Point centre = add(l.origin, scale(along, l.advance));
    return {add(centre, scale(l.across_lo - l.edge, l.across)),
            add(centre, scale(l.across_hi + l.edge, l.across))};
  }


  void
  Lacerator::advance(const unsigned int    index,
                     const double          from,
                     const double          forced,
                     LacerationStatistics &s)
  {
    Laceration &l = lacerations[index];
    if (!l.cutter)
    {
      // A new laceration, or a stopped one whose particle system was replaced.
      l.cutter = make_cutter(l, from);
      // A stopped laceration continued on a new particle system: its particles on its
      // plane (the opened crack, and the points where the MT closed it inside the cells
      // at its tip) are the new cutter's crack, so that the cells behind the tip open
      // when the front passes them instead of staying a bridge (doc/lacerations.md).
      std::vector<unsigned int> crack;
      for (unsigned int v = 0; v < sheet.size(); ++v)
        if (sheet[v] == index
            && std::abs(dot(l.normal, sub(position(v), l.origin)))
                 <= cut_parameters.snap_fraction * l.edge)
          crack.push_back(v);
      l.cutter->adopt_crack(crack);
    }
    double       u     = from;
    const double exit  = l.end + l.edge;
    const auto   apply = [&](const double next)
    {
      const unsigned int      before = system.n_particles();
      const CutStepStatistics c      = l.cutter->move_blade(blade_at(l, next));
      sheet.resize(system.n_particles(), no_laceration);
      for (unsigned int v = before; v < system.n_particles(); ++v)
      {
        sheet[v] = index;
        lacerations[index].created_rest.push_back(mesh.vertex(v));
      }
      s.cut_tets += c.cut_tets;
      s.created_tets += c.created_tets;
      s.new_particles += c.new_particles;
      s.changed |= c.changed;
      s.copied_particles.insert(s.copied_particles.end(),
                                c.copied_particles.begin(),
                                c.copied_particles.end());
      ++s.advances;
      u = next;
    };
    while (u < exit)
    {
      const double next = std::min(u + l.edge, exit);
      if (next > forced)
      {
        double most  = -std::numeric_limits<double>::infinity();
        bool   ahead = false;
        for (const Crossing &c : crossings)
          if (c.along > u && c.along <= next)
          {
            ahead = true;
            most  = std::max(most, ratio(c.a, c.b));
          }
        // Low stress ahead: the tear stops (a gap in the section is crossed).
        if (ahead && most < parameters.propagation_fraction)
          break;
      }
      apply(next);
    }
    l.stop     = u;
    l.complete = u >= exit;
    if (l.complete)
      l.cutter.reset();
  }


  void
  Lacerator::start(const SurfaceSpring &seed, LacerationStatistics &s)
  {
    const Point xa = position(seed.a), xb = position(seed.b);
    const Point m = midpoint(xa, xb);
    const Point e = normalized(sub(xb, xa));
    Laceration  l;
    l.origin = m;
    // The band of one advance: an element's size (a seed made short by earlier cuts
    // must not make the tear crawl).
    l.edge = std::max(norm(sub(xb, xa)), typical_edge);
    // The plane's normal: the mean direction of the over-stretched springs around the
    // seed, weighted by how far past their limit they are (one spring's direction is
    // the mesh's, the mean is closer to the principal stress).
    Point normal{{0, 0, 0}};
    for (const auto &[r, i] : heap)
    {
      const Point pa = position(surface[i].a), pb = position(surface[i].b);
      if (norm(sub(midpoint(pa, pb), m)) > 2 * l.edge)
        continue;
      Point d = normalized(sub(pb, pa));
      if (dot(d, e) < 0)
        d = scale(-1, d);
      normal = add(normal, scale(r, d));
    }
    l.normal = norm(normal) > 0 ? normalized(normal) : e;
    // The section of the body by the plane, sampled by the springs crossing it: its
    // long axis is the way the tear runs, its short axis (the thickness) the blade's.
    l.across                = l.normal; // unused by the unrestricted search below
    l.across_lo             = -std::numeric_limits<double>::infinity();
    l.across_hi             = std::numeric_limits<double>::infinity();
    const auto search_start = Clock::now();
    find_crossings(l, seed.tet);
    s.search_seconds +=
      std::chrono::duration<double>(Clock::now() - search_start).count();
    const Point helper =
      std::abs(l.normal[0]) < 0.9 ? Point{{1, 0, 0}} : Point{{0, 1, 0}};
    const Point e1 = normalized(cross(l.normal, helper));
    const Point e2 = cross(l.normal, e1);
    Point       centroid{{0, 0, 0}};
    for (const Crossing &c : crossings)
      centroid = add(centroid, c.at);
    if (!crossings.empty())
      centroid = scale(1.0 / crossings.size(), centroid);
    double c11 = 0, c12 = 0, c22 = 0;
    for (const Crossing &c : crossings)
    {
      const double p = dot(e1, sub(c.at, centroid)), q = dot(e2, sub(c.at, centroid));
      c11 += p * p;
      c12 += p * q;
      c22 += q * q;
    }
    const double angle = 0.5 * std::atan2(2 * c12, c11 - c22);
    l.advance          = add(scale(std::cos(angle), e1), scale(std::sin(angle), e2));
    l.across           = cross(l.normal, l.advance);
    double lo = 0, hi = 0;
    l.across_lo = l.across_hi = 0;
    for (const Crossing &c : crossings)
    {
      const Point r = sub(c.at, m);
      lo            = std::min(lo, dot(l.advance, r));
      hi            = std::max(hi, dot(l.advance, r));
      l.across_lo   = std::min(l.across_lo, dot(l.across, r));
      l.across_hi   = std::max(l.across_hi, dot(l.across, r));
    }
    // The tear enters from the end of the section nearest to the seed.
    if (-lo > hi)
    {
      l.advance = scale(-1, l.advance);
      l.across  = scale(-1, l.across);
      std::swap(lo, hi);
      lo = -lo;
      hi = -hi;
      std::swap(l.across_lo, l.across_hi);
      l.across_lo = -l.across_lo;
      l.across_hi = -l.across_hi;
    }
    l.end = hi;
    // The blade's extent holds every crossing found: only their positions along the
    // new direction change.
    for (Crossing &c : crossings)
      c.along = dot(l.advance, sub(c.at, l.origin));
    lacerations.push_back(l);
    // Up to one band past the seed the tear runs whatever the stress: the seed spring
    // must break and the tear must reach the surface.
    advance(lacerations.size() - 1, lo - l.edge, l.edge, s);
  }


  LacerationStatistics
  Lacerator::check()
  {
    LacerationStatistics s;
    if (!surface_valid)
      collect_surface_springs();
    s.surface_springs = static_cast<unsigned int>(surface.size());
    heap.clear();
    const auto less = [](const std::pair<double, unsigned int> &x,
                         const std::pair<double, unsigned int> &y)
    { return x.first < y.first; };
    for (unsigned int i = 0; i < surface.size(); ++i)
    {
      const SurfaceSpring &spring = surface[i];
      const double         now    = norm(sub(position(spring.b), position(spring.a)));
      const double r = (now - spring.rest_length) / spring.rest_length / spring.limit;
      // Springs of a laceration's own faces, or next to its torn part, were split by
      // it; they relax as it opens and do not start another one. Tissue held by an
      // instrument does not tear under its jaws, and the short springs of the splits at a
      // crack tip are no tissue of their own: neither is a seed.
      const bool on_sheet = spring.a < sheet.size() && spring.b < sheet.size()
                            && sheet[spring.a] != no_laceration
                            && sheet[spring.b] != no_laceration;
      if (r >= 1 && !on_sheet
          && !in_wake(midpoint(position(spring.a), position(spring.b)))
          && system.free[spring.a] > 0 && system.free[spring.b] > 0
          && spring.rest_length >= 0.25 * typical_edge)
      {
        heap.emplace_back(r, i);
        std::push_heap(heap.begin(), heap.end(), less);
      }
    }
    s.over_limit = static_cast<unsigned int>(heap.size());
    if (heap.empty() || heap.size() < parameters.threshold)
      return s;

    const auto           t0   = Clock::now();
    const SurfaceSpring &seed = surface[heap.front().second];
    s.torn                    = true;
    s.seed_a                  = seed.a;
    s.seed_b                  = seed.b;
    s.seed_ratio              = heap.front().first;
    const Point x             = midpoint(position(seed.a), position(seed.b));
    for (unsigned int i = 0; i < lacerations.size(); ++i)
    {
      // At the tip of a laceration that stopped inside (a particle it created, or
      // just ahead of its front): it goes on in its own plane, from where it stopped
      // (the stress concentrates at a crack tip).
      Laceration  &l       = lacerations[i];
      const Point  r       = sub(x, l.origin);
      const double u       = dot(l.advance, r);
      const bool   created = (seed.a < sheet.size() && sheet[seed.a] == i)
                           || (seed.b < sheet.size() && sheet[seed.b] == i);
      if (!l.complete
          && (created
              || (std::abs(dot(l.normal, r)) <= l.edge && u > l.stop - l.edge
                  && u <= l.stop + 2 * l.edge)))
      {
        s.continued             = true;
        const auto search_start = Clock::now();
        find_crossings(l, seed.tet);
        s.search_seconds +=
          std::chrono::duration<double>(Clock::now() - search_start).count();
        // Without its cutter (the particle system was replaced) a new one starts at
        // the tip, with the laceration's particles on its plane as its crack
        // (advance()).
        advance(i, l.stop, l.stop, s);
        s.complete = lacerations[i].complete;
        break;
      }
    }
    if (!s.continued)
    {
      start(seed, s);
      s.complete = lacerations.back().complete;
    }
    if (s.changed)
    {
      surface_valid = false;
      ++tears;
    }
    else
      s.torn = false;
    s.update_seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return s;
  }


  std::shared_ptr<Cutter>
  Lacerator::make_cutter(const Laceration &l, const double along)
  {
    auto cutter = std::make_shared<Cutter>(mesh,
                                           system,
                                           density,
                                           youngs_modulus,
                                           integral_of_density,
                                           cut_parameters,
                                           blade_at(l, along));
    cutter->set_recorder(recorder);
    return cutter;
  }


  void
  Lacerator::serialize(Archive &archive)
  {
    archive.section("lacerator");
    archive(surface, surface_valid, sheet, tears, typical_edge);
    std::size_t n = lacerations.size();
    archive    &n;
    lacerations.resize(archive.size(n, 1));
    for (Laceration &l : lacerations)
    {
      archive(l.origin, l.normal, l.advance, l.across, l.edge, l.stop, l.end, l.complete);
      archive(l.across_lo, l.across_hi, l.created_rest);
      // A laceration that may continue keeps its cutter's state (its stroke, its
      // decided crossings); the cutter is made on the loaded mesh, then given it.
      bool     has_cutter = l.cutter != nullptr;
      archive &has_cutter;
      if (archive.loading())
        l.cutter = has_cutter ? make_cutter(l, l.stop) : nullptr;
      if (l.cutter)
        l.cutter->serialize(archive);
    }
  }
} // namespace lacerta::cut
