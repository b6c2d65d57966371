#include <lacerta/base/exceptions.h>
#include <lacerta/fem/nodal_field.h>

#include <algorithm>
#include <cmath>

namespace lacerta::fem
{
  namespace
  {
    /// Barycentric coordinates of @p p in the tetrahedron (a, b, c, d).
    std::array<double, 4>
    barycentric(const mesh::Point3 &p,
                const mesh::Point3 &a,
                const mesh::Point3 &b,
                const mesh::Point3 &c,
                const mesh::Point3 &d)
    {
      const double volume = mesh::signed_volume(a, b, c, d);
      const double l0     = mesh::signed_volume(p, b, c, d) / volume;
      const double l1     = mesh::signed_volume(a, p, c, d) / volume;
      const double l2     = mesh::signed_volume(a, b, p, d) / volume;
      return {l0, l1, l2, 1.0 - l0 - l1 - l2};
    }
  } // namespace


  std::vector<mesh::Point3>
  evaluate(const mesh::TetMesh             &mesh,
           const NodalField                &field,
           const std::vector<mesh::Point3> &points)
  {
    // Bucket grid over the bounding box, about one tetrahedron per bucket; every
    // tetrahedron is listed in the buckets its bounding box touches.
    mesh::Point3 lower = mesh.vertex(0), upper = mesh.vertex(0);
    for (const auto &p : mesh.get_vertices())
      for (unsigned int d = 0; d < 3; ++d)
      {
        lower[d] = std::min(lower[d], p[d]);
        upper[d] = std::max(upper[d], p[d]);
      }
    const double extent =
      std::max({upper[0] - lower[0], upper[1] - lower[1], upper[2] - lower[2]});
    const double tolerance = 1e-9 * extent;
    const double cell      = std::max(extent / std::cbrt(double(mesh.n_tets())), 1e-300);
    std::array<unsigned int, 3> n{};
    for (unsigned int d = 0; d < 3; ++d)
      n[d] =
        std::max(1u, static_cast<unsigned int>(std::ceil((upper[d] - lower[d]) / cell)));
    const auto bucket_of = [&](const double x, const unsigned int d)
    {
      const double i = std::floor((x - lower[d]) / cell);
      return static_cast<unsigned int>(std::clamp(i, 0.0, double(n[d] - 1)));
    };
    std::vector<std::vector<unsigned int>> buckets(n[0] * n[1] * n[2]);
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      std::array<unsigned int, 3> from{}, to{};
      for (unsigned int d = 0; d < 3; ++d)
      {
        double lo = mesh.vertex(mesh.tet(t)[0])[d], hi = lo;
        for (const unsigned int v : mesh.tet(t))
        {
          lo = std::min(lo, mesh.vertex(v)[d]);
          hi = std::max(hi, mesh.vertex(v)[d]);
        }
        from[d] = bucket_of(lo - tolerance, d);
        to[d]   = bucket_of(hi + tolerance, d);
      }
      for (unsigned int i = from[0]; i <= to[0]; ++i)
        for (unsigned int j = from[1]; j <= to[1]; ++j)
          for (unsigned int k = from[2]; k <= to[2]; ++k)
            buckets[(k * n[1] + j) * n[0] + i].push_back(t);
    }

    std::vector<mesh::Point3> values(points.size());
    for (std::size_t p = 0; p < points.size(); ++p)
    {
      const auto &x = points[p];
      const auto &candidates =
        buckets[(bucket_of(x[2], 2) * n[1] + bucket_of(x[1], 1)) * n[0]
                + bucket_of(x[0], 0)];
      // The tetrahedron whose smallest barycentric coordinate is largest contains the
      // point, or is the nearest one if round-off puts the point just outside.
      double                best = -1e300;
      unsigned int          tet  = mesh::invalid_index;
      std::array<double, 4> lambda{};
      for (const unsigned int t : candidates)
      {
        const auto &v = mesh.tet(t);
        const auto  l = barycentric(
          x, mesh.vertex(v[0]), mesh.vertex(v[1]), mesh.vertex(v[2]), mesh.vertex(v[3]));
        const double smallest = *std::min_element(l.begin(), l.end());
        if (smallest > best)
        {
          best   = smallest;
          tet    = t;
          lambda = l;
        }
      }
      if (tet == mesh::invalid_index || best < -1e-6)
        throw_error("The point (",
                    x[0],
                    ", ",
                    x[1],
                    ", ",
                    x[2],
                    ") lies outside the mesh '",
                    mesh.source(),
                    "' of the reference solution.");

      const auto  &v = mesh.tet(tet);
      mesh::Point3 u{};
      if (field.degree == 1)
      {
        for (unsigned int i = 0; i < 4; ++i)
          for (unsigned int d = 0; d < 3; ++d)
            u[d] += lambda[i] * field.vertex[3 * v[i] + d];
      }
      else
      {
        // Quadratic Lagrange basis in barycentric coordinates: λ_i (2 λ_i - 1) at the
        // vertices, 4 λ_i λ_j at the edge midpoints.
        for (unsigned int i = 0; i < 4; ++i)
          for (unsigned int d = 0; d < 3; ++d)
            u[d] += lambda[i] * (2 * lambda[i] - 1) * field.vertex[3 * v[i] + d];
        // The tetrahedron's own edge ids: after a cut the edge list is not sorted.
        for (unsigned int k = 0; k < 6; ++k)
        {
          const auto &[i, j]   = mesh::TetMesh::edge_vertices[k];
          const unsigned int e = mesh.tet_edges(tet)[k];
          for (unsigned int d = 0; d < 3; ++d)
            u[d] += 4 * lambda[i] * lambda[j] * field.edge[3 * e + d];
        }
      }
      values[p] = u;
    }
    return values;
  }


  void
  NodalError::add(const NodalError &other)
  {
    squared_error += other.squared_error;
    squared_reference += other.squared_reference;
    max_error     = std::max(max_error, other.max_error);
    max_reference = std::max(max_reference, other.max_reference);
  }


  double
  NodalError::relative_l2() const
  {
    return squared_reference > 0 ? std::sqrt(squared_error / squared_reference) : 0.0;
  }


  double
  NodalError::relative_max() const
  {
    return max_reference > 0 ? max_error / max_reference : 0.0;
  }


  NodalError
  nodal_error(const std::vector<double> &u, const std::vector<mesh::Point3> &reference)
  {
    NodalError error;
    for (std::size_t i = 0; i < reference.size(); ++i)
    {
      double e2 = 0, r2 = 0;
      for (unsigned int d = 0; d < 3; ++d)
      {
        e2 += (u[3 * i + d] - reference[i][d]) * (u[3 * i + d] - reference[i][d]);
        r2 += reference[i][d] * reference[i][d];
      }
      error.squared_error += e2;
      error.squared_reference += r2;
      error.max_error     = std::max(error.max_error, std::sqrt(e2));
      error.max_reference = std::max(error.max_reference, std::sqrt(r2));
    }
    return error;
  }
} // namespace lacerta::fem
