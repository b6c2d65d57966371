#include <lacerta/physics/integrator.h>

#include <algorithm>
#include <cmath>

namespace lacerta::physics
{
  void
  Integrator::parse_parameters(dealii::ParameterHandler &)
  {
  }


  void
  Integrator::declare_parameters(dealii::ParameterHandler &prm)
  {
    IntegratorRegistry::declare_selector_subsection(
      prm,
      "Integrator",
      "Scheme",
      "rk4",
      "The explicit time integration scheme. Its stable "
      "time step is printed before the run (see "
      "doc/stability.md).");
  }


  std::unique_ptr<Integrator>
  Integrator::create(dealii::ParameterHandler &prm)
  {
    return IntegratorRegistry::create_selected(prm, "Integrator", "Scheme");
  }


  double
  modal_damping(const double omega,
                const double mass_damping,
                const double spring_damping)
  {
    return mass_damping + spring_damping * omega * omega;
  }


  double
  symplectic_linear_stability_limit(const double omega, const double c)
  {
    // Jury conditions on the amplification matrix [[1 - ω²dt², dt(1 - c dt)],
    // [-ω²dt, 1 - c dt]]: trace > -(1 + det) gives ω²dt² + 2c dt < 4.
    return (std::sqrt(c * c + 4.0 * omega * omega) - c) / (omega * omega);
  }


  double
  symplectic_critical_time_step(const double omega, const double c)
  {
    // The undamped scheme turns a mode by the numerical angle θ = 2 asin(ω dt / 2) per
    // step; at ω dt = √2, θ = π/2, four steps make a full turn, and a nonlinear force
    // couples the mode to its own fourth harmonic at zero frequency (Schlick,
    // Molecular Modeling and Simulation, 14.6): the linear limit 2 does not hold for
    // a nonlinear force.
    return std::min(symplectic_linear_stability_limit(omega, c), std::sqrt(2.0) / omega);
  }


  void
  resize_like(std::vector<double> &buffer, const std::vector<double> &state)
  {
    if (buffer.capacity() < state.capacity())
    {
      buffer.clear();
      buffer.reserve(state.capacity());
    }
    buffer.resize(state.size());
  }
} // namespace lacerta::physics
