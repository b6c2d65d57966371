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


  /// Moves most of the mass of the particle nearest the box's centre to a neighbour,
  /// as when a cut leaves it with small cells only; returns that particle.
  unsigned int
  make_interior_particle_light(const mesh::TetMesh &mesh, physics::ParticleSystem &system)
  {
    const unsigned int i = interior_particle(mesh);
    unsigned int       j = i;
    for (std::size_t s = 0; s < system.springs.size() && j == i; ++s)
      if (system.springs.a[s] == i)
        j = system.springs.b[s];
    EXPECT_NE(i, j);
    system.mass[j] += 0.999 * system.mass[i];
    system.mass[i] *= 0.001;
    return i;
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
  // Most of one particle's mass goes to a neighbour: its bound rises far above the
  // target.
  const double total = total_mass(*system);
  make_interior_particle_light(mesh, *system);
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


TEST(PhysicsMassBalancer,
     TakingBackTheGiftsOfADonorThatLostItsCellsCreatesNoKineticEnergy)
{
  mesh::TetMesh mesh = test_support::distorted_box(4, 0.2, {1, 1, 1});
  mesh.enable_local_updates();
  auto system = test_support::make_system(mesh, 1000, 1e4);
  // Mass from the nearest ring only.
  physics::MassBalancer balancer(*system, 1);
  // As above: one particle left light and raised from its neighbours; it alone moves.
  const unsigned int        i      = make_interior_particle_light(mesh, *system);
  const std::vector<double> lumped = system->mass;
  balancer.balance(*system);
  // The donor that gave most.
  unsigned int d     = i;
  double       given = 0;
  for (unsigned int p = 0; p < system->n_particles(); ++p)
    if (lumped[p] - system->mass[p] > given)
    {
      given = lumped[p] - system->mass[p];
      d     = p;
    }
  ASSERT_GT(given, 0);
  std::fill(system->velocity.begin(), system->velocity.end(), 0.0);
  system->velocity[3 * i] = 1;
  const auto kinetic      = [&]
  {
    double e = 0;
    for (unsigned int p = 0; p < system->n_particles(); ++p)
      e +=
        0.5 * system->mass[p]
        * (std::pow(system->velocity[3 * p], 2) + std::pow(system->velocity[3 * p + 1], 2)
           + std::pow(system->velocity[3 * p + 2], 2));
    return e;
  };
  const double before = kinetic();
  // A cut takes most of the donor's cells (to a copy, at rest): its own mass falls to a
  // tenth of what it gave, so it holds less than nothing until its gifts come back. Its
  // other neighbours are held, so that nothing can raise it again afterwards (as when
  // the particles within reach cannot spare what it needs).
  system->mass[d] -= lumped[d] - 0.1 * given;
  for (std::size_t s = 0; s < system->springs.size(); ++s)
    for (const auto &[p, q] : {std::pair{system->springs.a[s], system->springs.b[s]},
                               std::pair{system->springs.b[s], system->springs.a[s]}})
      if (p == d && q != i)
        system->free[q] = 0;
  balancer.rebalance(*system, {d});
  EXPECT_GT(system->mass[d], 0);
  EXPECT_LE(kinetic(), before * (1 + 1e-12));
  for (unsigned int p = 0; p < system->n_particles(); ++p)
    EXPECT_LE(std::hypot(system->velocity[3 * p],
                         system->velocity[3 * p + 1],
                         system->velocity[3 * p + 2]),
              1 + 1e-12)
      << "particle " << p;
}
