// Mass redistribution (physics::MassBalancer): the bound at rest comes back under the
// target, the mass of every piece is kept, and nothing moves where nothing is needed.
#include <lacerta/physics/mass_balancer.h>
#include <lacerta/physics/stability.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

using namespace lacerta;

namespace
{
  /// The largest row bound at rest over the free particles.
  double
  rest_bound(const physics::ParticleSystem &system)
  {
    const std::vector<double> row = test_support::rest_row_bounds(system);
    return *std::max_element(row.begin(), row.end());
  }


  double
  total_mass(const physics::ParticleSystem &system)
  {
    return std::accumulate(system.mass.begin(), system.mass.end(), 0.0);
  }


  /// The vertex nearest the box's centre.
  unsigned int
  interior_particle(const mesh::TetMesh &mesh)
  {
    unsigned int nearest  = 0;
    double       distance = std::numeric_limits<double>::infinity();
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    {
      const auto  &p = mesh.vertex(v);
      const double d = std::hypot(p[0] - 0.5, p[1] - 0.5, p[2] - 0.5);
      if (d < distance)
      {
        distance = d;
        nearest  = v;
      }
    }
    return nearest;
  }
} // namespace


TEST(PhysicsMassBalancer, TheSystemItWasMadeForNeedsNothing)
{
  mesh::TetMesh mesh = test_support::distorted_box(4, 0.2, {1, 1, 1});
  mesh.enable_local_updates();
  auto                      system = test_support::make_system(mesh, 1000, 1e4);
  const std::vector<double> before = system->mass;
  physics::MassBalancer     balancer(*system, 3);
  EXPECT_NEAR(balancer.target(), rest_bound(*system), 1e-12 * balancer.target());
  const physics::MassBalanceStatistics s = balancer.balance(*system);
  EXPECT_EQ(s.raised, 0u);
  EXPECT_EQ(s.unresolved, 0u);
  EXPECT_EQ(system->mass, before);
}


TEST(PhysicsMassBalancer, ALightParticleIsRaisedToTheTargetFromItsNeighbours)
{
  mesh::TetMesh mesh = test_support::distorted_box(4, 0.2, {1, 1, 1});
  mesh.enable_local_updates();
  auto                  system = test_support::make_system(mesh, 1000, 1e4);
  physics::MassBalancer balancer(*system, 3);
  // Most of one particle's mass goes to a neighbour, as when a cut leaves it with
  // small cells only: its bound rises far above the target.
  const unsigned int i = interior_particle(mesh);
  unsigned int       j = i;
  for (std::size_t s = 0; s < system->springs.size() && j == i; ++s)
    if (system->springs.a[s] == i)
      j = system->springs.b[s];
  ASSERT_NE(i, j);
  const double total = total_mass(*system);
  system->mass[j] += 0.999 * system->mass[i];
  system->mass[i] *= 0.001;
  ASSERT_GT(rest_bound(*system), 10 * balancer.target());

  const physics::MassBalanceStatistics s = balancer.balance(*system);
  EXPECT_GE(s.raised, 1u);
  EXPECT_EQ(s.unresolved, 0u);
  EXPECT_GT(s.moved, 0);
  EXPECT_LE(rest_bound(*system),
            physics::MassBalancer::donor_headroom * balancer.target() * (1 + 1e-9));
  EXPECT_NEAR(total_mass(*system), total, 1e-13 * total);
  for (const double m : system->mass)
    EXPECT_GT(m, 0);
}


TEST(PhysicsMassBalancer, AParticleWithoutMassIsGivenSomeAndConstrainedOnesKeepTheirs)
{
  mesh::TetMesh mesh = test_support::distorted_box(4, 0.1, {1, 1, 1});
  mesh.enable_local_updates();
  auto system = test_support::make_system(mesh, 1000, 1e4);
  // The face x = 0 is held: its particles neither give nor take.
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    if (mesh.vertex(v)[0] < 1e-12)
      system->free[v] = 0;
  physics::MassBalancer     balancer(*system, 2);
  const unsigned int        i      = interior_particle(mesh);
  const std::vector<double> before = system->mass;
  const double              total  = total_mass(*system);
  // A particle left with a negative mass (a donor that lost cells to a cut since).
  system->mass[i] = -0.1 * before[i];
  system->mass[(i + 1) % system->n_particles()] += 1.1 * before[i];
  balancer.balance(*system);
  EXPECT_GT(system->mass[i], 0);
  EXPECT_LE(rest_bound(*system),
            physics::MassBalancer::donor_headroom * balancer.target() * (1 + 1e-9));
  EXPECT_NEAR(total_mass(*system), total, 1e-13 * total);
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    if (system->free[v] == 0 && v != (i + 1) % system->n_particles())
    {
      EXPECT_EQ(system->mass[v], before[v]) << "constrained particle " << v;
    }
}


TEST(PhysicsMassBalancer, ATinyPieceOnItsOwnKeepsItsMassAndIsReported)
{
  // One tetrahedron far lighter than its stiffness allows, and nothing else within
  // reach: mass cannot come from another piece.
  mesh::TetMesh mesh = test_support::distorted_box(2, 0, {1, 1, 1});
  mesh.enable_local_updates();
  auto                  system = test_support::make_system(mesh, 1000, 1e4);
  physics::MassBalancer balancer(*system, 3);
  mesh::TetMesh         tet({{{0, 0, 0}}, {{0.01, 0, 0}}, {{0, 0.01, 0}}, {{0, 0, 0.01}}},
                    {{{0, 1, 2, 3}}},
                    "one tetrahedron");
  tet.enable_local_updates();
  auto piece = test_support::make_system(tet, 1000, 1e4);
  piece->mass.assign(4, 1e-9);
  const physics::MassBalanceStatistics s = balancer.balance(*piece);
  EXPECT_EQ(s.unresolved, 4u);
  EXPECT_EQ(s.moved, 0);
  EXPECT_EQ(piece->mass, std::vector<double>(4, 1e-9));
}
