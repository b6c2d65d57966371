#include <lacerta/base/exceptions.h>
#include <lacerta/base/fnv_hash.h>
#include <lacerta/mesh/point.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/homogenized_stiffness.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/precondition.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>

namespace lacerta::mt
{
  namespace
  {
    /**
     * A network of springs at rest: its vertices, its edges with the stiffness of the
     * cells that keep the rule (`fixed`) and of those the scale multiplies (`scaled`),
     * which vertices lie on its boundary, and its volume.
     */
    struct Network
    {
      std::vector<mesh::Point3>                x;
      std::vector<std::array<unsigned int, 2>> edges;
      std::vector<double>                      fixed, scaled;
      std::vector<std::uint8_t>                boundary;
      double                                   volume = 0;
    };


    /// The network of the MT tetrahedra @p tets; those with a destroyer are scaled.
    Network
    network_of(const MultiTriangulation         &mt,
               const std::vector<std::uint32_t> &tets,
               const EdgeStiffnessRule          &rule)
    {
      Network                   net;
      std::vector<unsigned int> local(mt.vertices.size(), mesh::invalid_index);
      const auto                local_of = [&](const std::uint32_t v)
      {
        if (local[v] == mesh::invalid_index)
        {
          local[v] = static_cast<unsigned int>(net.x.size());
          net.x.push_back(mt.vertices[v]);
        }
        return local[v];
      };
      struct EdgeTerm
      {
        std::array<unsigned int, 2> ends;
        double                      fixed, scaled;
      };
      std::vector<EdgeTerm>                    terms;
      std::vector<std::array<unsigned int, 3>> faces;
      for (const std::uint32_t t : tets)
      {
        const std::array<mesh::Point3, 4> corner = mt.corners(t);
        std::array<unsigned int, 4>       v;
        for (unsigned int i = 0; i < 4; ++i)
          v[i] = local_of(mt.tets[t][i]);
        net.volume +=
          std::abs(mesh::signed_volume(corner[0], corner[1], corner[2], corner[3]));
        const bool                  coarse = mt.destroyer[t] != mesh::invalid_index;
        const std::array<double, 6> k      = rule(corner);
        for (unsigned int e = 0; e < 6; ++e)
        {
          const auto [a, b] = mesh::TetMesh::edge_vertices[e];
          terms.push_back({{{std::min(v[a], v[b]), std::max(v[a], v[b])}},
                           coarse ? 0.0 : k[e],
                           coarse ? k[e] : 0.0});
        }
        for (const auto &fv : mesh::TetMesh::face_vertices)
        {
          std::array<unsigned int, 3> f{{v[fv[0]], v[fv[1]], v[fv[2]]}};
          std::sort(f.begin(), f.end());
          faces.push_back(f);
        }
      }
      std::sort(terms.begin(),
                terms.end(),
                [](const EdgeTerm &p, const EdgeTerm &q) { return p.ends < q.ends; });
      for (const EdgeTerm &term : terms)
        if (!net.edges.empty() && net.edges.back() == term.ends)
        {
          net.fixed.back() += term.fixed;
          net.scaled.back() += term.scaled;
        }
        else
        {
          net.edges.push_back(term.ends);
          net.fixed.push_back(term.fixed);
          net.scaled.push_back(term.scaled);
        }
      // A face of one cell only lies on the boundary.
      std::sort(faces.begin(), faces.end());
      net.boundary.assign(net.x.size(), 0);
      for (std::size_t i = 0; i < faces.size();)
      {
        std::size_t j = i + 1;
        while (j < faces.size() && faces[j] == faces[i])
          ++j;
        if (j - i == 1)
          for (const unsigned int v : faces[i])
            net.boundary[v] = 1;
        i = j;
      }
      return net;
    }


    /**
     * Σ over the six unit strains of an orthonormal basis of symmetric tensors of the
     * energy of @p net (scaled springs times @p s) with its boundary vertices displaced
     * affinely and its interior vertices at equilibrium, per volume.
     */
    double
    relaxed_energy_density(const Network &net, const double s)
    {
      const std::size_t         n = net.x.size();
      std::vector<unsigned int> dof(n, mesh::invalid_index);
      unsigned int              n_interior = 0;
      for (std::size_t i = 0; i < n; ++i)
        if (!net.boundary[i])
          dof[i] = n_interior++;
      // The six strains: e_i ⊗ e_i and (e_i ⊗ e_j + e_j ⊗ e_i) / √2.
      std::array<std::array<std::array<double, 3>, 3>, 6> strain{};
      for (unsigned int i = 0; i < 3; ++i)
        strain[i][i][i] = 1;
      const double r  = 1 / std::sqrt(2.0);
      strain[3][0][1] = strain[3][1][0] = r;
      strain[4][1][2] = strain[4][2][1] = r;
      strain[5][0][2] = strain[5][2][0] = r;
      // The affine displacement of every vertex for each strain; the interior ones are
      // replaced by the equilibrium below.
      std::array<std::vector<double>, 6> u;
      for (unsigned int m = 0; m < 6; ++m)
      {
        u[m].assign(3 * n, 0.0);
        for (std::size_t i = 0; i < n; ++i)
          for (unsigned int a = 0; a < 3; ++a)
            for (unsigned int b = 0; b < 3; ++b)
              u[m][3 * i + a] += strain[m][a][b] * net.x[i][b];
      }
      if (n_interior > 0)
      {
        dealii::DynamicSparsityPattern pattern(3 * n_interior);
        for (const auto &[a, b] : net.edges)
          for (const unsigned int p : {a, b})
            for (const unsigned int q : {a, b})
              if (dof[p] != mesh::invalid_index && dof[q] != mesh::invalid_index)
                for (unsigned int i = 0; i < 3; ++i)
                  for (unsigned int j = 0; j < 3; ++j)
                    pattern.add(3 * dof[p] + i, 3 * dof[q] + j);
        dealii::SparsityPattern sparsity;
        sparsity.copy_from(pattern);
        dealii::SparseMatrix<double>          K(sparsity);
        std::array<dealii::Vector<double>, 6> rhs;
        for (auto &b : rhs)
          b.reinit(3 * n_interior);
        for (std::size_t e = 0; e < net.edges.size(); ++e)
        {
          const auto [a, b]     = net.edges[e];
          const mesh::Point3 d  = mesh::sub(net.x[b], net.x[a]);
          const double       k  = (net.fixed[e] + s * net.scaled[e]) / mesh::dot(d, d);
          const unsigned int pa = dof[a], pb = dof[b];
          for (unsigned int i = 0; i < 3; ++i)
            for (unsigned int j = 0; j < 3; ++j)
            {
              const double kij = k * d[i] * d[j];
              if (pa != mesh::invalid_index)
                K.add(3 * pa + i, 3 * pa + j, kij);
              if (pb != mesh::invalid_index)
                K.add(3 * pb + i, 3 * pb + j, kij);
              if (pa != mesh::invalid_index && pb != mesh::invalid_index)
              {
                K.add(3 * pa + i, 3 * pb + j, -kij);
                K.add(3 * pb + i, 3 * pa + j, -kij);
              }
              // A boundary end's prescribed displacement loads the interior one.
              for (unsigned int m = 0; m < 6; ++m)
              {
                if (pa != mesh::invalid_index && pb == mesh::invalid_index)
                  rhs[m][3 * pa + i] += kij * u[m][3 * b + j];
                if (pb != mesh::invalid_index && pa == mesh::invalid_index)
                  rhs[m][3 * pb + i] += kij * u[m][3 * a + j];
              }
            }
        }
        // Conjugate gradients from the affine guess (zero correction), SSOR-
        // preconditioned: the matrix is symmetric positive definite once the
        // boundary holds the network.
        dealii::PreconditionSSOR<dealii::SparseMatrix<double>> preconditioner;
        preconditioner.initialize(K, 1.2);
        for (unsigned int m = 0; m < 6; ++m)
        {
          dealii::Vector<double> solution(3 * n_interior);
          dealii::SolverControl  control(100000, 1e-10 * rhs[m].l2_norm());
          dealii::SolverCG<dealii::Vector<double>> cg(control);
          try
          {
            cg.solve(K, solution, rhs[m], preconditioner);
          }
          catch (const std::exception &)
          {
            throw_error("Multiresolution: 'Coarse stiffness = homogenized': the "
                        "springs of a mesh of the Multi-Triangulation do not hold its "
                        "interior vertices (conjugate gradients did not converge); use "
                        "'Coarse stiffness = rule'.");
          }
          for (std::size_t i = 0; i < n; ++i)
            if (dof[i] != mesh::invalid_index)
              for (unsigned int a = 0; a < 3; ++a)
                u[m][3 * i + a] = solution[3 * dof[i] + a];
        }
      }
      double energy = 0;
      for (std::size_t e = 0; e < net.edges.size(); ++e)
      {
        const auto [a, b]    = net.edges[e];
        const mesh::Point3 d = mesh::sub(net.x[b], net.x[a]);
        const double       k = (net.fixed[e] + s * net.scaled[e]) / mesh::dot(d, d);
        for (unsigned int m = 0; m < 6; ++m)
        {
          double stretch = 0;
          for (unsigned int i = 0; i < 3; ++i)
            stretch += d[i] * (u[m][3 * b + i] - u[m][3 * a + i]);
          energy += 0.5 * k * stretch * stretch;
        }
      }
      return energy / net.volume;
    }


    /// The tetrahedra of the input mesh and of the coarsest mesh of the MT as built
    /// (those a cut appended later are in neither).
    std::array<std::vector<std::uint32_t>, 2>
    input_and_root(const MultiTriangulation &mt)
    {
      std::array<std::vector<std::uint32_t>, 2> meshes;
      for (std::uint32_t t = 0; t < mt.fine_begin.back(); ++t)
      {
        if (mt.destroyer[t] == mesh::invalid_index)
          meshes[0].push_back(t);
        if (mt.creator[t] == 0)
          meshes[1].push_back(t);
      }
      return meshes;
    }


    /// FNV-1a over @p rule's stiffnesses on the tetrahedra of both meshes.
    std::uint64_t
    rule_checksum(const MultiTriangulation &mt, const EdgeStiffnessRule &rule)
    {
      FnvHash hash;
      for (const auto &tets : input_and_root(mt))
        for (const std::uint32_t t : tets)
        {
          const std::array<double, 6> k = rule(mt.corners(t));
          hash.add(k.data(), sizeof(k));
        }
      return hash.value;
    }
  } // namespace


  HomogenizedScale
  homogenized_coarse_scale(const MultiTriangulation &mt, const EdgeStiffnessRule &rule)
  {
    HomogenizedScale result;
    if (mt.n_nodes() < 2)
      return result;
    const auto [fine, root]      = input_and_root(mt);
    result.fine_energy_density   = relaxed_energy_density(network_of(mt, fine, rule), 1);
    const Network coarse         = network_of(mt, root, rule);
    result.coarse_energy_density = relaxed_energy_density(coarse, 1);
    // The energy grows with s (linearly where every cell is scaled): secant steps from
    // s = 1 and the linear guess.
    const double target = result.fine_energy_density;
    double       s0 = 1, f0 = result.coarse_energy_density - target;
    double       s1     = target / result.coarse_energy_density;
    result.iterations   = 1;
    const auto in_range = [](const double s) { return s >= 0.1 && s <= 10; };
    while (in_range(s1) && std::abs(f0) > 1e-6 * target && result.iterations < 20)
    {
      const double f1 = relaxed_energy_density(coarse, s1) - target;
      ++result.iterations;
      if (f1 == f0)
        break;
      const double s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
      s0              = s1;
      f0              = f1;
      s1              = s2;
    }
    if (!in_range(s0) || !(std::abs(f0) <= 1e-4 * target))
      throw_error("Multiresolution: 'Coarse stiffness = homogenized': no factor in "
                  "[0.1, 10] gives the coarsest mesh the energy under uniform strain of "
                  "the input mesh (fine ",
                  result.fine_energy_density,
                  ", coarse ",
                  result.coarse_energy_density,
                  " J/m^3); use 'Coarse stiffness = rule'.");
    result.scale = s0;
    return result;
  }


  HomogenizedScale
  cached_homogenized_coarse_scale(const MultiTriangulation &mt,
                                  const EdgeStiffnessRule  &rule,
                                  const std::string        &file)
  {
    if (file.empty())
      return homogenized_coarse_scale(mt, rule);
    const std::uint64_t key    = rule_checksum(mt, rule);
    const std::string   format = "lacerta-homogenized-scale-1";
    {
      std::ifstream    in(file);
      std::string      name;
      std::uint64_t    stored = 0;
      HomogenizedScale h;
      if (in >> name >> stored >> h.scale >> h.fine_energy_density
            >> h.coarse_energy_density >> h.iterations
          && name == format && stored == key && std::isfinite(h.scale) && h.scale > 0)
      {
        h.loaded = true;
        return h;
      }
    }
    const HomogenizedScale h         = homogenized_coarse_scale(mt, rule);
    const std::string      temporary = file + ".tmp";
    {
      std::ofstream out(temporary);
      out << format << ' ' << key << ' ' << std::setprecision(17) << h.scale << ' '
          << h.fine_energy_density << ' ' << h.coarse_energy_density << ' '
          << h.iterations << '\n';
      if (!out)
        return h;
    }
    std::error_code error;
    std::filesystem::rename(temporary, file, error);
    return h;
  }
} // namespace lacerta::mt
