#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/spring_strain.h>

#include <cmath>

namespace lacerta::physics
{
  double
  spring_strain(const ParticleSystem &system, const unsigned int s)
  {
    const double *a = &system.position[3 * system.springs.a[s]];
    const double *b = &system.position[3 * system.springs.b[s]];
    return std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2])
             / system.springs.rest_length[s]
           - 1.0;
  }
} // namespace lacerta::physics
