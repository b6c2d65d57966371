// The cutter on a whole mesh with its particle system: scripted and randomised blade
// strokes, with every invariant checked after every step.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include <memory>
#include <numeric>
#include <random>

namespace
{
  using namespace lacerta;
  using cut::Blade;
  using cut::Point;

  /// A box [0,1]^3 of n^3 cubes as a TetMesh with its particle system and a cutter.
  struct CutFixture
  {
    mesh::TetMesh                            mesh;
    std::unique_ptr<physics::ParticleSystem> system;
    dealii::Functions::ConstantFunction<3>   density{1000.0};
    dealii::Functions::ConstantFunction<3>   youngs{1e4};
    double                                   integral = 0;
    double                                   volume   = 0;
    std::unique_ptr<cut::Cutter>             cutter;

    CutFixture(const unsigned int n,
               std::mt19937      &rng,
               const Blade       &start,
               const double       stretch = 1.0)
    {
      const auto                box = cut::test_support::box_mesh(n, rng);
      std::vector<mesh::Point3> x(box.points.begin(), box.points.end());
      std::vector<mesh::Tet>    t;
      for (const auto &c : box.tets)
        t.push_back({{c[0], c[1], c[2], c[3]}});
      mesh = mesh::TetMesh(x, t, "box");
      std::vector<double> rest;
      for (const auto &p : x)
        rest.insert(rest.end(), p.begin(), p.end());
      system          = std::make_unique<physics::ParticleSystem>(rest);
      system->mass    = physics::compute_masses(mesh, density);
      system->springs = physics::compute_springs(mesh, youngs);
      system->set_force_model(physics::ForceModelRegistry::create("linear springs"), 1);
      integral = physics::integrate_over_mesh(mesh, density);
      volume   = mesh.total_volume();
      // A deformed configuration: stretched along y. The blade cuts what it sees.
      for (unsigned int i = 0; i < system->n_particles(); ++i)
        system->position[3 * i + 1] *= stretch;
      cutter = std::make_unique<cut::Cutter>(
        mesh, *system, density, youngs, integral, cut::Cutter::Parameters(), start);
    }

    void
    expect_invariants(const std::string &where) const
    {
      const std::string problem = cut::check_invariants(mesh, *system, volume, integral);
      ASSERT_EQ(problem, "") << where;
      ASSERT_NEAR(integral, 1000.0, 1e-9) << where;
    }

    /// Moves the blade through @p path in @p steps equal steps per segment.
    void
    stroke(const std::vector<Blade> &path, const unsigned int steps)
    {
      cut::test_support::stroke(*cutter,
                                path,
                                steps,
                                [&](const std::size_t k, const unsigned int s)
                                {
                                  expect_invariants("segment " + std::to_string(k)
                                                    + " step " + std::to_string(s));
                                  return !::testing::Test::HasFatalFailure();
                                });
    }

    /// Volumes of the connected components, sorted.
    std::vector<double>
    component_volumes() const
    {
      return cut::component_volumes(mesh);
    }
  };

  /// A vertical blade through the whole box at (x, y), spanning z from -0.5 to 1.5.
  Blade
  vertical(const double x, const double y)
  {
    return {{{x, y, 1.5}}, {{x, y, -0.5}}};
  }
} // namespace


TEST(CutCutter, CompleteStraightCutSeparatesTwoPiecesOfTheRightVolume)
{
  std::mt19937 rng(1);
  // Stretched by 1.5 along y: the blade at y = 0.555 cuts the rest configuration at
  // y = 0.37 (the swept surface is mapped back through the deformation).
  CutFixture f(4, rng, vertical(-0.2, 0.555), 1.5);
  f.stroke({vertical(-0.2, 0.555), vertical(1.2, 0.555)}, 16);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const auto pieces = f.component_volumes();
  ASSERT_EQ(pieces.size(), 2u);
  EXPECT_EQ(cut::count_components(f.mesh), 2u);
  // Snapping moves the surface by at most ε of an edge (0.05 * 0.25).
  EXPECT_NEAR(pieces[0], 0.37, 0.0125);
}


TEST(CutCutter, PartialCutKeepsOnePieceUntilTheBladeLeaves)
{
  std::mt19937 rng(2);
  CutFixture   f(4, rng, vertical(-0.2, 0.43));
  f.stroke({vertical(-0.2, 0.43), vertical(0.6, 0.43)}, 10);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_EQ(cut::count_components(f.mesh), 1u);
  EXPECT_GT(f.mesh.n_tets(), 384u);
  f.stroke({vertical(0.6, 0.43), vertical(1.3, 0.43)}, 10);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  EXPECT_EQ(cut::count_components(f.mesh), 2u);
}


TEST(CutCutter, CutsThroughVerticesAndAlongFacesKeepTheInvariants)
{
  // y = 0.5 holds a layer of vertices and faces of the Kuhn triangulation; a diagonal
  // plane x = y passes through vertices and along faces too.
  for (const bool diagonal : {false, true})
  {
    std::mt19937 rng(3);
    const Blade  a = diagonal ? vertical(-0.2, -0.2) : vertical(-0.2, 0.5);
    const Blade  b = diagonal ? vertical(1.2, 1.2) : vertical(1.2, 0.5);
    CutFixture   f(4, rng, a);
    f.stroke({a, b}, 12);
    ASSERT_FALSE(::testing::Test::HasFatalFailure())
      << (diagonal ? "diagonal" : "y = 0.5");
    // Known limit (doc/cutting.md): a cut exactly along a plane of mesh vertices
    // opens only when the whole group of on-surface vertices is reached inside one
    // sweep's affected set, so it does not separate yet; the invariants hold.
  }
}


TEST(CutCutter, GrazingAndLeavingRepeatedlyKeepTheInvariants)
{
  std::mt19937 rng(4);
  // In and out through the side face x = 0, then grazing the face z = 1 with the tip.
  const std::vector<Blade> path = {vertical(-0.3, 0.3),
                                   vertical(0.3, 0.35),
                                   vertical(-0.3, 0.45),
                                   vertical(0.3, 0.6),
                                   vertical(-0.3, 0.7),
                                   {{{0.5, -0.2, 1.2}}, {{0.5, -0.2, 0.999}}},
                                   {{{0.5, 1.2, 1.2}}, {{0.5, 1.2, 0.999}}}};
  CutFixture               f(4, rng, path[0]);
  f.stroke(path, 6);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  // Each pair of legs in and out through x = 0 cuts a wedge free.
  EXPECT_GE(cut::count_components(f.mesh), 3u);
}


TEST(CutCutter, RandomStrokesKeepTheInvariants)
{
  std::uniform_real_distribution<double> u(0.05, 0.95), angle(0, 3.14159);
  unsigned int                           separated = 0;
  for (unsigned int seed = 0; seed < 6; ++seed)
  {
    std::mt19937 rng(100 + seed);
    // A straight stroke through the box at a random angle, cut in random steps.
    const double phi = angle(rng), cx = u(rng), cy = u(rng);
    const Point  dir{{std::cos(phi), std::sin(phi), 0}};
    const Blade  a = vertical(cx - 1.0 * dir[0], cy - 1.0 * dir[1]);
    const Blade  b = vertical(cx + 1.0 * dir[0], cy + 1.0 * dir[1]);
    CutFixture   f(3, rng, a);
    f.stroke({a, b}, 5 + seed * 3);
    ASSERT_FALSE(::testing::Test::HasFatalFailure()) << "seed " << seed;
    separated += cut::count_components(f.mesh) == 2;
  }
  // Strokes whose sweeps are postponed too often restart at the blade and leave a
  // bridge (doc/cutting.md, limits); most separate.
  EXPECT_GE(separated, 4u);
}


TEST(CutCutter, ClosedLoopPunchesAHole)
{
  std::mt19937 rng(5);
  // A square loop inside the box, passing its start again: the inside drops out.
  const std::vector<Blade> loop = {vertical(0.3, 0.3),
                                   vertical(0.7, 0.3),
                                   vertical(0.7, 0.7),
                                   vertical(0.3, 0.7),
                                   vertical(0.3, 0.25)};
  // The blade enters from above, then runs the loop.
  const Blade above{{{0.3, 0.3, 2.5}}, {{0.3, 0.3, 1.2}}};
  CutFixture  f(4, rng, above);
  f.stroke({above, loop[0]}, 4);
  f.stroke(loop, 8);
  ASSERT_FALSE(::testing::Test::HasFatalFailure());
  const auto pieces = f.component_volumes();
  // The loop cuts pieces free; with postponed sweeps at the corners it may leave
  // bridges or cut a cell beyond a corner, so the piece count is not yet exactly
  // two (doc/cutting.md, limits). All invariants hold after every step.
  EXPECT_GE(pieces.size(), 2u);
}
