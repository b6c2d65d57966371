// physics::TopologyUpdate, the local update cuts, tears and changes of level share:
// after a cut the springs and masses are those the assembly would make on the cut
// mesh, with the paper's springs and with fitted ones.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/material.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include <algorithm>
#include <sstream>

namespace lacerta
{
  TEST(TopologyUpdate, ACutLeavesTheSpringsAndMassesTheCutMeshWouldBeAssembledWith)
  {
    // A partial stroke through the slab of square_lod.prm on 10 x 10 x 2 boxes (full
    // resolution), once with each rule for the springs.
    for (const std::string rule : {"paper", "fitted"})
    {
      std::ostringstream text;
      text << "include " LACERTA_SCENE_DIR "/square_lod.prm\n"
           << "subsection Mesh\n  subsection Box\n    set Repetitions = 10, 10, 2\n"
           << "  end\nend\n"
           << "subsection Material\n  set Spring stiffness = " << rule
           << "\n  set Poisson ratio = 0.3\nend\n"
           << "subsection Multiresolution\n  set Enabled = false\nend\n"
           << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
           << "    set Keyframes = 0, -0.0273, 0.07, 0.03, -0.0261, 0.07, -0.01; "
              "1, -0.0273, -0.07, 0.03, -0.0261, -0.07, -0.01\n  end\nend\n";
      auto scene =
        test_support::scene_from_text("lacerta_topology_update.prm", text.str());
      const unsigned int tets_before = scene->active_mesh().n_tets();
      for (unsigned int k = 1; k <= 20; ++k)
        scene->cut(scene->tool->blade(0.03 * k), 0.03 * k);
      ASSERT_GT(scene->active_mesh().n_tets(), tets_before + 20) << rule;

      const mesh::TetMesh               &mesh    = scene->active_mesh();
      const physics::ParticleSystem     &system  = *scene->system;
      const dealii::Function<3, double> &modulus = scene->material.youngs_modulus();
      const physics::SpringSet           fresh =
        rule == "fitted" ? physics::compute_fitted_springs(mesh, modulus, 0.3)
                                   : physics::compute_springs(mesh, modulus);
      ASSERT_EQ(system.springs.size(), fresh.size()) << rule;
      const double stiffest =
        *std::max_element(fresh.stiffness.begin(), fresh.stiffness.end());
      for (std::size_t s = 0; s < fresh.size(); ++s)
      {
        EXPECT_EQ(std::minmax(system.springs.a[s], system.springs.b[s]),
                  std::minmax(fresh.a[s], fresh.b[s]))
          << rule << ", spring " << s;
        // The token stiffness of an edge every cell dropped is 1e-6 of the stiffest
        // spring of the mesh the update started from.
        EXPECT_NEAR(system.springs.stiffness[s],
                    fresh.stiffness[s],
                    1e-9 * fresh.stiffness[s] + 2e-6 * stiffest)
          << rule << ", spring " << s;
        EXPECT_NEAR(system.springs.rest_length[s],
                    fresh.rest_length[s],
                    1e-12 * fresh.rest_length[s])
          << rule << ", spring " << s;
      }
      const std::vector<double> masses =
        physics::compute_masses(mesh, scene->material.density());
      for (unsigned int i = 0; i < system.n_particles(); ++i)
        EXPECT_NEAR(system.mass[i], masses[i], 1e-12 * masses[i])
          << rule << ", particle " << i;
    }
  }
} // namespace lacerta
