// The time-step loop allocates nothing: every integrator and every force model keep
// their scratch space from initialize().

#include <lacerta/physics/integrator.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <atomic>
#include <cstdlib>
#include <new>

namespace
{
  std::atomic<bool>        counting{false};
  std::atomic<std::size_t> allocations{0};
} // namespace

// Count every allocation through operator new while `counting` is set.
void *
operator new(std::size_t size)
{
  if (counting)
    ++allocations;
  if (void *p = std::malloc(size == 0 ? 1 : size))
    return p;
  throw std::bad_alloc();
}

void
operator delete(void *p) noexcept
{
  std::free(p);
}

void
operator delete(void *p, std::size_t) noexcept
{
  std::free(p);
}


TEST(Physics, TimeStepsAllocateNothing)
{
  using namespace lacerta;
  // The counter itself works.
  counting          = true;
  const auto *probe = new std::vector<double>(10);
  counting          = false;
  EXPECT_EQ(allocations.load(), 2u);
  delete probe;

  const mesh::TetMesh mesh =
    test_support::distorted_box(4, 0.2, dealii::Point<3>(0.1, 0.1, 0.1));
  for (const auto &[model, model_entry] : physics::ForceModelRegistry::plugins())
    for (const unsigned int threads : {1u, 2u})
      for (const auto &[name, entry] : physics::IntegratorRegistry::plugins())
      {
        auto system          = test_support::make_system(mesh, 1000, 1e5, threads, model);
        system->mass_damping = 1;
        system->spring_damping    = 1e-4;
        system->body_acceleration = {0, 0, -9.81};
        const auto integrator     = physics::IntegratorRegistry::create(name);
        integrator->initialize(*system);
        integrator->step(*system, 0, 1e-5); // warm up (thread pools, lazy tables)
        allocations = 0;
        counting    = true;
        for (unsigned int step = 1; step <= 100; ++step)
          integrator->step(*system, step * 1e-5, 1e-5);
        counting = false;
        EXPECT_EQ(allocations.load(), 0u)
          << model << ", " << name << " on " << threads << " threads";
      }
}
