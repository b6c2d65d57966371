/**
 * @file
 * An integrator's update of one thread range's particles, run inside the evaluation.
 */
#pragma once

#include <lacerta/base/function_ref.h>

namespace lacerta::physics
{
  /**
   * Work on the particles [begin, end) of one of the force model's thread ranges,
   * which a force evaluation calls on that range's thread as soon as their
   * accelerations are complete (ForceModel::compute_acceleration()). An integrator
   * passes its update of positions and velocities this way, so that one parallel
   * pass both evaluates and updates instead of two passes that each wait for all
   * threads. The work may write only its range's entries, and only of arrays the
   * evaluation does not read: the other threads may still be reading the state
   * evaluated.
   */
  using RangeUpdate = FunctionRef<void(unsigned int begin, unsigned int end)>;
} // namespace lacerta::physics
