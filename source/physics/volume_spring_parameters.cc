#include <lacerta/physics/volume_spring_parameters.h>

namespace lacerta::physics
{
  VolumeSpringParameters
  volume_spring_parameters(const double nu, const double lattice_nu)
  {
    // The springs' own shear and bulk moduli over E (λ_s = μ_s = 2E/5 for the
    // orientation average of a tetrahedron's springs, lattice_nu = 1/4;
    // doc/physics.md).
    const double           lattice_shear = 1.0 / (2 * (1 + lattice_nu));
    const double           lattice_bulk  = 1.0 / (3 * (1 - 2 * lattice_nu));
    VolumeSpringParameters parameters;
    parameters.spring_scale = 1.0 / (2 * (1 + nu)) / lattice_shear;
    parameters.volume_modulus =
      1.0 / (3 * (1 - 2 * nu)) - parameters.spring_scale * lattice_bulk;
    return parameters;
  }
} // namespace lacerta::physics
