#include <lacerta/base/archive.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/single_evaluation_integrator.h>

namespace lacerta::physics
{
  void
  SingleEvaluationIntegrator::declare_parameters(dealii::ParameterHandler &)
  {
  }


  void
  SingleEvaluationIntegrator::initialize(const ParticleSystem &system)
  {
    // Every step computes the accelerations before reading them: growing the array is
    // enough, and costs the new particles only (nothing global per cut).
    acceleration.resize(system.position.size());
  }


  void
  SingleEvaluationIntegrator::prepare_next_state(const ParticleSystem &system)
  {
    resize_like(next_position, system.position);
    resize_like(next_velocity, system.velocity);
  }


  void
  SingleEvaluationIntegrator::take_next_state(ParticleSystem &system)
  {
    system.position.swap(next_position);
    system.velocity.swap(next_velocity);
  }


  unsigned int
  SingleEvaluationIntegrator::n_evaluations_per_step() const
  {
    return 1;
  }


  void
  SingleEvaluationIntegrator::serialize(Archive &archive)
  {
    archive &acceleration;
  }
} // namespace lacerta::physics
