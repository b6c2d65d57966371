#include <lacerta/base/exceptions.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/spring_fit.h>

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <typeinfo>

namespace lacerta::physics
{
  namespace
  {
    /**
     * The quadrature rule on the reference tetrahedron as barycentric coordinates and
     * weights (summing to 1), so that it maps to any tetrahedron without a Mapping.
     */
    struct BarycentricRule
    {
      std::vector<std::array<double, 4>> coordinates;
      std::vector<double>                weights;

      BarycentricRule()
      {
        // Degree 3 is exact for σ·c_i with σ quadratic.
        const dealii::QWitherdenVincentSimplex<3> rule(2);
        for (unsigned int q = 0; q < rule.size(); ++q)
        {
          const dealii::Point<3> &p = rule.point(q);
          coordinates.push_back({1.0 - p[0] - p[1] - p[2], p[0], p[1], p[2]});
          weights.push_back(rule.weight(q) * 6.0); // reference volume is 1/6
        }
      }
    };


    /// Calls @p visit(q, point, weight·|τ|) for every quadrature point of tet @p t.
    template <typename Visitor>
    void
    for_each_quadrature_point(const mesh::TetMesh   &mesh,
                              const unsigned int     t,
                              const BarycentricRule &rule,
                              const Visitor         &visit)
    {
      const mesh::Tet &tet    = mesh.tet(t);
      const double     volume = mesh.volume(t);
      for (unsigned int q = 0; q < rule.weights.size(); ++q)
      {
        dealii::Point<3> x;
        for (unsigned int i = 0; i < 4; ++i)
          for (unsigned int d = 0; d < 3; ++d)
            x[d] += rule.coordinates[q][i] * mesh.vertex(tet[i])[d];
        visit(q, x, rule.weights[q] * volume);
      }
    }
  } // namespace


  std::array<double, 4>
  tet_mass_contributions(const mesh::TetMesh               &mesh,
                         const unsigned int                 t,
                         const dealii::Function<3, double> &density)
  {
    static const BarycentricRule rule;
    std::array<double, 4>        m = {{0, 0, 0, 0}};
    for_each_quadrature_point(mesh,
                              t,
                              rule,
                              [&](unsigned int q, const dealii::Point<3> &x, double jxw)
                              {
                                const double sigma = density.value(x);
                                for (unsigned int i = 0; i < 4; ++i)
                                  m[i] += sigma * rule.coordinates[q][i] * jxw;
                              });
    return m;
  }


  std::array<double, 4>
  tet_mass_contributions(const mesh::TetMesh &mesh,
                         const unsigned int   t,
                         const double         sigma)
  {
    return constant_density_mass_contributions(mesh.volume(t), sigma);
  }


  std::array<double, 4>
  constant_density_mass_contributions(const double volume, const double sigma)
  {
    return ConstantDensityMass(sigma)(volume);
  }


  ConstantDensityMass::ConstantDensityMass(const double sigma)
  {
    static const BarycentricRule rule;
    if (rule.weights.size() != n_points)
      throw_error("ConstantDensityMass: the quadrature rule has ",
                  rule.weights.size(),
                  " points instead of ",
                  n_points,
                  ".");
    for (unsigned int q = 0; q < n_points; ++q)
    {
      weights[q] = rule.weights[q];
      for (unsigned int i = 0; i < 4; ++i)
        scaled_coordinates[q][i] = sigma * rule.coordinates[q][i];
    }
  }


  std::array<double, 4>
  ConstantDensityMass::operator()(const double volume) const
  {
    // The same sums in the same order as the general tet_mass_contributions() with
    // σ(x) = sigma, so that the contributions are bit-identical: its term
    // sigma * c_i * jxw is (sigma * c_i) * jxw, and only the first product is the
    // same for every cell. The quadrature points and the calls of the density are
    // saved too.
    std::array<double, 4> m = {{0, 0, 0, 0}};
    for (unsigned int q = 0; q < n_points; ++q)
    {
      const double jxw = weights[q] * volume;
      for (unsigned int i = 0; i < 4; ++i)
        m[i] += scaled_coordinates[q][i] * jxw;
    }
    return m;
  }


  std::optional<double>
  constant_value(const dealii::Function<3, double> &f)
  {
    // The exact types only: a class derived from them may override value().
    if (f.n_components != 1
        || (typeid(f) != typeid(dealii::Functions::ConstantFunction<3, double>)
            && typeid(f) != typeid(dealii::Functions::ZeroFunction<3, double>)))
      return std::nullopt;
    return f.value(dealii::Point<3>());
  }


  std::vector<double>
  compute_masses(const mesh::TetMesh &mesh, const dealii::Function<3, double> &density)
  {
    std::vector<double> masses(mesh.n_vertices(), 0.0);
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      const std::array<double, 4> m = tet_mass_contributions(mesh, t, density);
      for (unsigned int i = 0; i < 4; ++i)
        masses[mesh.tet(t)[i]] += m[i];
    }
    return masses;
  }


  double
  integrate_over_mesh(const mesh::TetMesh &mesh, const dealii::Function<3, double> &field)
  {
    const BarycentricRule rule;
    double                sum = 0;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      for_each_quadrature_point(mesh,
                                t,
                                rule,
                                [&](unsigned int, const dealii::Point<3> &x, double jxw)
                                { sum += field.value(x) * jxw; });
    return sum;
  }


  namespace
  {
    /// Centroid of tetrahedron @p t, where E is evaluated for the whole tetrahedron.
    dealii::Point<3>
    centroid_of(const mesh::TetMesh &mesh, const unsigned int t)
    {
      dealii::Point<3> centroid;
      for (const unsigned int v : mesh.tet(t))
        for (unsigned int d = 0; d < 3; ++d)
          centroid[d] += 0.25 * mesh.vertex(v)[d];
      return centroid;
    }


    /**
     * One spring per unique edge with rest length |e| and the stiffness summed over the
     * tetrahedra of the edge; @p contribution gives tetrahedron t's share to its six
     * edges (local edge order) from the rest lengths of all edges.
     */
    SpringSet
    springs_from_contributions(
      const mesh::TetMesh &mesh,
      const std::function<
        std::array<double, 6>(unsigned int, const std::vector<double> &)> &contribution)
    {
      const auto         &edges = mesh.get_edges();
      std::vector<double> length(edges.size());
      for (unsigned int e = 0; e < edges.size(); ++e)
      {
        const mesh::Point3 &a = mesh.vertex(edges[e][0]);
        const mesh::Point3 &b = mesh.vertex(edges[e][1]);
        length[e]             = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
      }

      std::vector<double> stiffness(edges.size(), 0.0);
      for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      {
        const std::array<double, 6> k = contribution(t, length);
        for (unsigned int i = 0; i < 6; ++i)
          stiffness[mesh.tet_edges(t)[i]] += k[i];
      }

      SpringSet springs;
      for (unsigned int e = 0; e < edges.size(); ++e)
        springs.push_back(edges[e][0], edges[e][1], stiffness[e], length[e]);
      return springs;
    }


  } // namespace


  std::array<double, 2>
  lame_parameters(const double youngs, const double nu)
  {
    return {{youngs * nu / ((1 + nu) * (1 - 2 * nu)), youngs / (2 * (1 + nu))}};
  }


  dealii::FullMatrix<double>
  p1_element_stiffness(const std::array<mesh::Point3, 4> &x,
                       const double                       lambda,
                       const double                       mu)
  {
    dealii::Tensor<2, 3> jacobian;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int d = 0; d < 3; ++d)
        jacobian[d][i] = x[i + 1][d] - x[0][d];
    const double               volume  = std::abs(dealii::determinant(jacobian)) / 6;
    const dealii::Tensor<2, 3> inverse = dealii::invert(jacobian);
    // Gradients of the barycentric coordinates: rows of J⁻¹ for vertices 1..3.
    std::array<dealii::Tensor<1, 3>, 4> g;
    for (unsigned int i = 0; i < 3; ++i)
      for (unsigned int d = 0; d < 3; ++d)
        g[i + 1][d] = inverse[i][d];
    g[0] = -(g[1] + g[2] + g[3]);
    dealii::FullMatrix<double> k(12, 12);
    for (unsigned int i = 0; i < 4; ++i)
      for (unsigned int j = 0; j < 4; ++j)
        for (unsigned int c = 0; c < 3; ++c)
          for (unsigned int d = 0; d < 3; ++d)
            k(3 * i + c, 3 * j + d) =
              volume
              * (lambda * g[i][c] * g[j][d] + mu * g[i][d] * g[j][c]
                 + (c == d ? mu * (g[i] * g[j]) : 0.0));
    return k;
  }


  double
  tet_stiffness_factor(const mesh::TetMesh               &mesh,
                       const unsigned int                 t,
                       const dealii::Function<3, double> &youngs_modulus)
  {
    return youngs_modulus.value(centroid_of(mesh, t)) * mesh.volume(t);
  }


  std::array<double, 2>
  edge_spring(const mesh::TetMesh               &mesh,
              const unsigned int                 e,
              const dealii::Function<3, double> &youngs_modulus)
  {
    const auto         &edge   = mesh.get_edges()[e];
    const mesh::Point3 &a      = mesh.vertex(edge[0]);
    const mesh::Point3 &b      = mesh.vertex(edge[1]);
    const double        length = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
    double              sum    = 0;
    for (const unsigned int t : mesh.tets_of_vertex(edge[0]))
    {
      const mesh::Tet &tet = mesh.tet(t);
      if (std::find(tet.begin(), tet.end(), edge[1]) != tet.end())
        sum += tet_stiffness_factor(mesh, t, youngs_modulus);
    }
    return {{sum / (length * length), length}};
  }


  SpringSet
  compute_springs(const mesh::TetMesh               &mesh,
                  const dealii::Function<3, double> &youngs_modulus)
  {
    return springs_from_contributions(
      mesh,
      [&](const unsigned int t, const std::vector<double> &length)
      {
        std::array<double, 6> squared_length;
        for (unsigned int i = 0; i < 6; ++i)
          squared_length[i] = length[mesh.tet_edges(t)[i]] * length[mesh.tet_edges(t)[i]];
        return paper_edge_stiffnesses(tet_stiffness_factor(mesh, t, youngs_modulus),
                                      squared_length);
      });
  }


  std::array<double, 6>
  paper_edge_stiffnesses(const double                 e_times_v,
                         const std::array<double, 6> &squared_length)
  {
    std::array<double, 6> k{};
    for (unsigned int i = 0; i < 6; ++i)
      k[i] = e_times_v / squared_length[i];
    return k;
  }


  std::array<double, 6>
  paper_edge_stiffnesses(const std::array<mesh::Point3, 4> &x,
                         const double                       youngs_modulus)
  {
    std::array<double, 6> squared_length;
    for (unsigned int i = 0; i < 6; ++i)
    {
      const auto [a, b]    = mesh::TetMesh::edge_vertices[i];
      const mesh::Point3 d = mesh::sub(x[b], x[a]);
      squared_length[i]    = mesh::dot(d, d);
    }
    return paper_edge_stiffnesses(youngs_modulus
                                    * mesh::signed_volume(x[0], x[1], x[2], x[3]),
                                  squared_length);
  }


  std::array<double, 6>
  fitted_edge_stiffnesses(const std::array<mesh::Point3, 4> &x,
                          const double                       youngs_modulus,
                          const double                       poisson_ratio)
  {
    const auto [lambda, mu]    = lame_parameters(youngs_modulus, poisson_ratio);
    const auto          target = p1_element_stiffness(x, lambda, mu);
    std::vector<double> entries(144);
    for (unsigned int r = 0; r < 12; ++r)
      for (unsigned int c = 0; c < 12; ++c)
        entries[12 * r + c] = target(r, c);
    const std::vector<mesh::Point3>                points(x.begin(), x.end());
    const std::vector<std::array<unsigned int, 2>> edges(
      mesh::TetMesh::edge_vertices.begin(), mesh::TetMesh::edge_vertices.end());
    const std::vector<double> fit = fit_spring_stiffnesses(points, edges, entries);
    std::array<double, 6>     k{};
    std::copy(fit.begin(), fit.end(), k.begin());
    return k;
  }


  std::array<double, 6>
  fitted_edge_stiffnesses(const mesh::TetMesh               &mesh,
                          const unsigned int                 t,
                          const dealii::Function<3, double> &youngs_modulus,
                          const double                       poisson_ratio)
  {
    std::array<mesh::Point3, 4> x;
    for (unsigned int i = 0; i < 4; ++i)
      x[i] = mesh.vertex(mesh.tet(t)[i]);
    return fitted_edge_stiffnesses(x,
                                   youngs_modulus.value(centroid_of(mesh, t)),
                                   poisson_ratio);
  }


  SpringSet
  compute_springs(const mesh::TetMesh                      &mesh,
                  const std::vector<std::array<double, 6>> &cell_stiffness)
  {
    SpringSet springs =
      springs_from_contributions(mesh,
                                 [&](const unsigned int t, const std::vector<double> &)
                                 { return cell_stiffness[t]; });
    const double floor =
      1e-6 * *std::max_element(springs.stiffness.begin(), springs.stiffness.end());
    for (double &k : springs.stiffness)
      k = std::max(k, floor);
    return springs;
  }


  SpringSet
  compute_fitted_springs(const mesh::TetMesh               &mesh,
                         const dealii::Function<3, double> &youngs_modulus,
                         const double                       poisson_ratio)
  {
    SpringSet springs = springs_from_contributions(
      mesh,
      [&](const unsigned int t, const std::vector<double> &)
      { return fitted_edge_stiffnesses(mesh, t, youngs_modulus, poisson_ratio); });
    // An edge dropped by every tetrahedron it belongs to (a boundary edge of a single
    // tetrahedron, typically) would have no stiffness at all; the springs keep the
    // mesh's topology, so it gets a token 1e-6 of the stiffest spring instead.
    const double floor =
      1e-6 * *std::max_element(springs.stiffness.begin(), springs.stiffness.end());
    for (double &k : springs.stiffness)
      k = std::max(k, floor);
    return springs;
  }
} // namespace lacerta::physics
