#include <lacerta/physics/assembly.h>

#include <deal.II/base/function.h>
#include <deal.II/base/quadrature_lib.h>

#include <algorithm>
#include <cmath>

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


  double
  tet_stiffness_factor(const mesh::TetMesh               &mesh,
                       const unsigned int                 t,
                       const dealii::Function<3, double> &youngs_modulus)
  {
    dealii::Point<3> centroid;
    for (const unsigned int v : mesh.tet(t))
      for (unsigned int d = 0; d < 3; ++d)
        centroid[d] += 0.25 * mesh.vertex(v)[d];
    return youngs_modulus.value(centroid) * mesh.volume(t);
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
      const double e_times_v = tet_stiffness_factor(mesh, t, youngs_modulus);
      for (const unsigned int e : mesh.tet_edges(t))
        stiffness[e] += e_times_v / (length[e] * length[e]);
    }

    SpringSet springs;
    for (unsigned int e = 0; e < edges.size(); ++e)
      springs.push_back(edges[e][0], edges[e][1], stiffness[e], length[e]);
    return springs;
  }
} // namespace lacerta::physics
