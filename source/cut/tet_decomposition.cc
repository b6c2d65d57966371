#include <lacerta/cut/tet_decomposition.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace lacerta::cut
{
  double
  signed_volume6(const Point &a, const Point &b, const Point &c, const Point &d)
  {
    const double u0 = b[0] - a[0], u1 = b[1] - a[1], u2 = b[2] - a[2];
    const double v0 = c[0] - a[0], v1 = c[1] - a[1], v2 = c[2] - a[2];
    const double w0 = d[0] - a[0], w1 = d[1] - a[1], w2 = d[2] - a[2];
    return u0 * (v1 * w2 - v2 * w1) - u1 * (v0 * w2 - v2 * w0) + u2 * (v0 * w1 - v1 * w0);
  }


  namespace
  {
    // Face codes: an oriented triangle of compact indices (< 32), rotated so that its
    // smallest index comes first; the reversed triangle has another code.
    using FaceCode = std::uint16_t;

    FaceCode
    face_code(unsigned a, unsigned b, unsigned c)
    {
      if (b < a && b < c)
        return static_cast<FaceCode>(b | (c << 5) | (a << 10));
      if (c < a && c < b)
        return static_cast<FaceCode>(c | (a << 5) | (b << 10));
      return static_cast<FaceCode>(a | (b << 5) | (c << 10));
    }

    FaceCode
    reversed(const FaceCode f)
    {
      return face_code(f & 31u, (f >> 10) & 31u, (f >> 5) & 31u);
    }

    enum FaceState : std::uint8_t
    {
      free_face = 0, // neither side is occupied
      open_face = 1, // a tetrahedron is needed on the positive side of this orientation
      used_face = 2  // the positive side of this orientation is occupied or outside
    };

    // Depth-first search for a set of positive tetrahedra whose faces pair up exactly
    // with each other and with the boundary. Such a set tiles the piece without overlap:
    // the sum of the tetrahedra's indicator functions equals the winding number of the
    // boundary, which is one inside, and all terms are non-negative.
    class Search
    {
    public:
      Search(const PieceProblem &problem, const std::vector<PieceNode> &nodes)
          : nodes(nodes)
          , n(static_cast<unsigned>(nodes.size()))
          , state(1u << 15, free_face)
      {
        if (n > 31)
          throw std::logic_error("decompose_piece: too many nodes");
        std::array<int, 32> compact;
        compact.fill(-1);
        for (unsigned i = 0; i < n; ++i)
          compact[nodes[i]] = static_cast<int>(i);
        for (unsigned i = 0; i < n; ++i)
          mask[i] = problem.plane_mask[nodes[i]];

        // Orientation of every 4-subset, sorted, in all samples: +1 or -1 if it is the
        // same and clearly non-zero in every sample, 0 otherwise.
        orientation.assign(n * n * n * n, 0);
        double scale = 0;
        for (const auto &s : problem.samples)
          for (const auto v : nodes)
            for (unsigned k = 0; k < 3; ++k)
              scale = std::max(scale, std::abs(s[v][k]));
        const double tolerance = 1e-9 * std::max(scale * scale * scale, 1e-300);
        for (unsigned a = 0; a < n; ++a)
          for (unsigned b = a + 1; b < n; ++b)
            for (unsigned c = b + 1; c < n; ++c)
              for (unsigned d = c + 1; d < n; ++d)
              {
                int sign = 0;
                for (const auto &s : problem.samples)
                {
                  const double v =
                    signed_volume6(s[nodes[a]], s[nodes[b]], s[nodes[c]], s[nodes[d]]);
                  const int this_sign = v > tolerance ? 1 : (v < -tolerance ? -1 : 0);
                  if (this_sign == 0 || (sign != 0 && this_sign != sign))
                  {
                    sign = 0;
                    break;
                  }
                  sign = this_sign;
                }
                orientation[((a * n + b) * n + c) * n + d] =
                  static_cast<std::int8_t>(sign);
              }

        // A triangle listed in both orientations is an internal face that the answer
        // must contain (a crack triangle whose nodes the crack does not separate).
        std::vector<FaceCode> codes;
        for (const auto &t : problem.boundary)
        {
          if (compact[t[0]] < 0 || compact[t[1]] < 0 || compact[t[2]] < 0)
            throw std::logic_error("decompose_piece: boundary uses an unknown node");
          const FaceCode f = face_code(compact[t[0]], compact[t[1]], compact[t[2]]);
          if (state[f] != free_face)
            throw std::logic_error("decompose_piece: boundary triangle repeated");
          set(f, open_face);
          codes.push_back(f);
        }
        for (const FaceCode f : codes)
          if (state[reversed(f)] == free_face)
            set(reversed(f), used_face);
        initial_log_size = log.size();
      }

      // Runs iterative deepening; returns the tetrahedra in piece node identifiers.
      std::optional<std::vector<PieceTetrahedron>>
      run(const unsigned max_tetrahedra)
      {
        for (unsigned limit = lower_bound(); limit <= max_tetrahedra; ++limit)
          if (dfs(limit))
          {
            std::vector<PieceTetrahedron> result;
            for (const auto &t : chosen)
              result.push_back({nodes[t[0]], nodes[t[1]], nodes[t[2]], nodes[t[3]]});
            return result;
          }
        return std::nullopt;
      }

    private:
      const std::vector<PieceNode>                  &nodes;
      const unsigned                                 n;
      std::array<std::uint32_t, 32>                  mask{};
      std::vector<std::int8_t>                       orientation;
      std::vector<std::uint8_t>                      state;
      std::vector<FaceCode>                          open_list;
      std::vector<std::pair<FaceCode, std::uint8_t>> log; // (face, previous state)
      std::size_t                                    initial_log_size = 0;
      std::vector<std::array<unsigned, 4>>           chosen;

      void
      set(const FaceCode f, const std::uint8_t s)
      {
        log.emplace_back(f, state[f]);
        if (state[f] == open_face)
          open_list.erase(std::find(open_list.begin(), open_list.end(), f));
        state[f] = s;
        if (s == open_face)
          open_list.push_back(f);
      }

      void
      undo_to(const std::size_t size)
      {
        while (log.size() > size)
        {
          const auto [f, previous] = log.back();
          log.pop_back();
          if (state[f] == open_face)
            open_list.erase(std::find(open_list.begin(), open_list.end(), f));
          state[f] = previous;
          if (previous == open_face)
            open_list.push_back(f);
        }
      }

      int
      orient(const unsigned a, const unsigned b, const unsigned c, const unsigned d) const
      {
        std::array<unsigned, 4> v{a, b, c, d};
        int                     parity = 0;
        for (unsigned i = 0; i < 4; ++i)
          for (unsigned j = i + 1; j < 4; ++j)
            if (v[i] > v[j])
              parity ^= 1;
        std::sort(v.begin(), v.end());
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[3])
          return 0;
        const int s = orientation[((v[0] * n + v[1]) * n + v[2]) * n + v[3]];
        return parity ? -s : s;
      }

      bool
      in_common_plane(const unsigned a, const unsigned b, const unsigned c) const
      {
        return (mask[a] & mask[b] & mask[c]) != 0;
      }

      // The inward faces of the positive tetrahedron (a, b, c, d).
      static std::array<std::array<unsigned, 3>, 4>
      inward_faces(const unsigned a, const unsigned b, const unsigned c, const unsigned d)
      {
        return {{{b, d, c}, {a, c, d}, {a, d, b}, {a, b, c}}};
      }

      bool
      can_add(const unsigned a,
              const unsigned b,
              const unsigned c,
              const unsigned d) const
      {
        for (const auto &g : inward_faces(a, b, c, d))
        {
          const FaceCode f = face_code(g[0], g[1], g[2]);
          if (state[f] == open_face)
            continue;
          if (state[f] != free_face || state[reversed(f)] != free_face)
            return false;
          if (in_common_plane(g[0], g[1], g[2]))
            return false; // would put a face on the boundary that is not a boundary
                          // triangle
        }
        return true;
      }

      void
      add(const unsigned a, const unsigned b, const unsigned c, const unsigned d)
      {
        for (const auto &g : inward_faces(a, b, c, d))
        {
          const FaceCode f = face_code(g[0], g[1], g[2]);
          if (state[f] == open_face)
            set(f, used_face);
          else
          {
            set(f, used_face);
            set(reversed(f), open_face);
          }
        }
        chosen.push_back({a, b, c, d});
      }

      unsigned
      lower_bound() const
      {
        // A tetrahedron closes at most four open faces and at most one per plane.
        std::array<unsigned, 32> per_plane{};
        unsigned                 best = (static_cast<unsigned>(open_list.size()) + 3) / 4;
        for (const FaceCode f : open_list)
        {
          const std::uint32_t m =
            mask[f & 31u] & mask[(f >> 5) & 31u] & mask[(f >> 10) & 31u];
          for (unsigned p = 0; p < 32; ++p)
            if (m & (1u << p))
              best = std::max(best, ++per_plane[p]);
        }
        return best;
      }

      bool
      dfs(const unsigned remaining)
      {
        if (open_list.empty())
          return true;
        if (lower_bound() > remaining)
          return false;

        // Branch on the open face with the fewest completions.
        FaceCode              best_face = 0;
        std::vector<unsigned> best_apexes;
        bool                  found = false;
        std::vector<FaceCode> faces = open_list;
        std::sort(faces.begin(), faces.end());
        for (const FaceCode f : faces)
        {
          const unsigned        a = f & 31u, b = (f >> 5) & 31u, c = (f >> 10) & 31u;
          std::vector<unsigned> apexes;
          for (unsigned d = 0; d < n; ++d)
            if (d != a && d != b && d != c && orient(a, b, c, d) > 0
                && can_add(a, b, c, d))
              apexes.push_back(d);
          if (!found || apexes.size() < best_apexes.size())
          {
            best_face   = f;
            best_apexes = std::move(apexes);
            found       = true;
            if (best_apexes.size() <= 1)
              break;
          }
        }
        if (best_apexes.empty())
          return false;

        const unsigned a = best_face & 31u, b = (best_face >> 5) & 31u,
                       c = (best_face >> 10) & 31u;
        for (const unsigned d : best_apexes)
        {
          const std::size_t mark = log.size();
          add(a, b, c, d);
          if (dfs(remaining - 1))
            return true;
          chosen.pop_back();
          undo_to(mark);
        }
        return false;
      }
    };
  } // namespace


  std::optional<std::vector<PieceTetrahedron>>
  minimal_tetrahedralization(const PieceProblem &problem,
                             const unsigned int  max_tetrahedra)
  {
    Search search(problem, problem.nodes);
    return search.run(max_tetrahedra);
  }


  PieceDecomposition
  decompose_piece(const PieceProblem &problem, const unsigned int max_tetrahedra)
  {
    PieceDecomposition result;
    if (auto tets = minimal_tetrahedralization(problem, max_tetrahedra))
    {
      result.tetrahedra = std::move(*tets);
      return result;
    }

    // No tetrahedralisation with the piece's own nodes (the boundary diagonals twist):
    // add a node at the average of the nodes and search again with it.
    PieceProblem with_interior = problem;
    with_interior.nodes.push_back(steiner_node);
    with_interior.plane_mask[steiner_node] = 0;
    for (auto &s : with_interior.samples)
    {
      Point c{0, 0, 0};
      for (const auto v : problem.nodes)
        for (unsigned k = 0; k < 3; ++k)
          c[k] += s[v][k] / static_cast<double>(problem.nodes.size());
      s[steiner_node] = c;
    }
    const auto bound = static_cast<unsigned>(problem.boundary.size());
    if (auto tets = minimal_tetrahedralization(with_interior, bound))
    {
      result.tetrahedra         = std::move(*tets);
      result.uses_interior_node = true;
      return result;
    }
    throw std::logic_error(
      "decompose_piece: the piece is not star-shaped from its centroid ("
      + std::to_string(problem.boundary.size()) + " boundary triangles)");
  }
} // namespace lacerta::cut
