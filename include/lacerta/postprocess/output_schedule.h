/**
 * @file
 * When a postprocessor that writes every so much simulated time writes next.
 */
#pragma once

#include <algorithm>
#include <cmath>

namespace lacerta::postprocess
{
  /**
   * Writes at time 0 and then once per interval of simulated time (the first step at or
   * after each multiple of it); an interval of 0 writes every step.
   */
  class OutputSchedule
  {
  public:
    /// Sets the interval [s].
    void
    set_interval(const double seconds)
    {
      interval = seconds;
    }

    /// Whether a state at @p time is due.
    bool
    due(const double time) const
    {
      return time >= next - 1e-12 * std::max(1.0, std::abs(time));
    }

    /// The state at @p time was written.
    void
    written(const double time)
    {
      next = interval > 0 ? (std::floor(time / interval + 1e-9) + 1) * interval : time;
    }

  private:
    double interval = 0, next = 0;
  };
} // namespace lacerta::postprocess
