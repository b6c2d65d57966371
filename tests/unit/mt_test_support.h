// Helpers shared by the Multi-Triangulation tests.
#pragma once

#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>
#include <lacerta/mt/multi_triangulation.h>
#include <lacerta/scene/scene.h>
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <unistd.h>

namespace lacerta::test_support
{
  /**
   * The scene of a parameter file whose text is @p parameters, written to a temporary
   * file @p name (so that its `include` lines resolve as a scene file's) and removed,
   * its force model on @p n_threads threads.
   */
  inline std::unique_ptr<scene::Scene>
  scene_from_text(const std::string &name,
                  const std::string &parameters,
                  const unsigned int n_threads = 1)
  {
    // One file per process: CTest runs the tests that share a name in parallel.
    const std::string file =
      (std::filesystem::temp_directory_path() / (std::to_string(::getpid()) + "_" + name))
        .string();
    std::ofstream(file) << parameters;
    dealii::ParameterHandler prm;
    Simulator::read_parameters(file, prm);
    std::filesystem::remove(file);
    return std::make_unique<scene::Scene>(prm, n_threads);
  }


  /**
   * The slab of square_lod.prm at 6 x 6 x 2 boxes without multiresolution, at
   * Poisson ratio 0.4 with force model @p model on @p n_threads threads, and a scalpel
   * spanning its thickness that goes from (x0, y0) at t = 0 to (x1, y1) at t = 1 s.
   */
  inline std::unique_ptr<scene::Scene>
  slab_cut_scene(const std::string &model,
                 const double       x0,
                 const double       y0,
                 const double       x1,
                 const double       y1,
                 const unsigned int n_threads = 1)
  {
    std::ostringstream text;
    text << "include " LACERTA_SCENE_DIR "/square_lod.prm\n"
         << "subsection Mesh\n  subsection Box\n    set Repetitions = 6, 6, 2\n"
         << "  end\nend\n"
         << "subsection Multiresolution\n  set Enabled = false\nend\n"
         << "subsection Material\n  set Poisson ratio = 0.4\nend\n"
         << "subsection Force model\n  set Model = " << model << "\nend\n"
         << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
         << "    set Keyframes = 0, " << x0 << ", " << y0 << ", 0.03, " << x0 << ", "
         << y0 << ", -0.01; 1, " << x1 << ", " << y1 << ", 0.03, " << x1 << ", " << y1
         << ", -0.01\n  end\nend\n";
    return scene_from_text("lacerta_slab_cut.prm", text.str(), n_threads);
  }


  /// A level of detail query from a name and parameters, as a scene would make it.
  inline std::unique_ptr<mt::LodQuery>
  make_query(const std::string &name, const std::map<std::string, std::string> &values)
  {
    dealii::ParameterHandler prm;
    mt::LodQueryRegistry::declare_all_in_subsections(prm);
    prm.enter_subsection(mt::LodQueryRegistry::subsection_name(name));
    for (const auto &[entry, value] : values)
      prm.set(entry, value);
    prm.leave_subsection();
    return mt::LodQueryRegistry::create_and_parse(name, prm);
  }

  /// The active set is exactly the live tets whose creator is applied and whose
  /// destroyer is not, and the applied set is closed under parents: every
  /// root-to-leaf path of the DAG crosses exactly one arc of the front.
  inline void
  expect_front_of_dag(const mt::MultiTriangulation &mt, const mt::Lod &lod)
  {
    for (std::uint32_t t = 0; t < mt.n_tets(); ++t)
    {
      const bool expected =
        mt.is_live(t) && lod.is_applied(mt.creator[t])
        && (mt.destroyer[t] == mesh::invalid_index || !lod.is_applied(mt.destroyer[t]));
      ASSERT_EQ(lod.is_active(t), expected) << "tet " << t;
    }
    for (std::uint32_t j = 1; j < mt.n_nodes(); ++j)
      if (lod.is_applied(j))
        mt.for_each_coarse(j,
                           [&](const std::uint32_t t)
                           { ASSERT_TRUE(lod.is_applied(mt.creator[t])) << j; });
  }

  /// Area of the boundary of @p m (rest configuration).
  inline double
  boundary_area(const mesh::TetMesh &m)
  {
    double area = 0;
    for (const auto &f : m.get_boundary_faces())
    {
      const auto      &l = mesh::TetMesh::face_vertices[f.face];
      const mesh::Tet &t = m.tet(f.tet);
      area += 0.5
              * cut::norm(cut::cross(cut::sub(m.vertex(t[l[1]]), m.vertex(t[l[0]])),
                                     cut::sub(m.vertex(t[l[2]]), m.vertex(t[l[0]]))));
    }
    return area;
  }
} // namespace lacerta::test_support
