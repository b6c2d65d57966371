/**
 * @file
 * The strain of a spring: what the laceration criterion and the pictures show.
 */
#pragma once

namespace lacerta::physics
{
  class ParticleSystem;

  /// Elongation over rest length of spring @p s of @p system at its current positions.
  double
  spring_strain(const ParticleSystem &system, unsigned int s);
} // namespace lacerta::physics
