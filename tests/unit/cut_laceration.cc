// Lacerations (Section 7) on a slab: the threshold h, a tear that stops where the stress
// is low against the tissue's strength or where a pull near one edge fades, a complete
// tear, the invariants after a tear and a later scalpel cut, the dynamics after a tear,
// and a bad maximum elongation.
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/integrator.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>

#include <deal.II/base/function.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <set>

namespace
{
  using namespace lacerta;
  using cut::Point;

  /// A function of the rest position given by a lambda.
  class Field : public dealii::Function<3>
  {
  public:
    explicit Field(std::function<double(const dealii::Point<3> &)> f)
        : f(std::move(f))
    {
    }

    double
    value(const dealii::Point<3> &p, unsigned int = 0) const override
    {
      return f(p);
    }

  private:
    std::function<double(const dealii::Point<3> &)> f;
  };

  /**
   * A slab [0,1] x [0,1] x [0,0.25] of 8 x 8 x 2 cubes (six tetrahedra each around the
   * main diagonal), its particle system, deformed by @p deformation of the rest
   * position, and a lacerator with the given limit and threshold.
   */
  struct TearFixture
  {
    mesh::TetMesh                            mesh;
    std::unique_ptr<physics::ParticleSystem> system;
    dealii::Functions::ConstantFunction<3>   density{1000.0};
    dealii::Functions::ConstantFunction<3>   youngs{1e4};
    Field                                    limit;
    double                                   integral = 0;
    double                                   volume   = 0;
    std::unique_ptr<cut::Lacerator>          lacerator;

    TearFixture(const std::function<Point(const Point &)>             &deformation,
                const std::function<double(const dealii::Point<3> &)> &limit_field,
                const unsigned int                                     threshold,
                const double                                           fraction = 0.5)
        : limit(limit_field)
    {
      const unsigned int        nx = 8, ny = 8, nz = 2;
      std::vector<mesh::Point3> x;
      const auto index = [&](unsigned int i, unsigned int j, unsigned int k)
      { return (k * (ny + 1) + j) * (nx + 1) + i; };
      for (unsigned int k = 0; k <= nz; ++k)
        for (unsigned int j = 0; j <= ny; ++j)
          for (unsigned int i = 0; i <= nx; ++i)
            x.push_back({{double(i) / nx, double(j) / ny, 0.125 * k}});
      const std::array<std::array<unsigned int, 3>, 6> paths = {
        {{{0, 1, 2}}, {{0, 2, 1}}, {{1, 0, 2}}, {{1, 2, 0}}, {{2, 0, 1}}, {{2, 1, 0}}}};
      std::vector<mesh::Tet> tets;
      for (unsigned int k = 0; k < nz; ++k)
        for (unsigned int j = 0; j < ny; ++j)
          for (unsigned int i = 0; i < nx; ++i)
            for (const auto &path : paths)
            {
              std::array<unsigned int, 3> c{{i, j, k}};
              mesh::Tet                   t;
              t[0] = index(c[0], c[1], c[2]);
              for (unsigned int s = 0; s < 3; ++s)
              {
                ++c[path[s]];
                t[s + 1] = index(c[0], c[1], c[2]);
              }
              if (mesh::signed_volume(x[t[0]], x[t[1]], x[t[2]], x[t[3]]) < 0)
                std::swap(t[0], t[1]);
              tets.push_back(t);
            }
      mesh     = mesh::TetMesh(x, tets, "slab");
      system   = test_support::make_system(mesh,
                                         density.value(dealii::Point<3>()),
                                         youngs.value(dealii::Point<3>()));
      integral = physics::integrate_over_mesh(mesh, density);
      volume   = mesh.total_volume();
      for (unsigned int i = 0; i < system->n_particles(); ++i)
      {
        const Point y = deformation(x[i]);
        for (unsigned int d = 0; d < 3; ++d)
          system->position[3 * i + d] = y[d];
      }
      cut::Lacerator::Parameters parameters;
      parameters.threshold            = threshold;
      parameters.propagation_fraction = fraction;
      lacerator                       = std::make_unique<cut::Lacerator>(mesh,
                                                   *system,
                                                   density,
                                                   youngs,
                                                   limit,
                                                   integral,
                                                   cut::Cutter::Parameters(),
                                                   parameters);
    }

    /// Surface springs past their limit, counted here from the boundary faces.
    unsigned int
    count_over_limit() const
    {
      std::set<std::pair<unsigned int, unsigned int>> edges;
      for (const auto &f : mesh.get_boundary_faces())
        for (unsigned int k = 0; k < 3; ++k)
        {
          const auto        &fv = mesh::TetMesh::face_vertices[f.face];
          const unsigned int a  = mesh.tet(f.tet)[fv[k]];
          const unsigned int b  = mesh.tet(f.tet)[fv[(k + 1) % 3]];
          edges.insert({std::min(a, b), std::max(a, b)});
        }
      unsigned int n = 0;
      for (const auto &[a, b] : edges)
      {
        const Point  &ra = mesh.vertex(a), &rb = mesh.vertex(b);
        const double *xa = &system->position[3 * a], *xb = &system->position[3 * b];
        const double  rest = cut::norm(cut::sub(rb, ra));
        const double  now  = std::hypot(xb[0] - xa[0], xb[1] - xa[1], xb[2] - xa[2]);
        const auto    m    = cut::scale(0.5, cut::add(ra, rb));
        if ((now - rest) / rest >= limit.value(dealii::Point<3>(m[0], m[1], m[2])))
          ++n;
      }
      return n;
    }

    void
    expect_invariants(const std::string &where) const
    {
      ASSERT_EQ(cut::check_invariants(mesh, *system, volume, integral), "") << where;
      ASSERT_NEAR(integral, 1000.0 * 0.25, 1e-9) << where;
    }

    /// Rest-configuration extent in y of the faces a tear or cut opened.
    std::pair<double, double>
    torn_y_range() const
    {
      double lo = 1e300, hi = -1e300;
      for (const auto &f : mesh.get_boundary_faces())
        if (f.boundary_id == cut::cut_boundary_id)
          for (const unsigned int k : mesh::TetMesh::face_vertices[f.face])
          {
            lo = std::min(lo, mesh.vertex(mesh.tet(f.tet)[k])[1]);
            hi = std::max(hi, mesh.vertex(mesh.tet(f.tet)[k])[1]);
          }
      return {lo, hi};
    }
  };

  /// Uniform stretch by @p s along x about x = @p centre.
  std::function<Point(const Point &)>
  stretch_x(const double s, const double centre = 0.5)
  {
    return [s, centre](const Point &p) {
      return Point{{centre + (1 + s) * (p[0] - centre), p[1], p[2]}};
    };
  }

  /**
   * Tissue that is weak near the edge y = 1 and strong away from it: under a uniform
   * stretch of 0.4 the springs along x are past their limit for y > 0.78 and past half
   * of it for y > 0.5 only.
   */
  double
  weak_near_one_edge(const dealii::Point<3> &p)
  {
    return 0.3 + 2 * (1 - p[1]) * (1 - p[1]);
  }

  double
  constant_limit(const dealii::Point<3> &)
  {
    return 0.3;
  }

  /// Slightly weaker towards y = 1, so that a uniform stretch seeds the tear there.
  double
  weaker_towards_y1(const dealii::Point<3> &p)
  {
    return 0.3 - 0.02 * p[1];
  }


  /**
   * Tears @p f once and checks a partial tear: from the rim y = 1, stopping inside
   * between y = 0.3 and 0.7 (where the springs ahead fall below half their limit, at
   * y = 0.5, within about an element), the slab in one piece and every invariant kept.
   */
  void
  expect_tear_from_the_rim_that_stops_inside(TearFixture &f)
  {
    const cut::LacerationStatistics s = f.lacerator->check();
    ASSERT_TRUE(s.torn);
    EXPECT_FALSE(s.complete);
    f.expect_invariants("after the tear");
    ASSERT_FALSE(::testing::Test::HasFatalFailure());
    EXPECT_EQ(cut::count_components(f.mesh), 1u);
    const auto [lo, hi] = f.torn_y_range();
    EXPECT_NEAR(hi, 1.0, 1e-12);
    EXPECT_GT(lo, 0.3);
    EXPECT_LT(lo, 0.7);
  }
} // namespace


TEST(CutLaceration, NoTearUntilThresholdSpringsExceedTheLimit)
{
  // Stretched by 0.4 along x: every surface spring along x is past the limit 0.3.
  const unsigned int over =
    TearFixture(stretch_x(0.4), constant_limit, 1000).count_over_limit();
  ASSERT_GT(over, 10u);
  for (const unsigned int h : {1000u, over + 1, over})
  {
    TearFixture                     f(stretch_x(0.4), constant_limit, h);
    const unsigned int              tets = f.mesh.n_tets();
    const cut::LacerationStatistics s    = f.lacerator->check();
    EXPECT_EQ(s.over_limit, over) << "h = " << h;
    EXPECT_EQ(s.torn, h <= over) << "h = " << h;
    EXPECT_EQ(f.mesh.n_tets() > tets, h <= over) << "h = " << h;
    EXPECT_EQ(f.lacerator->n_tears(), h <= over ? 1u : 0u);
    f.expect_invariants("h = " + std::to_string(h));
  }
  // Below the limit nothing is in the heap at all.
  TearFixture f(stretch_x(0.2), constant_limit, 1);
  EXPECT_EQ(f.lacerator->check().over_limit, 0u);
  EXPECT_EQ(f.mesh.n_tets(), 768u);
}


TEST(CutLaceration, UniformStretchTearsThroughTheSlab)
{
  TearFixture                     f(stretch_x(0.4), constant_limit, 3);
  const cut::LacerationStatistics s = f.lacerator->check();
  ASSERT_TRUE(s.torn);
  EXPECT_TRUE(s.complete);
  EXPECT_GT(s.cut_tets, 0u);
  f.expect_invariants("after the tear");
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  // Orthogonal to the pull: two pieces, split across x.
  const auto pieces = cut::component_volumes(f.mesh);
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_GT(pieces[0], 0.01);
}


TEST(CutLaceration, TearStopsWhereTheStressIsLow)
{
  TearFixture f(stretch_x(0.4), weak_near_one_edge, 3);
  // It starts at the weak edge y = 1 and stops within about an element of where the
  // springs ahead fall below half their limit (y = 0.5).
  expect_tear_from_the_rim_that_stops_inside(f);
}


TEST(CutLaceration, TearStopsWhereAPullNearOneEdgeFades)
{
  // Uniform tissue, pulled along x near the edge y = 1 only: the stretch 0.6 y^2 puts
  // the springs along x past the limit 0.3 for y > 0.71 and past half of it for
  // y > 0.5 only, so the tear must start at y = 1 and stop inside the slab.
  const auto pulled_near_one_edge = [](const Point &p)
  {
    const double s = 0.6 * p[1] * p[1];
    return Point{{0.5 + (1 + s) * (p[0] - 0.5), p[1], p[2]}};
  };
  TearFixture f(pulled_near_one_edge, constant_limit, 3);
  expect_tear_from_the_rim_that_stops_inside(f);
  const auto [lo, hi] = f.torn_y_range();
  std::cout << "tear from y = " << hi << " down to y = " << lo << '\n';
}


TEST(CutLaceration, AStoppedTearContinuesFromItsTipWhenThePullGrows)
{
  // Weak only in the column of cells 0.375 < x < 0.5: the first tear takes its
  // over-stretched springs; the rest of the slab is strong.
  const auto limit = [](const dealii::Point<3> &p)
  { return std::abs(p[0] - 0.4375) < 0.07 ? weak_near_one_edge(p) : 10.0; };
  TearFixture                     f(stretch_x(0.4, 0.4375), limit, 3);
  const cut::LacerationStatistics first = f.lacerator->check();
  ASSERT_TRUE(first.torn);
  ASSERT_FALSE(first.complete);
  const double stop = f.torn_y_range().first;
  // Nothing left to tear at this stretch.
  EXPECT_FALSE(f.lacerator->check().torn);
  // Pulled further (about the tear's plane, so that its tip stays where it was), the
  // springs ahead of the tip pass their limit: the same laceration goes on from its
  // tip (no second plane beside it) and reaches lower.
  const auto more = stretch_x(1.5, 0.4375);
  for (unsigned int i = 0; i < f.system->n_particles(); ++i)
  {
    const Point y = more(f.mesh.vertex(i));
    for (unsigned int d = 0; d < 3; ++d)
      f.system->position[3 * i + d] = y[d];
  }
  const cut::LacerationStatistics second = f.lacerator->check();
  ASSERT_TRUE(second.torn);
  EXPECT_TRUE(second.continued);
  EXPECT_EQ(f.lacerator->n_tears(), 2u);
  EXPECT_LT(f.torn_y_range().first, stop - 0.05);
  f.expect_invariants("after the continuation");
  // Past half their limit down to y = 0 at this stretch: the tear goes through.
  EXPECT_TRUE(second.complete);
  EXPECT_EQ(cut::count_components(f.mesh), 2u);
}


namespace
{
  /**
   * Cuts the slab of @p f along y = 0.2 with a scalpel through the whole thickness
   * and across a tear's plane x = 0.4375, in 30 steps, checking every invariant after
   * each: the strip y < 0.2 comes off.
   */
  void
  cut_off_the_strip(TearFixture &f)
  {
    const auto blade = [](const double x) -> cut::Blade {
      return {{{x, 0.2, 0.5}}, {{x, 0.2, -0.25}}};
    };
    cut::Cutter cutter(f.mesh,
                       *f.system,
                       f.density,
                       f.youngs,
                       f.integral,
                       cut::Cutter::Parameters(),
                       blade(-0.5));
    for (unsigned int k = 1; k <= 30; ++k)
    {
      cutter.move_blade(blade(-0.5 + 2.5 * k / 30));
      f.expect_invariants("scalpel step " + std::to_string(k));
      if (::testing::Test::HasFatalFailure())
        return;
    }
  }
} // namespace


TEST(CutLaceration, LaceratedThenCutKeepsEveryInvariant)
{
  TearFixture f(stretch_x(0.4), weak_near_one_edge, 3);
  ASSERT_TRUE(f.lacerator->check().torn);
  // The crack and the cut cross.
  cut_off_the_strip(f);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  // The scalpel separated the strip y < 0.2 (at rest); the tear did not reach it.
  EXPECT_EQ(cut::count_components(f.mesh), 2u);
  // The lacerator sees the new faces and stays consistent.
  f.lacerator->mesh_changed();
  f.lacerator->check();
  f.expect_invariants("after a second check");
}


TEST(CutLaceration, ATearStaysInThePieceItStartsIn)
{
  // A uniform stretch past the limit everywhere (the most at the rim y = 1, where the
  // tear starts), after a scalpel separated the strip y < 0.2: the tear's plane
  // crosses both pieces, but the springs crossing it are found by walking from the
  // seed, so only the seed's piece tears through (3 pieces). A search over every
  // spring crossing the plane tore both (4 pieces).
  TearFixture f(stretch_x(0.4), weaker_towards_y1, 3);
  cut_off_the_strip(f);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  ASSERT_EQ(cut::count_components(f.mesh), 2u);
  f.lacerator->mesh_changed();
  const cut::LacerationStatistics tear = f.lacerator->check();
  ASSERT_TRUE(tear.torn);
  EXPECT_TRUE(tear.complete);
  f.expect_invariants("after the tear");
  EXPECT_EQ(cut::count_components(f.mesh), 3u);
}


TEST(CutLaceration, DynamicsStayStableAfterATear)
{
  TearFixture f(stretch_x(0.4), constant_limit, 3);
  ASSERT_TRUE(f.lacerator->check().torn);
  f.expect_invariants("after the tear");
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  physics::ParticleSystem &system = *f.system;
  system.mass_damping             = 2;
  const auto integrator           = physics::IntegratorRegistry::create("rk4");
  integrator->initialize(system);
  const double omega = physics::bound_highest_frequency(system).omega;
  const double dt    = 0.9 * integrator->critical_time_step(omega, 2, 0);
  ASSERT_GT(dt, 0);
  // Free and damped after the tear: the mechanical energy only decreases and the
  // two halves spring back towards their rest length.
  const double initial = system.kinetic_energy() + system.elastic_energy();
  double       energy  = initial;
  ASSERT_GT(energy, 0);
  for (unsigned int step = 1; step <= 2000; ++step)
  {
    integrator->step(system, step * dt, dt);
    if (step % 100 == 0)
    {
      const double now = system.kinetic_energy() + system.elastic_energy();
      ASSERT_TRUE(std::isfinite(now)) << "step " << step;
      EXPECT_LE(now, energy * (1 + 1e-6)) << "step " << step;
      energy = now;
    }
  }
  EXPECT_LT(energy, 0.5 * initial);
}


TEST(CutLaceration, MaximumElongationOutOfRangeIsAnError)
{
  for (const double bad : {-0.1, 0.0, 1e3, std::nan("")})
    try
    {
      TearFixture f(
        stretch_x(0.4), [bad](const dealii::Point<3> &) { return bad; }, 3);
      ADD_FAILURE() << "no error for " << bad;
    }
    catch (const Error &e)
    {
      EXPECT_NE(std::string(e.what()).find("Material/Maximum elongation"),
                std::string::npos)
        << e.what();
    }
}
