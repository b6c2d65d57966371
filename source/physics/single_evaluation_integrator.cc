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
    acceleration.assign(system.position.size(), 0.0);
  }


  unsigned int
  SingleEvaluationIntegrator::n_evaluations_per_step() const
  {
    return 1;
  }
} // namespace lacerta::physics
