/**
 * @file
 * The spring model's static equilibrium, two ways that must agree (a direct solve of the
 * linearised springs, damped dynamic relaxation of the explicit model), and its lowest
 * vibration frequencies.
 */
#pragma once

#include <vector>

namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::fem
{
  /**
   * Displacements (3 per particle) of the small-strain equilibrium K u = f of the
   * system's force model linearised at rest: K = Σ k n nᵀ per spring with n its rest
   * direction (scaled as the model scales the springs) plus the model's element
   * stiffness per tetrahedron (ForceModel::for_each_element_stiffness());
   * f = m g + the external forces. The constrained particles keep their current
   * displacement (the caller puts them where the scene prescribes them first). Solved by
   * a sparse direct factorisation (UMFPACK).
   */
  std::vector<double>
  solve_linearised_springs(const physics::ParticleSystem &system);

  /**
   * The outcome of dynamic relaxation.
   */
  struct RelaxationResult
  {
    /// Displacements from rest, 3 per particle.
    std::vector<double> displacement;
    /// Iterations made and the final largest residual force over the largest load.
    unsigned int iterations        = 0;
    double       relative_residual = 0;
  };

  /**
   * Steady state of the explicit (nonlinear) spring model by dynamic relaxation:
   * leapfrog steps with fictitious masses m̃_i = √3 Σ k (scaled as the model scales the
   * springs) plus, per tetrahedron of the model, the largest absolute row sum of its
   * element stiffness at i (which make a unit step stable by Gershgorin) and kinetic
   * damping (velocities reset whenever the kinetic energy falls), until the largest
   * residual force is below @p tolerance times the largest load or, if larger, the
   * largest residual force at the start (the pull of the prescribed particles, which
   * drives a displacement-driven problem such as an indentation). The forces are the
   * system's own force model. Moves @p system's positions to the equilibrium; throws an
   * Error if @p max_iterations do not reach it.
   */
  RelaxationResult
  relax_springs(physics::ParticleSystem &system,
                double                   tolerance      = 1e-9,
                unsigned int             max_iterations = 2000000);

  /**
   * The @p n lowest vibration frequencies (Hz) of the system's force model linearised
   * at rest (as solve_linearised_springs()) with lumped masses, the constrained
   * particles held.
   */
  std::vector<double>
  spring_frequencies(const physics::ParticleSystem &system, unsigned int n);
} // namespace lacerta::fem
