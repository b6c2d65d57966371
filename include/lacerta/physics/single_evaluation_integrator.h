/**
 * @file
 * The common part of the integrators that evaluate the acceleration once per step.
 */
#pragma once

#include <lacerta/physics/integrator.h>

#include <vector>

namespace lacerta::physics
{
  /**
   * An integrator with one acceleration evaluation per step into one scratch vector
   * (symplectic Euler, velocity Verlet, explicit Euler), and no parameters of its own.
   */
  class SingleEvaluationIntegrator : public Integrator
  {
  public:
    /// These integrators have no parameters.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Allocates the acceleration vector.
    void
    initialize(const ParticleSystem &system) override;

    /// One evaluation per step.
    unsigned int
    n_evaluations_per_step() const override;

    /// The accelerations of the last evaluation.
    void
    serialize(Archive &archive) override;

  protected:
    /// Accelerations of the current evaluation, 3 per particle.
    std::vector<double> acceleration;
  };
} // namespace lacerta::physics
