// Force model `corotated fem`: explicit corotated linear elasticity on the P1
// tetrahedra (Müller and Gross 2004), with the masses of Section 3.1.

#include <lacerta/base/archive.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/matrix3.h>
#include <lacerta/physics/particle_ranges.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/partitioned_tets.h>

#include <array>
#include <cmath>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /**
     * The rotation R of deformation gradient @p F: if det F > 0 its polar factor
     * (F = R S, S symmetric positive definite), by Higham's scaled Newton iteration
     * X ← ½ (γ X + X⁻ᵀ / γ); otherwise (an inverted or flat element) the rotation of
     * the Gram–Schmidt QR factorisation of F, which is always proper.
     */
    Matrix3
    rotation_of(const Matrix3 &F)
    {
      double det = determinant(F);
      if (det > 0)
      {
        Matrix3 X = F;
        for (unsigned int iteration = 0; iteration < 40; ++iteration)
        {
          const Matrix3 inverse_t = inverse_transpose(X, det);
          const double  gamma =
            std::sqrt(std::sqrt(squared_norm(inverse_t) / squared_norm(X)));
          double change = 0;
          for (unsigned int k = 0; k < 9; ++k)
          {
            const double next = 0.5 * (gamma * X[k] + inverse_t[k] / gamma);
            change += (next - X[k]) * (next - X[k]);
            X[k] = next;
          }
          // Quadratic convergence: the next error is about change², below rounding.
          if (change < 1e-18)
            break;
          det = determinant(X);
        }
        return X;
      }
      // Columns c0, c1 of F orthonormalised, c2 = c0 × c1.
      double       c0[3] = {F[0], F[3], F[6]}, c1[3] = {F[1], F[4], F[7]};
      const double n0 = std::sqrt(c0[0] * c0[0] + c0[1] * c0[1] + c0[2] * c0[2]);
      if (!(n0 > 0))
        return {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
      for (double &c : c0)
        c /= n0;
      const double dot = c0[0] * c1[0] + c0[1] * c1[1] + c0[2] * c1[2];
      for (unsigned int d = 0; d < 3; ++d)
        c1[d] -= dot * c0[d];
      const double n1 = std::sqrt(c1[0] * c1[0] + c1[1] * c1[1] + c1[2] * c1[2]);
      if (!(n1 > 0))
        return {{1, 0, 0, 0, 1, 0, 0, 0, 1}};
      for (double &c : c1)
        c /= n1;
      const double c2[3] = {c0[1] * c1[2] - c0[2] * c1[1],
                            c0[2] * c1[0] - c0[0] * c1[2],
                            c0[0] * c1[1] - c0[1] * c1[0]};
      return {{c0[0], c1[0], c2[0], c0[1], c1[1], c2[1], c0[2], c1[2], c2[2]}};
    }


    /**
     * Explicit corotated linear elasticity on the P1 tetrahedra: in every tetrahedron
     * the deformation gradient F = D_s D_m⁻¹ (edge vectors now and at rest) is split
     * into its rotation R (rotation_of()) and a stretch, and the tetrahedron stores
     * V0 (μ |F - R|² + λ/2 tr(RᵀF - I)²), linear elasticity in the rotated frame. The
     * forces are minus its gradient, -V0 P D_m⁻ᵀ with P = 2μ (F - R) +
     * λ tr(RᵀF - I) R (the derivative of R drops out); at small rotations they are
     * those of the P1 element stiffness. Damping along springs becomes Rayleigh damping
     * β R K Rᵀ v. The masses are the system's (Section 3.1).
     *
     * Per-tetrahedron data are structures of arrays per thread range (PartitionedTets):
     * each range evaluates the tetrahedra touching it and writes its own vertices
     * only. After a cut or a tear the copies of the changed tetrahedra are replaced
     * (PartitionedTets::update()); the ranges are split again only when appended
     * particles have unbalanced them.
     */
    class CorotatedFem : public ForceModel
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &)
      {
      }

      void
      initialize(const ParticleSystem &system, const unsigned int n_threads) override
      {
        nu                               = checked_poisson_ratio(system, "corotated fem");
        const std::array<double, 2> lame = lame_parameters(1.0, nu);
        lambda_per_modulus               = lame[0];
        mu_per_modulus                   = lame[1];
        ranges.split(system, PartitionedTets::tets_per_particle(system), n_threads);
        tets.build(system, ranges);
      }

      void
      springs_changed(const ParticleSystem            &system,
                      const std::vector<unsigned int> &changed) override
      {
        // New particles join the last range; the masses of the changed springs' ends
        // and the copies of the changed tetrahedra are read again.
        ranges.append_particles(system);
        const std::size_t n_springs = system.springs.size();
        for (const unsigned int s : changed)
          if (s < n_springs)
          {
            ranges.update_inverse_mass(system, system.springs.a[s]);
            ranges.update_inverse_mass(system, system.springs.b[s]);
          }
        tets.update(system, ranges, changed);
        if (tets.unbalanced())
          initialize(system, ranges.threads());
      }

      void
      masses_changed(const ParticleSystem            &system,
                     const std::vector<unsigned int> &particles) override
      {
        for (const unsigned int i : particles)
          ranges.update_inverse_mass(system, i);
      }

      void
      compute_acceleration(const ParticleSystem &system,
                           const double         *x,
                           const double         *v,
                           double               *a,
                           const RangeUpdate     update) const override
      {
        ranges.for_each_part(
          [&](const unsigned int p)
          {
            element_forces_of_part(system, p, x, v, a);
            ranges.finish_accelerations(system, p, v, a);
            update(ranges.begin(p), ranges.end(p));
          });
      }

      void
      compute_spring_forces(const ParticleSystem &system,
                            const double         *x,
                            const double         *v,
                            double               *f) const override
      {
        ranges.for_each_part([&](const unsigned int p)
                             { element_forces_of_part(system, p, x, v, f); });
      }

      double
      elastic_energy(const ParticleSystem &, const double *x) const override
      {
        double energy = 0;
        tets.for_each_tet(
          [&](unsigned int, const unsigned int p, const std::size_t c)
          {
            const PartitionedTets::Part &part    = tets.part(p);
            const Matrix3                F       = part.deformation_gradient(c, x);
            const Matrix3                R       = rotation_of(F);
            double                       stretch = 0, trace = -3;
            for (unsigned int k = 0; k < 9; ++k)
              stretch += (F[k] - R[k]) * (F[k] - R[k]);
            for (unsigned int k = 0; k < 9; ++k)
              trace += R[k] * F[k];
            energy +=
              part.rest_volume[c] * part.youngs_modulus[c]
              * (mu_per_modulus * stretch + 0.5 * lambda_per_modulus * trace * trace);
          });
        return energy;
      }

      const ParticleRanges &
      particle_ranges() const override
      {
        return ranges;
      }

      double
      spring_stiffness_scale() const override
      {
        return 0;
      }

      bool
      has_element_stiffness() const override
      {
        return true;
      }

      void
      for_each_element_stiffness(
        const ParticleSystem                                              &system,
        const double                                                      *x,
        const std::function<void(unsigned int, const ElementStiffness &)> &visit)
        const override
      {
        tets.for_each_tet([&](unsigned int t, unsigned int p, std::size_t c)
                          { visit(t, rotated_stiffness(*system.mesh, p, c, x)); });
      }

      void
      for_each_element_stiffness_of(
        const ParticleSystem                                              &system,
        const double                                                      *x,
        const std::vector<unsigned int>                                   &list,
        const std::function<void(unsigned int, const ElementStiffness &)> &visit)
        const override
      {
        tets.for_each_copy_of(list,
                              [&](unsigned int t, unsigned int p, std::size_t c)
                              { visit(t, rotated_stiffness(*system.mesh, p, c, x)); });
      }

    private:
      /**
       * The stress P of copy @p c: 2μ (F - R) + λ tr(RᵀF - I) R, plus with β > 0 the
       * damping stress β R (2μ sym(RᵀḞ) + λ tr(RᵀḞ) I).
       */
      Matrix3
      stress(const unsigned int p,
             const std::size_t  c,
             const double      *x,
             const double      *v,
             const double       beta) const
      {
        const Matrix3 F      = tets.part(p).deformation_gradient(c, x);
        const Matrix3 R      = rotation_of(F);
        const double  youngs = tets.part(p).youngs_modulus[c];
        const double  l = lambda_per_modulus * youngs, m = mu_per_modulus * youngs;
        double        trace = -3;
        for (unsigned int k = 0; k < 9; ++k)
          trace += R[k] * F[k];
        Matrix3 P;
        for (unsigned int k = 0; k < 9; ++k)
          P[k] = 2 * m * (F[k] - R[k]) + l * trace * R[k];
        if (beta > 0)
        {
          // G = Rᵀ Ḟ, the velocity gradient in the rotated frame.
          const Matrix3 Fdot = tets.part(p).deformation_gradient(c, v);
          Matrix3       G{};
          for (unsigned int r = 0; r < 3; ++r)
            for (unsigned int s = 0; s < 3; ++s)
              for (unsigned int k = 0; k < 3; ++k)
                G[3 * r + s] += R[3 * k + r] * Fdot[3 * k + s];
          const double rate = G[0] + G[4] + G[8];
          Matrix3      sigma;
          for (unsigned int r = 0; r < 3; ++r)
            for (unsigned int s = 0; s < 3; ++s)
              sigma[3 * r + s] =
                beta * (m * (G[3 * r + s] + G[3 * s + r]) + (r == s ? l * rate : 0.0));
          for (unsigned int r = 0; r < 3; ++r)
            for (unsigned int s = 0; s < 3; ++s)
              for (unsigned int k = 0; k < 3; ++k)
                P[3 * r + s] += R[3 * r + k] * sigma[3 * k + s];
        }
        return P;
      }

      /// Zeroes the forces of range @p p's particles and adds its tetrahedra's forces.
      void
      element_forces_of_part(const ParticleSystem &system,
                             const unsigned int    p,
                             const double         *x,
                             const double         *v,
                             double               *f) const
      {
        ranges.zero(p, f);
        const PartitionedTets::Part &part = tets.part(p);
        const double                 beta = system.spring_damping;
        for (std::size_t c = 0; c < part.size(); ++c)
        {
          part.add_owned_nodal_forces(c, stress(p, c, x, v, beta), f);
        }
      }

      /// R K Rᵀ of copy @p c, K the P1 element stiffness at rest, R its rotation at x.
      ElementStiffness
      rotated_stiffness(const mesh::TetMesh &mesh,
                        const unsigned int   p,
                        const std::size_t    c,
                        const double        *x) const
      {
        const Matrix3 R = rotation_of(tets.part(p).deformation_gradient(c, x));
        std::array<mesh::Point3, 4> rest;
        for (unsigned int i = 0; i < 4; ++i)
          rest[i] = mesh.vertex(mesh.tet(tets.part(p).tet[c])[i]);
        const dealii::FullMatrix<double> K =
          p1_element_stiffness(rest,
                               lambda_per_modulus * tets.part(p).youngs_modulus[c],
                               mu_per_modulus * tets.part(p).youngs_modulus[c]);
        ElementStiffness rotated{};
        for (unsigned int a = 0; a < 4; ++a)
          for (unsigned int b = 0; b < 4; ++b)
            for (unsigned int r = 0; r < 3; ++r)
              for (unsigned int s = 0; s < 3; ++s)
              {
                double sum = 0;
                for (unsigned int k = 0; k < 3; ++k)
                  for (unsigned int l = 0; l < 3; ++l)
                    sum += R[3 * r + k] * K(3 * a + k, 3 * b + l) * R[3 * s + l];
                rotated[12 * (3 * a + r) + 3 * b + s] = sum;
              }
        return rotated;
      }

    public:
      /// The ranges and the copies of the tetrahedra in them.
      void
      serialize(Archive &archive) override
      {
        archive(ranges, tets);
      }

    private:
      double          nu = 0.25;
      ParticleRanges  ranges;
      PartitionedTets tets;
      /// λ / E and μ / E at the Poisson ratio (λ and μ are linear in E).
      double lambda_per_modulus = 0, mu_per_modulus = 0;
    };
  } // namespace

  LACERTA_REGISTER_FORCE_MODEL(
    CorotatedFem,
    "corotated fem",
    "Explicit corotated linear elasticity on the P1 tetrahedra (Mueller and Gross "
    "2004) with E and 'Material/Poisson ratio', rotations by polar decomposition; the "
    "springs then only tell where the tissue tears (doc/physics.md).");
} // namespace lacerta::physics
