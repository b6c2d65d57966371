/**
 * @file
 * The parameters of force model `volume springs` from the Poisson ratio.
 */
#pragma once

namespace lacerta::physics
{
  /**
   * How force model `volume springs` scales the paper's springs and how stiff it makes
   * the two terms per tetrahedron, all relative to Young's modulus E. At most one of
   * the two terms is non-zero, and neither is negative.
   */
  struct VolumeSpringParameters
  {
    /// α: the factor on the paper's spring stiffness k_e = Σ E V / |e|².
    double spring_scale = 1;
    /// κ̂: the volume term's modulus κ = κ̂ E (energy ½ κ V0 (V/V0 - 1)² per
    /// tetrahedron); non-zero for ratios above the springs' own.
    double volume_modulus = 0;
    /// μ̂: the shear term's modulus μ_d = μ̂ E (energy μ_d V0 |dev E|² per
    /// tetrahedron, E the Green strain); non-zero for ratios below the springs' own.
    double shear_modulus = 0;
  };

  /**
   * α, κ̂ and μ̂ for Poisson ratio @p nu in [0, 0.5), the paper's springs taken as an
   * isotropic material of Young's modulus E and Poisson ratio @p lattice_nu (1/4 for
   * an isotropic lattice). Above the lattice's ratio the springs give the shear
   * modulus E / (2 (1 + ν)) and the volume term the rest of the bulk modulus
   * E / (3 (1 - 2 ν)); below it the springs give the bulk modulus and the shear term
   * the rest of the shear modulus. doc/physics.md derives them.
   */
  VolumeSpringParameters
  volume_spring_parameters(double nu, double lattice_nu = 0.25);
} // namespace lacerta::physics
