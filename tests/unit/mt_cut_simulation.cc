// A cut on the multiresolution model in a scene (doc/mt-cutting.md): the cutter cuts
// the level of detail during the stroke, the MT replays its records after it, and the
// particle system stays on the cut mesh with its state; later levels keep the cut.
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <gtest/gtest.h>

#include "mt_test_support.h"
#include <cmath>
#include <sstream>

namespace lacerta
{
  namespace
  {
    /// The plane of the cut: x = cut_x.
    constexpr double cut_x = 0.003;

    /**
     * prm/square_lod.prm with a scalpel that crosses it completely
     * along x = cut_x in y from 0.07 to -0.07 over the first second.
     */
    std::unique_ptr<scene::Scene>
    cut_slab_scene()
    {
      std::ostringstream text;
      text << "include " LACERTA_SCENE_DIR "/square_lod.prm\n"
           << "subsection Mesh\n  subsection Box\n    set Repetitions = 20, 20, 4\n"
           << "  end\nend\n"
           << "subsection Multiresolution\n  set Cache directory =\nend\n"
           << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
           << "    set Keyframes = 0, 0.003, 0.07, 0.03, 0.003, 0.07, -0.01; "
              "1, 0.003, -0.07, 0.03, 0.003, -0.07, -0.01\n  end\nend\n";
      return test_support::scene_from_text("lacerta_mt_cut_simulation.prm", text.str());
    }

    /**
     * The side of the cut of every vertex of @p m, cut into two pieces: +1 in the
     * piece whose tetrahedra lie mostly at x > cut_x, -1 in the other. Pieces, not the
     * plane: a vertex snapped onto the cut lies off the plane.
     */
    std::vector<int>
    sides(const mesh::TetMesh &m)
    {
      std::vector<unsigned int> piece(m.n_tets(), mesh::invalid_index);
      std::vector<double>       mean_x;
      for (unsigned int seed = 0; seed < m.n_tets(); ++seed)
        if (piece[seed] == mesh::invalid_index)
        {
          const unsigned int        p = static_cast<unsigned int>(mean_x.size());
          std::vector<unsigned int> queue{seed};
          piece[seed]      = p;
          double       sum = 0;
          unsigned int n   = 0;
          while (!queue.empty())
          {
            const unsigned int t = queue.back();
            queue.pop_back();
            for (const auto u : m.tet(t))
              sum += 0.25 * m.vertex(u)[0];
            ++n;
            for (unsigned int f = 0; f < 4; ++f)
            {
              const unsigned int next = m.neighbor(t, f);
              if (next != mesh::invalid_index && piece[next] == mesh::invalid_index)
              {
                piece[next] = p;
                queue.push_back(next);
              }
            }
          }
          mean_x.push_back(sum / n);
        }
      std::vector<int> side(m.n_vertices());
      for (unsigned int v = 0; v < m.n_vertices(); ++v)
        side[v] = mean_x[piece[m.tets_of_vertex(v).front()]] > cut_x ? 1 : -1;
      return side;
    }

    /// A deformed and moving state: affine in the rest position, plus a jump across
    /// the cut (the two sides moved apart), component @p d of particle at @p rest.
    double
    field_x(const mesh::Point3 &r, const int s, const unsigned int d)
    {
      const double affine[3] = {0.1 * r[1] - 0.05 * r[2], 0.2 * r[0], 0.1 * r[1]};
      return r[d] + affine[d] + (d == 0 ? 0.002 * s : 0.0);
    }

    double
    field_v(const mesh::Point3 &r, const int s, const unsigned int d)
    {
      return (d == 2 ? 0.5 * r[0] - 0.3 * r[1] : 0.4 * r[2]) + (d == 1 ? 0.01 * s : 0.0);
    }
  } // namespace


  TEST(MtCutSimulation, KeepsTheCutMeshAndItsStateThroughTheMtUpdate)
  {
    auto           scene   = cut_slab_scene();
    auto          &system  = *scene->system;
    const unsigned n_steps = 100;
    unsigned int   step    = 1;
    // Into the slab: the cutter cuts the level of detail, the MT waits.
    for (; step <= n_steps / 2; ++step)
      scene->cutter->move_blade(scene->tool->blade(double(step) / n_steps));
    ASSERT_FALSE(scene->cutter->active_tets().empty());
    ASSERT_TRUE(scene->cut_pending());
    EXPECT_FALSE(scene->update_multiresolution_after_cut(0.5).has_value());
    // Re-extraction is postponed while the stroke is in progress.
    EXPECT_FALSE(scene->update_level_of_detail(0.5, 1000000, std::cout));
    // Out of the slab: the stroke is over.
    for (; step <= n_steps; ++step)
      scene->cutter->move_blade(scene->tool->blade(double(step) / n_steps));
    ASSERT_TRUE(scene->cutter->active_tets().empty());
    const mesh::TetMesh &cut = scene->active_mesh();
    ASSERT_EQ(cut::count_components(cut), 2u);
    const std::vector<int> cut_sides = sides(cut);
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
      {
        system.position[3 * i + d] = field_x(cut.vertex(i), cut_sides[i], d);
        system.velocity[3 * i + d] = field_v(cut.vertex(i), cut_sides[i], d);
      }
    const unsigned int        n_cut_particles = system.n_particles();
    const std::vector<double> x_before = system.position, v_before = system.velocity;
    const mesh::Tet           first_tet = cut.tet(0);

    // The MT update replays the cutter's records: the system and its mesh stay.
    const auto result = scene->update_multiresolution_after_cut(1.0);
    ASSERT_TRUE(result.has_value());
    EXPECT_FALSE(scene->cut_pending());
    EXPECT_GT(result->update.split_fragments, 0u);
    EXPECT_GT(result->update.cut_tets, 0u);
    EXPECT_GT(result->update.pinned_applied, 0u);
    const mesh::TetMesh &now = scene->active_mesh();
    EXPECT_EQ(&now, &cut);
    EXPECT_EQ(now.tet(0), first_tet);
    EXPECT_EQ(system.n_particles(), n_cut_particles);
    EXPECT_EQ(system.position, x_before);
    EXPECT_EQ(system.velocity, v_before);
    EXPECT_EQ(result->pieces, 2u);
    EXPECT_EQ(scene->multiresolution->active_vertices().size(), now.n_vertices());
    EXPECT_EQ(cut::check_invariants(
                now, system, scene->expected_volume(), scene->integral_of_density),
              "");

    // The scalpel can cut again the mesh it now lives on.
    EXPECT_TRUE(scene->cutter->active_tets().empty());
    EXPECT_EQ(&now, &scene->active_mesh());

    // A later level of detail, the focus moved: the cut keeps its tetrahedra and its
    // particles their state; the particles that appear near it are interpolated in
    // uncut tetrahedra, which lie on one side. Tolerances: a quarter of the jump; a
    // few vertices outside the coarse tetrahedron they are interpolated in are clamped.
    ASSERT_TRUE(scene->update_level_of_detail(0.5, 2000000, std::cout));
    const mesh::TetMesh   &later       = scene->active_mesh();
    const std::vector<int> later_sides = sides(later);
    EXPECT_EQ(cut::count_components(later), 2u);
    unsigned int n_checked = 0, n_off = 0;
    for (unsigned int i = 0; i < later.n_vertices(); ++i)
    {
      // Near the cut only: far from it the coarse tetrahedra reach the fixed edges,
      // whose particles are at rest rather than on the field.
      const mesh::Point3 &r = later.vertex(i);
      if (std::abs(r[0] - cut_x) > 0.01)
        continue;
      ++n_checked;
      bool off = false;
      for (unsigned int d = 0; d < 3; ++d)
        off =
          off
          || std::abs(system.position[3 * i + d] - field_x(r, later_sides[i], d)) > 1e-3
          || std::abs(system.velocity[3 * i + d] - field_v(r, later_sides[i], d)) > 5e-3;
      if (off)
      {
        ++n_off;
        std::cout << "particle " << i << " at rest (" << r[0] << ", " << r[1] << ", "
                  << r[2] << ") has not the state of its side\n";
      }
    }
    EXPECT_EQ(n_off, 0u);
    std::cout << n_off << " of " << n_checked
              << " particles near the cut off their side's state\n";
    EXPECT_GT(n_checked, 100u);
  }
} // namespace lacerta
