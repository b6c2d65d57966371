#include <lacerta/physics/volume_spring_parameters.h>

#include <algorithm>

namespace lacerta::physics
{
  VolumeSpringParameters
  volume_spring_parameters(const double nu, const double lattice_nu)
  {
    // The springs' own shear and bulk moduli over E (λ_s = μ_s = 2E/5 for the
    // orientation average of a tetrahedron's springs, lattice_nu = 1/4;
    // doc/physics.md), and those asked.
    const double lattice_shear = 1.0 / (2 * (1 + lattice_nu));
    const double lattice_bulk  = 1.0 / (3 * (1 - 2 * lattice_nu));
    const double shear         = 1.0 / (2 * (1 + nu));
    const double bulk          = 1.0 / (3 * (1 - 2 * nu));
    // The springs are scaled to the smaller of the two ratios, so that the term per
    // tetrahedron only adds stiffness: a volume term when the asked material is
    // relatively stiffer in bulk than the lattice, a shear term when it is stiffer
    // in shear.
    VolumeSpringParameters parameters;
    if (nu >= lattice_nu)
    {
      parameters.spring_scale = shear / lattice_shear;
      parameters.volume_modulus =
        std::max(0.0, bulk - parameters.spring_scale * lattice_bulk);
    }
    else
    {
      parameters.spring_scale = bulk / lattice_bulk;
      parameters.shear_modulus =
        std::max(0.0, shear - parameters.spring_scale * lattice_shear);
    }
    return parameters;
  }
} // namespace lacerta::physics
