// The cutter's records (cut/cut_record.h): replaying them with the split table on the
// uncut mesh, by global ids and keys alone, rebuilds the cut mesh exactly.
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/base/function.h>

#include <gtest/gtest.h>

#include "cut_split_support.h"
#include "physics_test_support.h"
#include <set>

namespace lacerta
{
  namespace
  {
    using cut::Blade;
    using mesh::Tet;

    Tet
    sorted(Tet t)
    {
      std::sort(t.begin(), t.end());
      return t;
    }

    Blade
    vertical(const double x, const double y)
    {
      return {{{x, y, 1.5}}, {{x, y, -0.5}}};
    }

    /// Cuts a jittered box along @p path and checks that its records rebuild it.
    void
    expect_replay_rebuilds(const std::vector<Blade> &path, const unsigned int steps)
    {
      const mesh::TetMesh original =
        test_support::distorted_box(4, 0.25, dealii::Point<3>(1, 1, 1));
      mesh::TetMesh m      = original;
      auto          system = test_support::make_system(m, 1000, 1e4);
      dealii::Functions::ConstantFunction<3> sigma(1000), youngs(1e4);
      double      integral = physics::integrate_over_mesh(m, sigma);
      cut::Cutter cutter(
        m, *system, sigma, youngs, integral, cut::Cutter::Parameters(), path[0]);
      std::vector<cut::CutRecord> records;
      cutter.set_recorder(&records);
      cut::test_support::stroke(cutter,
                                path,
                                steps,
                                [](std::size_t,
                                   unsigned int,
                                   const cut::CutStepStatistics &) { return true; });
      ASSERT_FALSE(records.empty());

      std::set<Tet> current;
      for (const Tet &t : original.get_tets())
        current.insert(sorted(t));
      unsigned int n_vertices = original.n_vertices();
      for (const auto &record : records)
      {
        for (const auto &p : record.new_points)
        {
          ASSERT_EQ(p.id, n_vertices++);
          EXPECT_EQ(p.position, m.vertex(p.id));
        }
        const auto children = cut::recorded_children(record);
        ASSERT_EQ(children.size(), record.cuts.size());
        for (unsigned int k = 0; k < record.cuts.size(); ++k)
        {
          const cut::TetCut &c = record.cuts[k];
          Tet                t;
          for (unsigned int i = 0; i < 4; ++i)
          {
            t[i] = static_cast<unsigned int>(c.vertex_ids[i]);
            EXPECT_EQ(c.points[i], m.vertex(t[i]));
          }
          ASSERT_EQ(current.erase(sorted(t)), 1u) << "a recorded tet is not in the mesh";
          for (const Tet &child : children[k])
            current.insert(sorted(child));
        }
      }
      EXPECT_EQ(n_vertices, m.n_vertices());
      std::set<Tet> cut_mesh;
      for (const Tet &t : m.get_tets())
        cut_mesh.insert(sorted(t));
      EXPECT_EQ(current, cut_mesh);
    }
  } // namespace


  TEST(CutRecord, ReplayRebuildsACompleteCut)
  {
    expect_replay_rebuilds({vertical(-0.2, 0.43), vertical(1.2, 0.47)}, 12);
  }


  TEST(CutRecord, ReplayRebuildsAPartialAndABentCut)
  {
    expect_replay_rebuilds({vertical(-0.2, 0.52), vertical(0.55, 0.5)}, 8);
    expect_replay_rebuilds({vertical(-0.2, 0.3), vertical(0.5, 0.5), vertical(0.6, 1.2)},
                           7);
  }
} // namespace lacerta
