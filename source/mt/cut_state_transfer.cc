#include <lacerta/base/exceptions.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/mt/cut_state_transfer.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lacerta::mt
{
  namespace
  {
    /// A uniform grid over the boxes of a mesh's tetrahedra at rest (about 4 per cell).
    class TetGrid
    {
    public:
      explicit TetGrid(const mesh::TetMesh &m)
          : m(m)
      {
        cut::Box all;
        for (const auto &p : m.get_vertices())
          all.extend(p);
        double volume = 1;
        for (unsigned int d = 0; d < 3; ++d)
        {
          origin[d] = all.lower[d];
          volume *= std::max(all.upper[d] - all.lower[d], 1e-12);
        }
        cell = std::cbrt(4 * volume / std::max(1u, m.n_tets()));
        for (unsigned int d = 0; d < 3; ++d)
          dims[d] =
            std::max(1u,
                     static_cast<unsigned int>((all.upper[d] - all.lower[d]) / cell) + 1);
        cells.resize(std::size_t(dims[0]) * dims[1] * dims[2]);
        for (unsigned int t = 0; t < m.n_tets(); ++t)
        {
          cut::Box box;
          for (const auto v : m.tet(t))
            box.extend(m.vertex(v));
          const auto lo = index(box.lower), hi = index(box.upper);
          for (unsigned int k = lo[2]; k <= hi[2]; ++k)
            for (unsigned int j = lo[1]; j <= hi[1]; ++j)
              for (unsigned int i = lo[0]; i <= hi[0]; ++i)
                cells[(std::size_t(k) * dims[1] + j) * dims[0] + i].push_back(t);
        }
      }

      /// The tetrahedra whose boxes meet the cell of @p p.
      const std::vector<unsigned int> &
      near(const mesh::Point3 &p) const
      {
        const auto c = index(p);
        return cells[(std::size_t(c[2]) * dims[1] + c[1]) * dims[0] + c[0]];
      }

    private:
      std::array<unsigned int, 3>
      index(const mesh::Point3 &p) const
      {
        std::array<unsigned int, 3> c;
        for (unsigned int d = 0; d < 3; ++d)
        {
          const double x = (p[d] - origin[d]) / cell;
          c[d]           = static_cast<unsigned int>(
            std::clamp(x, 0.0, static_cast<double>(dims[d] - 1)));
        }
        return c;
      }

      const mesh::TetMesh                   &m;
      mesh::Point3                           origin{};
      double                                 cell = 1;
      std::array<unsigned int, 3>            dims{{1, 1, 1}};
      std::vector<std::vector<unsigned int>> cells;
    };


    /// The tetrahedra around every vertex of @p m: those of vertex w are
    /// incident[first[w]] .. incident[first[w + 1] - 1].
    struct Incidence
    {
      explicit Incidence(const mesh::TetMesh &m)
          : first(m.n_vertices() + 1, 0)
      {
        for (const auto &t : m.get_tets())
          for (const auto w : t)
            ++first[w + 1];
        for (unsigned int w = 0; w < m.n_vertices(); ++w)
          first[w + 1] += first[w];
        incident.resize(first.back());
        std::vector<unsigned int> fill(first.begin(), first.end() - 1);
        for (unsigned int t = 0; t < m.n_tets(); ++t)
          for (const auto w : m.tet(t))
            incident[fill[w]++] = t;
      }

      std::vector<unsigned int> first, incident;
    };


    /// Centroid of tet @p t of @p m.
    mesh::Point3
    centroid(const mesh::TetMesh &m, const unsigned int t)
    {
      mesh::Point3 c{};
      for (const auto u : m.tet(t))
        c = cut::add(c, cut::scale(0.25, m.vertex(u)));
      return c;
    }


    /// Mean of the centroids of the tetrahedra around vertex @p w: on w's side of a cut
    /// through w.
    mesh::Point3
    star_centre(const mesh::TetMesh &m, const Incidence &around, const unsigned int w)
    {
      mesh::Point3 c{};
      for (unsigned int k = around.first[w]; k < around.first[w + 1]; ++k)
        c = cut::add(c, centroid(m, around.incident[k]));
      return cut::scale(1.0 / std::max(1u, around.first[w + 1] - around.first[w]), c);
    }


    /// The piece (face-connected component) of every tetrahedron of @p m.
    std::vector<unsigned int>
    pieces(const mesh::TetMesh &m)
    {
      std::vector<unsigned int> piece(m.n_tets(), mesh::invalid_index);
      std::vector<unsigned int> queue;
      unsigned int              n = 0;
      for (unsigned int seed = 0; seed < m.n_tets(); ++seed)
        if (piece[seed] == mesh::invalid_index)
        {
          piece[seed] = n;
          queue.assign(1, seed);
          while (!queue.empty())
          {
            const unsigned int t = queue.back();
            queue.pop_back();
            for (unsigned int f = 0; f < 4; ++f)
            {
              const unsigned int next = m.neighbor(t, f);
              if (next != mesh::invalid_index && piece[next] == mesh::invalid_index)
              {
                piece[next] = n;
                queue.push_back(next);
              }
            }
          }
          ++n;
        }
      return piece;
    }


    /// Barycentric coordinates of @p p in tet @p t of @p m.
    std::array<double, 4>
    coordinates(const mesh::TetMesh &m, const unsigned int t, const mesh::Point3 &p)
    {
      const auto &c = m.tet(t);
      return cut::barycentric(
        m.vertex(c[0]), m.vertex(c[1]), m.vertex(c[2]), m.vertex(c[3]), p);
    }
  } // namespace


  CutTransferReport
  transfer_state_across_cut(const mesh::TetMesh       &from,
                            const std::vector<double> &from_x,
                            const std::vector<double> &from_v,
                            const mesh::TetMesh       &to,
                            std::vector<double>       &x,
                            std::vector<double>       &v)
  {
    const TetGrid grid(from);
    // A vertex of the other mesh at the same rest position: identical up to rounding
    // relative to the object's size.
    cut::Box all;
    for (const auto &p : from.get_vertices())
      all.extend(p);
    const double    diagonal = cut::norm(cut::sub(all.upper, all.lower));
    const double    same     = 1e-9 * diagonal;
    const Incidence around_from(from), around_to(to);
    // Every vertex is matched and interpolated within the piece of the old mesh that
    // holds most of the centroids of its tetrahedra, so that a vertex that the two
    // cut surfaces put on different sides (they differ by the snapping distance)
    // takes its state from its own side.
    const std::vector<unsigned int> piece_from = pieces(from);
    const auto locate = [&](const mesh::Point3 &p, const unsigned int piece)
    {
      unsigned int best        = mesh::invalid_index;
      double       best_inside = -1e300;
      for (const unsigned int t : grid.near(p))
        if (piece == mesh::invalid_index || piece_from[t] == piece)
        {
          const auto   lambda = coordinates(from, t, p);
          const double inner  = *std::min_element(lambda.begin(), lambda.end());
          if (inner > best_inside)
          {
            best_inside = inner;
            best        = t;
          }
        }
      return std::make_pair(best, best_inside);
    };
    CutTransferReport         report;
    std::vector<unsigned int> candidates, votes;
    x.assign(3 * to.n_vertices(), 0.0);
    v.assign(3 * to.n_vertices(), 0.0);
    for (unsigned int w = 0; w < to.n_vertices(); ++w)
    {
      const mesh::Point3 &rest = to.vertex(w);
      const mesh::Point3  star = star_centre(to, around_to, w);
      // w's side: the old piece holding most centroids of its tetrahedra (ties: the
      // lowest piece id).
      votes.clear();
      for (unsigned int k = around_to.first[w]; k < around_to.first[w + 1]; ++k)
      {
        const unsigned int found =
          locate(centroid(to, around_to.incident[k]), mesh::invalid_index).first;
        if (found != mesh::invalid_index)
          votes.push_back(piece_from[found]);
      }
      std::sort(votes.begin(), votes.end());
      unsigned int piece = mesh::invalid_index, most = 0;
      for (std::size_t i = 0; i < votes.size();)
      {
        std::size_t j = i;
        while (j < votes.size() && votes[j] == votes[i])
          ++j;
        if (j - i > most)
        {
          most  = static_cast<unsigned int>(j - i);
          piece = votes[i];
        }
        i = j;
      }
      // A particle of that piece at the same rest position: the vertex itself, or one
      // of its copies if it lies on a cut: the one whose tetrahedra contain the points
      // just inside w's own tetrahedra (a copy's tetrahedra lie on its side), the
      // nearest star if none does.
      candidates.clear();
      for (const unsigned int t : grid.near(rest))
        for (const auto u : from.tet(t))
          if ((piece == mesh::invalid_index || piece_from[t] == piece)
              && cut::norm(cut::sub(from.vertex(u), rest)) <= same
              && std::find(candidates.begin(), candidates.end(), u) == candidates.end())
            candidates.push_back(u);
      unsigned int twin = mesh::invalid_index;
      if (candidates.size() == 1)
        twin = candidates[0];
      else if (candidates.size() > 1)
      {
        double best_score = -1e300;
        for (const auto u : candidates)
        {
          double score = 0;
          for (unsigned int k = around_to.first[w]; k < around_to.first[w + 1]; ++k)
          {
            const mesh::Point3 inside =
              cut::add(rest,
                       cut::scale(1e-3,
                                  cut::sub(centroid(to, around_to.incident[k]), rest)));
            double contained = -1e300;
            for (unsigned int j = around_from.first[u]; j < around_from.first[u + 1]; ++j)
            {
              const auto lambda = coordinates(from, around_from.incident[j], inside);
              contained =
                std::max(contained, *std::min_element(lambda.begin(), lambda.end()));
            }
            score += contained >= -1e-6 ? 1 : 0;
          }
          // Ties (no star contains the points): the nearest star centre.
          score -= 1e-3 * cut::norm(cut::sub(star_centre(from, around_from, u), star))
                   / diagonal;
          if (score > best_score)
          {
            best_score = score;
            twin       = u;
          }
        }
      }
      if (twin != mesh::invalid_index)
      {
        ++report.copied;
        for (unsigned int d = 0; d < 3; ++d)
        {
          x[3 * w + d] = from_x[3 * twin + d];
          v[3 * w + d] = from_v[3 * twin + d];
        }
        continue;
      }
      // Otherwise (a cut point of the MT that the cutter did not make): the old
      // tetrahedron that best contains a point a quarter of the way from the vertex
      // to the centroid of one of its new tetrahedra, on the vertex's side of any cut
      // since the new tetrahedron does not cross it.
      unsigned int best        = mesh::invalid_index;
      double       best_inside = -1e300;
      for (unsigned int k = around_to.first[w];
           k < around_to.first[w + 1] && best_inside < 0;
           ++k)
      {
        const mesh::Point3 inside =
          cut::add(cut::scale(0.75, rest),
                   cut::scale(0.25, centroid(to, around_to.incident[k])));
        const auto [t, inner] = locate(inside, piece);
        if (inner > best_inside)
        {
          best_inside = inner;
          best        = t;
        }
      }
      if (best == mesh::invalid_index)
        throw_error("Cut on the multiresolution model: vertex ",
                    w,
                    " of the updated level of detail at (",
                    rest[0],
                    ", ",
                    rest[1],
                    ", ",
                    rest[2],
                    ") lies in no tetrahedron of the cut mesh.");
      const auto &corners = from.tet(best);
      // Interpolated, extrapolating at most a little: the two meshes' cut surfaces
      // and boundaries differ by the snapping distance.
      ++report.interpolated;
      auto   lambda = coordinates(from, best, rest);
      double sum    = 0;
      for (double &l : lambda)
        sum += (l = std::clamp(l, -0.5, 1.5));
      for (unsigned int k = 0; k < 4; ++k)
        for (unsigned int d = 0; d < 3; ++d)
        {
          x[3 * w + d] += lambda[k] / sum * from_x[3 * corners[k] + d];
          v[3 * w + d] += lambda[k] / sum * from_v[3 * corners[k] + d];
        }
    }
    return report;
  }
} // namespace lacerta::mt
