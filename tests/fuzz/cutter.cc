// libFuzzer target: the scalpel. The input is decoded into blade motions on a slab of
// 3 x 3 x 1 cubes (45 tetrahedra), held stretched along y so that the deformed and the
// rest configurations differ; after every motion the invariants must hold: conformity,
// orientation, volume, mass = ∫σ, faces shared by at most two cells. A violation, a
// crash or a sanitizer report is a finding.
//
// Byte 0: the stretch along y, 0.8 to 1.25. Then 6 bytes per motion (at most 32): the
// blade's tail x, y (-0.2 to 1.2), z (0.4 to 0.9) and head x, y, z (-0.3 to 0.3), so
// that the blade may span the slab's thickness or end inside it. The coarse grid of
// byte values puts blades exactly through vertices, edges and faces.

#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>
#include <deal.II/base/parameter_handler.h>

#include "fuzz_support.h"
#include <iostream>
#include <memory>

namespace
{
  using namespace lacerta;

  const mesh::TetMesh &
  slab()
  {
    static const mesh::TetMesh pristine = []
    {
      dealii::ParameterHandler prm;
      mesh::MeshSource::declare_parameters(prm);
      prm.enter_subsection("Mesh");
      prm.set("Source", "box");
      prm.enter_subsection("Box");
      prm.set("Lower corner", "0, 0, 0");
      prm.set("Upper corner", "1, 1, 0.4");
      prm.set("Repetitions", "3, 3, 1");
      prm.leave_subsection();
      prm.leave_subsection();
      return mesh::MeshSource::create(prm)->create_mesh();
    }();
    return pristine;
  }


  double
  scaled(const std::uint8_t byte, const double low, const double high)
  {
    return low + (high - low) * byte / 255.0;
  }
} // namespace


extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
  if (size < 1)
    return 0;
  const dealii::Functions::ConstantFunction<3> density(1000.0), youngs(1e4);
  mesh::TetMesh                                mesh = slab();
  std::vector<double>                          rest(3 * mesh.n_vertices());
  for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    for (unsigned int d = 0; d < 3; ++d)
      rest[3 * v + d] = mesh.vertex(v)[d];
  physics::ParticleSystem system(rest);
  system.mass    = physics::compute_masses(mesh, density);
  system.springs = physics::compute_springs(mesh, youngs);
  system.set_force_model(physics::ForceModelRegistry::create("linear springs"), 1);
  const double stretch = scaled(data[0], 0.8, 1.25);
  for (unsigned int i = 0; i < system.n_particles(); ++i)
    system.position[3 * i + 1] *= stretch;
  double       integral = physics::integrate_over_mesh(mesh, density);
  const double volume   = mesh.total_volume();

  const auto blade_at = [&](const std::uint8_t *b)
  {
    cut::Blade blade;
    blade.tail = {scaled(b[0], -0.2, 1.2),
                  scaled(b[1], -0.2, 1.2),
                  scaled(b[2], 0.4, 0.9)};
    blade.head = {scaled(b[3], -0.2, 1.2),
                  scaled(b[4], -0.2, 1.2),
                  scaled(b[5], -0.3, 0.3)};
    return blade;
  };
  const std::size_t n_motions = std::min<std::size_t>((size - 1) / 6, 32);
  if (n_motions < 2)
    return 0;
  fuzz::expect_clean(
    [&]
    {
      cut::Cutter cutter(mesh,
                         system,
                         density,
                         youngs,
                         integral,
                         cut::Cutter::Parameters(),
                         blade_at(data + 1));
      for (std::size_t k = 1; k < n_motions; ++k)
      {
        cutter.move_blade(blade_at(data + 1 + 6 * k));
        const std::string problem = cut::check_invariants(mesh, system, volume, integral);
        if (!problem.empty())
        {
          std::cerr << "Invariant broken after motion " << k << ": " << problem << "\n";
          std::abort();
        }
      }
    });
  return 0;
}
