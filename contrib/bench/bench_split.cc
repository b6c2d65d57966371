// lacerta-bench split: throughput of the tetrahedron split lookup table, on one core,
// over every configuration of the table in every vertex order.
//
//   lacerta-bench split            the figures
//   lacerta-bench split --table    the table of cases (Markdown, for doc/split-table.md)
//   lacerta-bench split --dump     one split per case, for
//   contrib/plot/plot_split_cases.py

#include <lacerta/cut/split_table.h>

#include "benchmark_registry.h"
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>
#include <vector>

namespace lacerta::bench
{
  namespace
  {
    using cut::Point;

    Point
    lerp(const Point &a, const Point &b, const double t)
    {
      return {a[0] + t * (b[0] - a[0]),
              a[1] + t * (b[1] - a[1]),
              a[2] + t * (b[2] - a[2])};
    }

    Point
    cross(const Point &a, const Point &b)
    {
      return {a[1] * b[2] - a[2] * b[1],
              a[2] * b[0] - a[0] * b[2],
              a[0] * b[1] - a[1] * b[0]};
    }

    Point
    sub(const Point &a, const Point &b)
    {
      return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    }

    double
    dot(const Point &a, const Point &b)
    {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    }

    /**
     * The cut of one tetrahedron by a plane through three given points, possibly
     * limited by a front (the crack is where dot(x - front_origin, front_normal) < 0).
     * No snapping is needed: the points are chosen away from the vertices.
     */
    cut::TetCut
    plane_cut(const std::array<Point, 4>         &x,
              const std::array<cut::VertexId, 4> &ids,
              const std::array<int, 4>           &side,
              const Point                        &origin,
              const Point                        &normal,
              const bool                          has_front,
              const Point                        &front_origin,
              const Point                        &front_normal)
    {
      cut::TetCut c;
      c.vertex_ids = ids;
      c.points     = x;
      std::array<double, 4> d;
      for (unsigned v = 0; v < 4; ++v)
      {
        c.vertex_side[v] = static_cast<std::int8_t>(side[v]);
        d[v]             = side[v] == 0 ? 0.0 : dot(normal, sub(x[v], origin));
      }
      const auto behind = [&](const Point &p)
      { return has_front ? dot(front_normal, sub(p, front_origin)) : -1.0; };
      // Section corners (position, reached) per local face, to place front points.
      std::array<std::vector<std::pair<Point, bool>>, 4> corners;
      for (unsigned v = 0; v < 4; ++v)
        if (side[v] == 0)
          for (unsigned f = 0; f < 4; ++f)
            if (f != v)
              corners[f].push_back({x[v], behind(x[v]) < 0});
      for (unsigned e = 0; e < 6; ++e)
      {
        const unsigned i = cut::tet_edge_vertices[e][0], j = cut::tet_edge_vertices[e][1];
        if (side[i] * side[j] >= 0)
          continue;
        const Point  p       = lerp(x[i], x[j], d[i] / (d[i] - d[j]));
        const bool   reached = behind(p) < 0;
        const double t = ids[i] < ids[j] ? d[i] / (d[i] - d[j]) : d[j] / (d[j] - d[i]);
        if (reached)
        {
          c.cut_edges |= static_cast<std::uint8_t>(1u << e);
          c.edge_parameter[e] = t;
        }
        for (unsigned f = 0; f < 4; ++f)
          if (f != i && f != j)
            corners[f].push_back({p, reached});
      }
      for (unsigned f = 0; f < 4 && has_front; ++f)
        if (corners[f].size() == 2 && corners[f][0].second != corners[f][1].second)
        {
          const auto  &r = corners[f][0].second ? corners[f][0] : corners[f][1];
          const auto  &u = corners[f][0].second ? corners[f][1] : corners[f][0];
          const double s = cut::clamp_front_parameter(
            behind(r.first) / (behind(r.first) - behind(u.first)));
          c.front_faces |= static_cast<std::uint8_t>(1u << f);
          c.front_points[f] = lerp(r.first, u.first, s);
        }
      return c;
    }

    /**
     * Inputs covering the whole table: for each of the 24 vertex orders, every pattern
     * of vertex sides (complete and touching cuts), every partial cut whose front crosses
     * two section sides, and every edge code as a refinement.
     */
    std::vector<cut::TetCut>
    all_configurations(const bool every_order = true)
    {
      std::mt19937                           rng(1);
      std::uniform_real_distribution<double> param(0.15, 0.85);
      const std::array<Point, 4>             x = {
                    {{0.1, 0.05, 0}, {1, 0.1, 0.05}, {0.2, 0.9, 0.1}, {0.3, 0.3, 1}}};
      std::vector<cut::TetCut>     inputs;
      std::array<cut::VertexId, 4> rank{0, 1, 2, 3};
      do
      {
        const std::array<cut::VertexId, 4> ids{1000 + 3 * rank[0],
                                               1000 + 3 * rank[1],
                                               1000 + 3 * rank[2],
                                               1000 + 3 * rank[3]};
        for (unsigned code = 0; code < 81; ++code)
        {
          std::array<int, 4> side;
          for (unsigned v = 0, c = code; v < 4; ++v, c /= 3)
            side[v] = static_cast<int>(c % 3) - 1;
          std::vector<Point>                   through;
          std::vector<std::array<unsigned, 2>> crossing;
          for (unsigned v = 0; v < 4; ++v)
            if (side[v] == 0)
              through.push_back(x[v]);
          for (const auto &e : cut::tet_edge_vertices)
            if (side[e[0]] * side[e[1]] < 0)
              crossing.push_back(e);
          if (crossing.empty() || through.size() > 2)
            continue; // touching planes are cheap lookups; measured via refinements
          for (unsigned attempt = 0; attempt < 200; ++attempt)
          {
            std::vector<Point> p = through;
            for (std::size_t k = 0; p.size() < 3; ++k)
              p.push_back(lerp(x[crossing[k][0]], x[crossing[k][1]], param(rng)));
            Point        n   = cross(sub(p[1], p[0]), sub(p[2], p[0]));
            const double len = std::sqrt(dot(n, n));
            n                = {n[0] / len, n[1] / len, n[2] / len};
            bool ok          = true;
            int  sign        = 0;
            for (unsigned v = 0; v < 4; ++v)
              if (side[v] != 0)
              {
                const int s = dot(n, sub(x[v], p[0])) * side[v] > 0 ? 1 : -1;
                ok          = ok && (sign == 0 || s == sign);
                sign        = s;
              }
            for (const auto &e : crossing)
            {
              const double di = dot(n, sub(x[e[0]], p[0])),
                           dj = dot(n, sub(x[e[1]], p[0]));
              ok              = ok && di / (di - dj) > 0.1 && di / (di - dj) < 0.9;
            }
            if (!ok)
              continue;
            std::array<int, 4> s = side;
            if (sign < 0)
              for (auto &v : s)
                v = -v;
            inputs.push_back(plane_cut(x, ids, s, p[0], n, false, {}, {}));
            // Partial cuts: a front between every two section corners (vertices on the
            // plane and crossing points), either way round.
            std::vector<Point> corners = through;
            for (const auto &e : crossing)
            {
              const double di = dot(n, sub(x[e[0]], p[0])),
                           dj = dot(n, sub(x[e[1]], p[0]));
              corners.push_back(lerp(x[e[0]], x[e[1]], di / (di - dj)));
            }
            for (std::size_t a = 0; a < corners.size(); ++a)
              for (std::size_t b = a + 1; b < corners.size(); ++b)
                for (const double dir : {1.0, -1.0})
                {
                  // The perpendicular bisector of the two corners, in the plane.
                  const Point m = sub(corners[b], corners[a]);
                  const Point o = lerp(corners[a], corners[b], 0.5);
                  auto        c = plane_cut(
                    x, ids, s, p[0], n, true, o, {dir * m[0], dir * m[1], dir * m[2]});
                  cut::SplitResult r;
                  if (c.front_faces != 0
                      && cut::split_tetrahedron(c, r) == cut::CutKind::partial)
                    inputs.push_back(c);
                }
            break;
          }
        }
        for (unsigned code = 1; code < 64; ++code)
        {
          cut::TetCut c;
          c.vertex_ids = ids;
          c.points     = x;
          c.vertex_side.fill(1);
          c.cut_edges = static_cast<std::uint8_t>(code);
          for (auto &t : c.edge_parameter)
            t = param(rng);
          inputs.push_back(c);
        }
      } while (every_order && std::next_permutation(rank.begin(), rank.end()));
      if (every_order)
        std::shuffle(inputs.begin(), inputs.end(), rng);
      return inputs;
    }

    struct Rate
    {
      double splits_per_second  = 0;
      double children_per_split = 0;
    };

    // Splits per second over the inputs, best of five timed batches of about 0.2 s.
    Rate
    measure(const std::vector<cut::TetCut> &inputs)
    {
      cut::SplitResult result;
      std::size_t      children = 0;
      const auto       run      = [&](const unsigned repetitions)
      {
        children = 0;
        for (unsigned r = 0; r < repetitions; ++r)
          for (const auto &c : inputs)
          {
            cut::split_tetrahedron(c, result);
            children += result.n_children;
          }
      };
      unsigned repetitions = 1;
      for (;;)
      {
        const auto start = std::chrono::steady_clock::now();
        run(repetitions);
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
              .count()
            > 0.05)
          break;
        repetitions *= 2;
      }
      repetitions *= 4;
      Rate best;
      for (unsigned batch = 0; batch < 5; ++batch)
      {
        const auto start = std::chrono::steady_clock::now();
        run(repetitions);
        const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double n          = double(inputs.size()) * repetitions;
        best.splits_per_second  = std::max(best.splits_per_second, n / seconds);
        best.children_per_split = double(children) / n;
      }
      return best;
    }

    void
    print_table()
    {
      // One row per case: subcases (canonical table entries, i.e. distinct vertex-order
      // classes), children, against the 17 of Bielser et al.'s fixed split.
      struct Row
      {
        unsigned entries = 0, min_children = 1000, max_children = 0;
        bool     interior = false;
      };
      std::map<std::string, Row> rows;
      for (const auto &e : cut::split_table_entries())
      {
        Row &r         = rows[e.name];
        r.entries      = r.entries + 1;
        r.min_children = std::min(r.min_children, e.n_children);
        r.max_children = std::max(r.max_children, e.n_children);
        r.interior     = r.interior || e.uses_interior_point;
      }
      std::printf(
        "| case | table entries | children | Bielser et al. |\n|---|---|---|---|\n");
      for (const auto &[name, r] : rows)
      {
        const std::string children =
          r.min_children == r.max_children
            ? std::to_string(r.min_children)
            : std::to_string(r.min_children) + "-" + std::to_string(r.max_children);
        std::printf("| %s | %u | %s%s | 17 |\n",
                    name.c_str(),
                    r.entries,
                    children.c_str(),
                    r.interior ? " (interior vertex)" : "");
      }
    }

    // One split per case (the first input of each, in the identity vertex order): the
    // parent, and every child's side, cut faces and node positions and kinds.
    void
    print_dump()
    {
      std::map<std::string, bool> done;
      cut::SplitResult            r;
      for (const auto &c : all_configurations(false))
      {
        cut::split_tetrahedron(c, r);
        const auto &entry = cut::split_table_entries()[r.entry];
        if (done[entry.name])
          continue;
        done[entry.name] = true;
        std::printf("case %s %u\n", entry.name.c_str(), r.n_children);
        for (const auto &p : c.points)
          std::printf("parent %.6f %.6f %.6f\n", p[0], p[1], p[2]);
        for (unsigned i = 0; i < r.n_children; ++i)
        {
          const cut::Child &child = r.children[i];
          std::printf("child %d %u", child.side, child.cut_faces);
          for (const auto &n : child.nodes)
          {
            const Point &p =
              n.kind == cut::NodeKind::vertex       ? c.points[n.index]
              : n.kind == cut::NodeKind::edge_point ? r.edge_points[n.index]
              : n.kind == cut::NodeKind::face_point ? r.face_points[n.index]
                                                    : r.interior_point;
            std::printf(" %d %.6f %.6f %.6f", int(n.kind), p[0], p[1], p[2]);
          }
          std::printf("\n");
        }
      }
    }

    int
    run_split_benchmark(const std::vector<std::string> &arguments)
    {
      if (std::find(arguments.begin(), arguments.end(), "--dump") != arguments.end())
      {
        print_dump();
        return 0;
      }
      if (std::find(arguments.begin(), arguments.end(), "--table") != arguments.end())
      {
        print_table();
        return 0;
      }
      const auto start = std::chrono::steady_clock::now();
      cut::split_table_entries(); // builds the table
      print_figure("split table build time",
                   1e3
                     * std::chrono::duration<double>(std::chrono::steady_clock::now()
                                                     - start)
                         .count(),
                   "ms");
      print_figure("split table entries", double(cut::split_table_entries().size()), "");

      const auto                                       inputs = all_configurations();
      std::map<cut::CutKind, std::vector<cut::TetCut>> by_kind;
      cut::SplitResult                                 result;
      for (const auto &c : inputs)
        by_kind[cut::split_tetrahedron(c, result)].push_back(c);
      print_figure("inputs (all configurations x 24 vertex orders)",
                   double(inputs.size()),
                   "");

      const Rate all = measure(inputs);
      print_figure("tetrahedra split per second (one core)",
                   all.splits_per_second,
                   "1/s");
      print_figure("children created per split", all.children_per_split, "");
      print_figure("children created per second (one core)",
                   all.splits_per_second * all.children_per_split,
                   "1/s");
      const std::map<cut::CutKind, std::string> names = {
        {cut::CutKind::complete, "complete"},
        {cut::CutKind::partial, "partial"},
        {cut::CutKind::refinement, "refinement"}};
      for (const auto &[kind, name] : names)
      {
        const Rate r = measure(by_kind[kind]);
        print_figure("  " + name + " cuts split per second", r.splits_per_second, "1/s");
        print_figure("  " + name + " cuts children per split", r.children_per_split, "");
      }
      return 0;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK(
    "split",
    "tetrahedron split lookup table: tetrahedra split per second and "
    "children per split over all cases and vertex orders (--table: the "
    "table of cases)",
    run_split_benchmark);
} // namespace lacerta::bench
