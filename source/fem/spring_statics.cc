#include <lacerta/base/exceptions.h>
#include <lacerta/fem/spring_statics.h>
#include <lacerta/fem/subspace_iteration.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>

#include <algorithm>
#include <cmath>

namespace lacerta::fem
{
  namespace
  {
    using namespace dealii;

    /**
     * The stiffness of the system's force model linearised at rest (the springs, scaled
     * as the model scales them, plus the model's element stiffnesses per tetrahedron),
     * unconstrained and with the constrained particles' rows and columns eliminated,
     * with its sparsity pattern (every pair of vertices of a tetrahedron is a spring).
     */
    struct SpringStiffness
    {
      explicit SpringStiffness(const physics::ParticleSystem &system)
      {
        const unsigned int n = 3 * system.n_particles();
        for (unsigned int i = 0; i < system.n_particles(); ++i)
          if (system.free[i] == 0)
            for (unsigned int d = 0; d < 3; ++d)
              constraints.add_line(3 * i + d);
        constraints.close();

        DynamicSparsityPattern dsp(n, n);
        for (unsigned int i = 0; i < n; ++i)
          dsp.add(i, i);
        const auto &springs = system.springs;
        for (std::size_t s = 0; s < springs.size(); ++s)
          for (unsigned int d = 0; d < 3; ++d)
            for (unsigned int e = 0; e < 3; ++e)
              for (const unsigned int p : {springs.a[s], springs.b[s]})
                for (const unsigned int q : {springs.a[s], springs.b[s]})
                  dsp.add(3 * p + d, 3 * q + e);
        pattern.copy_from(dsp);
        full.reinit(pattern);
        constrained.reinit(pattern);

        const double scale =
          system.has_force_model() ? system.force_model().spring_stiffness_scale() : 1.0;
        const auto                          &rest = system.rest_position();
        FullMatrix<double>                   local(6, 6);
        std::vector<types::global_dof_index> dofs(6);
        for (std::size_t s = 0; s < springs.size() && scale != 0; ++s)
        {
          const unsigned int a = springs.a[s], b = springs.b[s];
          double             n_ab[3], length     = 0;
          for (unsigned int d = 0; d < 3; ++d)
          {
            n_ab[d] = rest[3 * b + d] - rest[3 * a + d];
            length += n_ab[d] * n_ab[d];
          }
          length = std::sqrt(length);
          for (unsigned int d = 0; d < 3; ++d)
          {
            dofs[d]     = 3 * a + d;
            dofs[3 + d] = 3 * b + d;
          }
          for (unsigned int d = 0; d < 3; ++d)
            for (unsigned int e = 0; e < 3; ++e)
            {
              const double k =
                scale * springs.stiffness[s] * n_ab[d] * n_ab[e] / (length * length);
              local(d, e) = local(3 + d, 3 + e) = k;
              local(d, 3 + e) = local(3 + d, e) = -k;
            }
          add(local, dofs);
        }
        if (system.has_force_model())
        {
          FullMatrix<double> element(12, 12);
          dofs.resize(12);
          system.force_model().for_each_element_stiffness(
            system,
            rest.data(),
            [&](const unsigned int t, const physics::ForceModel::ElementStiffness &K)
            {
              const auto &tet = system.mesh->tet(t);
              for (unsigned int i = 0; i < 12; ++i)
              {
                dofs[i] = 3 * tet[i / 3] + i % 3;
                for (unsigned int j = 0; j < 12; ++j)
                  element(i, j) = K[12 * i + j];
              }
              add(element, dofs);
            });
        }
        // A particle joined to nothing free would leave a zero row.
        for (unsigned int i = 0; i < n; ++i)
          if (constrained.diag_element(i) == 0)
            constrained.set(i, i, 1.0);
      }

      /// Adds a local matrix on @p dofs to both matrices.
      void
      add(const FullMatrix<double>                   &local,
          const std::vector<types::global_dof_index> &dofs)
      {
        for (unsigned int i = 0; i < dofs.size(); ++i)
          for (unsigned int j = 0; j < dofs.size(); ++j)
            full.add(dofs[i], dofs[j], local(i, j));
        constraints.distribute_local_to_global(local, dofs, constrained);
      }

      AffineConstraints<double> constraints;
      SparsityPattern           pattern;
      SparseMatrix<double>      full, constrained;
    };
  } // namespace


  std::vector<double>
  solve_linearised_springs(const physics::ParticleSystem &system)
  {
    const SpringStiffness stiffness(system);
    const unsigned int    n = 3 * system.n_particles();
    Vector<double>        u_d(n), f(n), residual(n), w(n);
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
      {
        const unsigned int k = 3 * i + d;
        if (system.free[i] == 0)
          u_d(k) = system.position[k] - system.rest_position()[k];
        f(k) = system.mass[i] * system.body_acceleration[d] + system.external_force[k];
      }
    stiffness.full.vmult(residual, u_d);
    residual.sadd(-1.0, 1.0, f);
    stiffness.constraints.set_zero(residual);
    SparseDirectUMFPACK direct;
    direct.initialize(stiffness.constrained);
    direct.vmult(w, residual);
    stiffness.constraints.set_zero(w);
    w += u_d;
    return std::vector<double>(w.begin(), w.end());
  }


  RelaxationResult
  relax_springs(physics::ParticleSystem &system,
                const double             tolerance,
                const unsigned int       max_iterations)
  {
    const unsigned int  n = system.n_particles();
    std::vector<double> fictitious(n, 0.0);
    const auto         &springs = system.springs;
    const double        scale =
      system.has_force_model() ? system.force_model().spring_stiffness_scale() : 1.0;
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      fictitious[springs.a[s]] += std::sqrt(3.0) * scale * springs.stiffness[s];
      fictitious[springs.b[s]] += std::sqrt(3.0) * scale * springs.stiffness[s];
    }
    // The model's tetrahedra: every element adds at most its largest row sum at each
    // of its vertices (Gershgorin), counted once per element around the particle.
    if (system.has_force_model() && system.mesh)
    {
      std::vector<double> element_bound(n, 0.0);
      system.force_model().for_each_element_stiffness(
        system,
        system.rest_position().data(),
        [&](const unsigned int t, const physics::ForceModel::ElementStiffness &K)
        {
          const auto &tet = system.mesh->tet(t);
          for (unsigned int i = 0; i < 12; ++i)
          {
            double row = 0;
            for (unsigned int j = 0; j < 12; ++j)
              row += std::abs(K[12 * i + j]);
            element_bound[tet[i / 3]] = std::max(element_bound[tet[i / 3]], row);
          }
          for (const unsigned int v : tet)
          {
            fictitious[v] += element_bound[v];
            element_bound[v] = 0;
          }
        });
    }
    std::vector<double> load(3 * n), force(3 * n), zero(3 * n, 0.0), v(3 * n, 0.0);
    double              largest_load = 0;
    for (unsigned int i = 0; i < n; ++i)
      for (unsigned int d = 0; d < 3; ++d)
      {
        load[3 * i + d] = system.free[i]
                          * (system.mass[i] * system.body_acceleration[d]
                             + system.external_force[3 * i + d]);
        largest_load = std::max(largest_load, std::abs(load[3 * i + d]));
      }

    RelaxationResult result;
    double           previous_energy = 0;
    for (result.iterations = 0; result.iterations < max_iterations; ++result.iterations)
    {
      system.force_model().compute_spring_forces(system,
                                                 system.position.data(),
                                                 zero.data(),
                                                 force.data());
      double largest = 0, energy = 0;
      for (unsigned int i = 0; i < n; ++i)
        for (unsigned int d = 0; d < 3; ++d)
        {
          const unsigned int k = 3 * i + d;
          const double       r = system.free[i] * (force[k] + load[k]);
          largest              = std::max(largest, std::abs(r));
          v[k] += r / fictitious[i];
          energy += fictitious[i] * v[k] * v[k];
        }
      // A displacement-driven problem (prescribed particles moved, small or no loads)
      // is measured against the pull of its prescribed particles at the start.
      if (result.iterations == 0)
        largest_load = std::max(largest_load, largest);
      result.relative_residual = largest_load > 0 ? largest / largest_load : 0;
      if (result.relative_residual < tolerance)
        break;
      // Kinetic damping: at a peak of the kinetic energy the system passes the minimum
      // of the potential energy along its path; stopping there removes that mode.
      if (energy < previous_energy)
      {
        std::fill(v.begin(), v.end(), 0.0);
        energy = 0;
      }
      previous_energy = energy;
      for (std::size_t k = 0; k < v.size(); ++k)
        system.position[k] += v[k];
    }
    if (result.relative_residual >= tolerance)
      throw_error(
        "Dynamic relaxation of the springs did not reach the relative residual ",
        tolerance,
        " in ",
        max_iterations,
        " iterations (it reached ",
        result.relative_residual,
        ").");
    result.displacement.resize(3 * n);
    for (std::size_t k = 0; k < result.displacement.size(); ++k)
      result.displacement[k] = system.position[k] - system.rest_position()[k];
    return result;
  }


  std::vector<double>
  spring_frequencies(const physics::ParticleSystem &system, const unsigned int n)
  {
    const SpringStiffness stiffness(system);
    SparseDirectUMFPACK   direct;
    direct.initialize(stiffness.constrained);
    const unsigned int size = 3 * system.n_particles();
    return to_frequencies(lowest_eigenvalues<Vector<double>>(
      n,
      [&](Vector<double> &x, const unsigned int j)
      {
        x.reinit(size);
        for (unsigned int i = 0; i < size; ++i)
          x(i) = std::sin(1.0 + 12.9898 * i + 78.233 * (j + 1));
      },
      [&](Vector<double> &dst, const Vector<double> &src)
      { stiffness.full.vmult(dst, src); },
      [&](Vector<double> &dst, const Vector<double> &src)
      {
        for (unsigned int i = 0; i < size; ++i)
          dst(i) = system.mass[i / 3] * src(i);
      },
      [&](Vector<double> &dst, const Vector<double> &src) { direct.vmult(dst, src); },
      [&](Vector<double> &x) { stiffness.constraints.set_zero(x); }));
  }
} // namespace lacerta::fem
