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
#include <map>
#include <set>
#include <tuple>

namespace lacerta
{
  namespace
  {
    using cut::Blade;
    using cut::NodeKind;
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
      using Key               = std::tuple<NodeKind, int, std::array<unsigned int, 4>>;
      for (const auto &record : records)
      {
        std::map<Key, unsigned int>                         point_of;
        std::map<std::array<unsigned int, 3>, unsigned int> choice;
        for (const auto &p : record.new_points)
        {
          ASSERT_EQ(p.id, n_vertices++);
          EXPECT_EQ(p.position, m.vertex(p.id));
          if (p.kind != NodeKind::vertex)
            point_of[{p.kind, 0, p.ids}] = p.id;
        }
        for (const auto &c : record.vertex_choices)
          choice[{{c.cut, c.child, c.node}}] = c.used;
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
          cut::SplitResult r;
          cut::split_tetrahedron(c, r);
          for (unsigned int i = 0; i < r.n_children; ++i)
          {
            Tet child;
            for (unsigned int j = 0; j < 4; ++j)
            {
              const cut::NodeRef         &n = r.children[i].nodes[j];
              std::array<unsigned int, 4> ids{};
              if (n.kind == NodeKind::vertex)
              {
                child[j]      = t[n.index];
                const auto it = choice.find({{k, i, j}});
                if (c.vertex_side[n.index] == 0 && it != choice.end())
                  child[j] = it->second;
                continue;
              }
              if (n.kind == NodeKind::edge_point)
                ids = {{t[cut::tet_edge_vertices[n.index][0]],
                        t[cut::tet_edge_vertices[n.index][1]],
                        0,
                        0}};
              else if (n.kind == NodeKind::face_point)
              {
                for (unsigned int k = 0, l = 0; k < 4; ++k)
                  if (k != n.index)
                    ids[l++] = t[k];
              }
              else
                ids = t;
              const unsigned int count = n.kind == NodeKind::edge_point   ? 2
                                         : n.kind == NodeKind::face_point ? 3
                                                                          : 4;
              std::sort(ids.begin(), ids.begin() + count);
              // One particle per edge or face; where the crack opens, the copy of it
              // a child uses is recorded like a vertex's.
              const auto it = point_of.find({n.kind, 0, ids});
              ASSERT_NE(it, point_of.end()) << "a child's point has no recorded particle";
              child[j]          = it->second;
              const auto chosen = choice.find({{k, i, j}});
              if (chosen != choice.end())
                child[j] = chosen->second;
            }
            current.insert(sorted(child));
          }
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
