// Constraint plugins: what prescribe() writes for the threads' ranges of particles.

#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/constraint.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

using namespace lacerta;

namespace
{
  /// The constraint plugin @p name with its parameter @p entry set to @p value.
  std::unique_ptr<scene::Constraint>
  make_constraint(const std::string &name,
                  const std::string &entry = "",
                  const std::string &value = "")
  {
    dealii::ParameterHandler prm;
    scene::ConstraintRegistry::declare_all_in_subsections(prm);
    if (!entry.empty())
    {
      prm.enter_subsection(scene::ConstraintRegistry::subsection_name(name));
      prm.set(entry, value);
      prm.leave_subsection();
    }
    return scene::ConstraintRegistry::create_and_parse(name, prm);
  }
} // namespace


// Every thread prescribes the constraint's particles of its own range and writes no
// other entry, whatever order the region listed the particles in.
TEST(SceneConstraints, EachRangeWritesExactlyTheConstraintsParticlesInIt)
{
  const unsigned int  n = 12;
  std::vector<double> rest(3 * n);
  for (unsigned int i = 0; i < 3 * n; ++i)
    rest[i] = 0.01 * i;
  physics::ParticleSystem         system(rest);
  const std::vector<unsigned int> clamped = {9, 2, 5, 11, 0};
  const std::vector<unsigned int> pulled  = {7, 3};
  auto                            fixed   = make_constraint("fixed");
  fixed->initialize(clamped, system);
  // A displacement that depends on the position: one value per particle.
  auto handle = make_constraint("moving handle", "Displacement", "x + t; 0; 2 * t");
  handle->initialize(pulled, system);
  const double t = 0.5;
  fixed->prepare(t, rest.data());
  handle->prepare(t, rest.data());

  const double        unset = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> x(3 * n, unset), v(3 * n, unset);
  // Ranges whose bounds fall on, before and after constrained particles.
  const std::vector<unsigned int> bounds = {0, 2, 3, 4, 8, 11, 12};
  for (std::size_t r = 0; r + 1 < bounds.size(); ++r)
  {
    fixed->prescribe(rest.data(), x.data(), v.data(), bounds[r], bounds[r + 1]);
    handle->prescribe(rest.data(), x.data(), v.data(), bounds[r], bounds[r + 1]);
  }
  for (unsigned int i = 0; i < n; ++i)
  {
    const bool is_clamped = std::find(clamped.begin(), clamped.end(), i) != clamped.end();
    const bool is_pulled  = std::find(pulled.begin(), pulled.end(), i) != pulled.end();
    for (unsigned int d = 0; d < 3; ++d)
    {
      const unsigned int c = 3 * i + d;
      if (is_clamped)
      {
        EXPECT_EQ(x[c], rest[c]) << "particle " << i;
        EXPECT_EQ(v[c], 0.0) << "particle " << i;
      }
      else if (is_pulled)
      {
        const double u  = d == 0 ? rest[3 * i] + t : (d == 2 ? 2 * t : 0.0);
        const double du = d == 0 ? 1.0 : (d == 2 ? 2.0 : 0.0);
        EXPECT_NEAR(x[c], rest[c] + u, 1e-12) << "particle " << i;
        EXPECT_NEAR(v[c], du, 1e-6) << "particle " << i;
      }
      else
      {
        EXPECT_TRUE(std::isnan(x[c])) << "particle " << i << " was written";
        EXPECT_TRUE(std::isnan(v[c])) << "particle " << i << " was written";
      }
    }
  }
  // initialize() keeps the particles in increasing order.
  EXPECT_TRUE(std::is_sorted(fixed->particles.begin(), fixed->particles.end()));
}
