/**
 * @file
 * The parameters of force model `volume springs` from the Poisson ratio.
 */
#pragma once

namespace lacerta::physics
{
  /**
   * How force model `volume springs` scales the paper's springs and how stiff it makes
   * the volume term of a tetrahedron, both relative to Young's modulus E.
   */
  struct VolumeSpringParameters
  {
    /// α: the factor on the paper's spring stiffness k_e = Σ E V / |e|².
    double spring_scale = 1;
    /// κ̂: the volume term's modulus κ = κ̂ E (energy ½ κ V0 (V/V0 - 1)² per
    /// tetrahedron); negative below the springs' own Poisson ratio.
    double volume_modulus = 0;
  };

  /**
   * α and κ̂ for Poisson ratio @p nu in [0, 0.5), the paper's springs taken as an
   * isotropic material of Young's modulus E and Poisson ratio @p lattice_nu (1/4 for
   * an isotropic lattice): the springs give the shear modulus E / (2 (1 + ν)), the
   * volume term the rest of the bulk modulus E / (3 (1 - 2 ν)). doc/physics.md derives
   * them.
   */
  VolumeSpringParameters
  volume_spring_parameters(double nu, double lattice_nu = 0.25);
} // namespace lacerta::physics
