// Force model `volume springs`: the paper's springs, rescaled, plus a volume or a shear
// term per tetrahedron, so that the pair reproduces Young's modulus and the Poisson
// ratio.

#include <lacerta/base/archive.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/linear_springs.h>
#include <lacerta/physics/matrix3.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/partitioned_tets.h>
#include <lacerta/physics/volume_spring_parameters.h>

#include <array>
#include <vector>

namespace lacerta::physics
{
  namespace
  {
    /// The gradients ∂V/∂x_i of the signed volume V of tetrahedron (x0, x1, x2, x3),
    /// 3 per local vertex; returns V.
    inline double
    volume_gradient(const double *x0,
                    const double *x1,
                    const double *x2,
                    const double *x3,
                    double (&g)[4][3])
    {
      const double     d1[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]};
      const double     d2[3] = {x2[0] - x0[0], x2[1] - x0[1], x2[2] - x0[2]};
      const double     d3[3] = {x3[0] - x0[0], x3[1] - x0[1], x3[2] - x0[2]};
      constexpr double sixth = 1.0 / 6.0;
      g[1][0]                = sixth * (d2[1] * d3[2] - d2[2] * d3[1]);
      g[1][1]                = sixth * (d2[2] * d3[0] - d2[0] * d3[2]);
      g[1][2]                = sixth * (d2[0] * d3[1] - d2[1] * d3[0]);
      g[2][0]                = sixth * (d3[1] * d1[2] - d3[2] * d1[1]);
      g[2][1]                = sixth * (d3[2] * d1[0] - d3[0] * d1[2]);
      g[2][2]                = sixth * (d3[0] * d1[1] - d3[1] * d1[0]);
      g[3][0]                = sixth * (d1[1] * d2[2] - d1[2] * d2[1]);
      g[3][1]                = sixth * (d1[2] * d2[0] - d1[0] * d2[2]);
      g[3][2]                = sixth * (d1[0] * d2[1] - d1[1] * d2[0]);
      for (unsigned int d = 0; d < 3; ++d)
        g[0][d] = -(g[1][d] + g[2][d] + g[3][d]);
      return d1[0] * g[1][0] + d1[1] * g[1][1] + d1[2] * g[1][2];
    }


    /// dev(sym(Fᵀ G)): with G = F twice the deviator of the Green strain
    /// ½ (FᵀF - I) (the identity has no deviator), with G = Ḟ the deviator of the
    /// Green strain's rate.
    inline Matrix3
    symmetric_product_deviator(const Matrix3 &F, const Matrix3 &G)
    {
      Matrix3 product{};
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int s = 0; s < 3; ++s)
          for (unsigned int k = 0; k < 3; ++k)
            product[3 * r + s] +=
              0.5 * (F[3 * k + r] * G[3 * k + s] + G[3 * k + r] * F[3 * k + s]);
      const double mean = (product[0] + product[4] + product[8]) / 3;
      product[0] -= mean;
      product[4] -= mean;
      product[8] -= mean;
      return product;
    }

    /// F S, the first Piola–Kirchhoff stress of second Piola–Kirchhoff stress @p S.
    inline Matrix3
    first_piola(const Matrix3 &F, const Matrix3 &S)
    {
      Matrix3 P{};
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int s = 0; s < 3; ++s)
          for (unsigned int k = 0; k < 3; ++k)
            P[3 * r + s] += F[3 * r + k] * S[3 * k + s];
      return P;
    }


    /**
     * The paper's springs with their stiffness scaled by α(ν), plus per tetrahedron
     * either the volume energy ½ κ V0 (V/V0 - 1)² (ν above the lattice's own ratio)
     * or the shear energy μ_d V0 |dev E|², E the Green strain (ν below it), with
     * κ = κ̂(ν) E and μ_d = μ̂(ν) E at the centroid (doc/physics.md derives α, κ̂, μ̂).
     * The springs are those of LinearSprings, on the same particle ranges; every range
     * also evaluates the tetrahedra that touch it (PartitionedTets) and adds their
     * forces to its own vertices only.
     *
     * After a cut or a tear the springs and the copies of the changed tetrahedra are
     * updated locally (LinearSprings, PartitionedTets::update()).
     */
    class VolumeSprings : public LinearSprings
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Lattice Poisson ratio",
          "0.25",
          dealii::Patterns::Double(0.05, 0.25),
          "The Poisson ratio the paper's springs show on the mesh, from which the "
          "springs' scale and the term per tetrahedron are derived (doc/physics.md): "
          "0.25 for an isotropic lattice (the orientation average), 0.117 measured on "
          "box meshes (hexahedra split into five tetrahedra). Asked ratios above it "
          "add a volume term, ratios below it a shear term.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        lattice_nu = prm.get_double("Lattice Poisson ratio");
      }

      void
      initialize(const ParticleSystem &system, const unsigned int n_threads) override
      {
        parameters =
          volume_spring_parameters(checked_poisson_ratio(system, "volume springs"),
                                   lattice_nu);
        set_stiffness_scale(parameters.spring_scale);
        LinearSprings::initialize(system, n_threads);
        tets.build(system, ranges);
      }

      void
      springs_changed(const ParticleSystem            &system,
                      const std::vector<unsigned int> &changed) override
      {
        // The springs may split their ranges again (when appended particles have
        // unbalanced them); then every tetrahedron is copied again, else only the
        // changed ones.
        range_starts.clear();
        for (unsigned int p = 0; p < ranges.n_parts(); ++p)
          range_starts.push_back(ranges.begin(p));
        LinearSprings::springs_changed(system, changed);
        bool same_ranges = range_starts.size() == ranges.n_parts();
        for (unsigned int p = 0; same_ranges && p < ranges.n_parts(); ++p)
          same_ranges = range_starts[p] == ranges.begin(p);
        if (same_ranges)
          tets.update(system, ranges, changed);
        else
          tets.build(system, ranges);
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
            spring_forces_of_part(system, p, x, v, a);
            add_element_forces(system, p, x, v, a);
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
        ranges.for_each_part(
          [&](const unsigned int p)
          {
            spring_forces_of_part(system, p, x, v, f);
            add_element_forces(system, p, x, v, f);
          });
      }

      double
      elastic_energy(const ParticleSystem &system, const double *x) const override
      {
        double energy = LinearSprings::elastic_energy(system, x);
        tets.for_each_tet([&](unsigned int, unsigned int p, std::size_t c)
                          { energy += element_energy(tets.part(p), c, x); });
        return energy;
      }

      bool
      has_element_stiffness() const override
      {
        return true;
      }

      void
      for_each_element_stiffness(
        const ParticleSystem &,
        const double                                                      *x,
        const std::function<void(unsigned int, const ElementStiffness &)> &visit)
        const override
      {
        tets.for_each_tet([&](unsigned int t, unsigned int p, std::size_t c)
                          { visit(t, element_stiffness(tets.part(p), c, x)); });
      }

      void
      for_each_element_stiffness_of(
        const ParticleSystem &,
        const double                                                      *x,
        const std::vector<unsigned int>                                   &list,
        const std::function<void(unsigned int, const ElementStiffness &)> &visit)
        const override
      {
        tets.for_each_copy_of(list,
                              [&](unsigned int t, unsigned int p, std::size_t c)
                              { visit(t, element_stiffness(tets.part(p), c, x)); });
      }

    private:
      /// The tangent stiffness of copy @p c's term at @p x (the volume term, or the
      /// shear term below the lattice's Poisson ratio).
      ElementStiffness
      element_stiffness(const PartitionedTets::Part &part,
                        const std::size_t            c,
                        const double                *x) const
      {
        return parameters.volume_modulus > 0 ? volume_term_stiffness(part, c, x)
                                             : shear_term_stiffness(part, c, x);
      }

      /// The energy of copy @p c's term at @p x.
      double
      element_energy(const PartitionedTets::Part &part,
                     const std::size_t            c,
                     const double                *x) const
      {
        const double youngs = part.youngs_modulus[c];
        const double v0     = part.rest_volume[c];
        double       energy = 0;
        if (parameters.volume_modulus > 0)
        {
          double       g[4][3];
          const double change = volume_gradient(x + 3 * part.vertex[0][c],
                                                x + 3 * part.vertex[1][c],
                                                x + 3 * part.vertex[2][c],
                                                x + 3 * part.vertex[3][c],
                                                g)
                                  / v0
                                - 1;
          energy += 0.5 * parameters.volume_modulus * youngs * v0 * change * change;
        }
        if (parameters.shear_modulus > 0)
        {
          // |dev E|² = |dev(FᵀF)|² / 4.
          const Matrix3 F = part.deformation_gradient(c, x);
          energy += parameters.shear_modulus * youngs * v0 * 0.25
                    * squared_norm(symmetric_product_deviator(F, F));
        }
        return energy;
      }

      /// Adds the forces of range @p p's tetrahedra to its own particles.
      void
      add_element_forces(const ParticleSystem &system,
                         const unsigned int    p,
                         const double         *x,
                         const double         *v,
                         double               *f) const
      {
        if (parameters.volume_modulus > 0)
          add_volume_forces(system, p, x, v, f);
        if (parameters.shear_modulus > 0)
          add_shear_forces(system, p, x, v, f);
      }

      /// Adds the volume forces of range @p p's tetrahedra to its own particles.
      void
      add_volume_forces(const ParticleSystem &system,
                        const unsigned int    p,
                        const double         *x,
                        const double         *v,
                        double               *f) const
      {
        const PartitionedTets::Part &part = tets.part(p);
        const double                 beta = system.spring_damping;
        const unsigned int *__restrict v0 = part.vertex[0].data();
        const unsigned int *__restrict v1 = part.vertex[1].data();
        const unsigned int *__restrict v2 = part.vertex[2].data();
        const unsigned int *__restrict v3 = part.vertex[3].data();
        const double *__restrict rest     = part.rest_volume.data();
        const double *__restrict youngs   = part.youngs_modulus.data();
        const double modulus              = parameters.volume_modulus;
        for (std::size_t c = 0; c < part.size(); ++c)
        {
          const unsigned int vertex[4] = {3 * v0[c], 3 * v1[c], 3 * v2[c], 3 * v3[c]};
          double             g[4][3];
          const double       volume = volume_gradient(
            x + vertex[0], x + vertex[1], x + vertex[2], x + vertex[3], g);
          // -∂E/∂V, E = ½ κ V0 (V/V0 - 1)², and the damping -β κ/V0 dV/dt.
          const double kappa    = modulus * youngs[c];
          double       pressure = -kappa * (volume / rest[c] - 1);
          if (beta > 0)
          {
            double rate = 0;
            for (unsigned int i = 0; i < 4; ++i)
              for (unsigned int d = 0; d < 3; ++d)
                rate += g[i][d] * v[vertex[i] + d];
            pressure -= beta * kappa / rest[c] * rate;
          }
          const unsigned char owned = part.owned[c];
          for (unsigned int i = 0; i < 4; ++i)
            if (owned & (1u << i))
              for (unsigned int d = 0; d < 3; ++d)
                f[vertex[i] + d] += pressure * g[i][d];
        }
      }

      /**
       * Adds the shear forces of range @p p's tetrahedra to its own particles: the
       * stress P = F S with S = 2 μ_d dev E, and with β > 0 the damping stress
       * β F 2 μ_d dev(sym(Fᵀ Ḟ)).
       */
      void
      add_shear_forces(const ParticleSystem &system,
                       const unsigned int    p,
                       const double         *x,
                       const double         *v,
                       double               *f) const
      {
        const PartitionedTets::Part &part = tets.part(p);
        const double                 beta = system.spring_damping;
        for (std::size_t c = 0; c < part.size(); ++c)
        {
          const double  two_mu = 2 * parameters.shear_modulus * part.youngs_modulus[c];
          const Matrix3 F      = part.deformation_gradient(c, x);
          // S / 2μ_d = dev E = ½ dev(FᵀF), plus β dev(sym(Fᵀ Ḟ)).
          Matrix3 S = symmetric_product_deviator(F, F);
          for (double &entry : S)
            entry *= 0.5;
          if (beta > 0)
          {
            const Matrix3 rate =
              symmetric_product_deviator(F, part.deformation_gradient(c, v));
            for (unsigned int k = 0; k < 9; ++k)
              S[k] += beta * rate[k];
          }
          for (double &entry : S)
            entry *= two_mu;
          part.add_owned_nodal_forces(c, first_piola(F, S), f);
        }
      }

      /**
       * The tangent stiffness of copy @p c's volume term at @p x:
       * (κ/V0) ∇V ∇Vᵀ + κ (V/V0 - 1) ∇²V.
       */
      ElementStiffness
      volume_term_stiffness(const PartitionedTets::Part &part,
                            const std::size_t            c,
                            const double                *x) const
      {
        const double  k = parameters.volume_modulus * part.youngs_modulus[c];
        const double *y[4];
        for (unsigned int i = 0; i < 4; ++i)
          y[i] = x + 3 * part.vertex[i][c];
        double           g[4][3];
        const double     volume = volume_gradient(y[0], y[1], y[2], y[3], g);
        const double     v0     = part.rest_volume[c];
        ElementStiffness K{};
        for (unsigned int i = 0; i < 12; ++i)
          for (unsigned int j = 0; j < 12; ++j)
            K[12 * i + j] = k / v0 * g[i / 3][i % 3] * g[j / 3][j % 3];
        // ∂²V/∂x_i∂x_j = [x_l - x_m]×/6 for (i, j, l, m) an even permutation of
        // (0, 1, 2, 3) (V is trilinear and alternating in the vertices).
        const double                  scale           = k * (volume / v0 - 1) / 6.0;
        static constexpr unsigned int others[4][4][2] = {
          {{0, 0}, {2, 3}, {3, 1}, {1, 2}},
          {{3, 2}, {0, 0}, {0, 3}, {2, 0}},
          {{1, 3}, {3, 0}, {0, 0}, {0, 1}},
          {{2, 1}, {0, 2}, {1, 0}, {0, 0}}};
        for (unsigned int i = 0; i < 4; ++i)
          for (unsigned int j = 0; j < 4; ++j)
            if (i != j)
            {
              const unsigned int l = others[i][j][0], m = others[i][j][1];
              const double       a[3] = {y[l][0] - y[m][0],
                                         y[l][1] - y[m][1],
                                         y[l][2] - y[m][2]};
              // [a]× as rows.
              const double cross[3][3] = {{0, -a[2], a[1]},
                                          {a[2], 0, -a[0]},
                                          {-a[1], a[0], 0}};
              for (unsigned int r = 0; r < 3; ++r)
                for (unsigned int s = 0; s < 3; ++s)
                  K[12 * (3 * i + r) + 3 * j + s] += scale * cross[r][s];
            }
        return K;
      }

      /**
       * The tangent stiffness of copy @p c's shear term at @p x, column by column:
       * moving local vertex j along axis d changes F by dF = e_d ⊗ ∇N_j, the stress by
       * dP = dF S + F 2 μ_d dev(sym(Fᵀ dF)), and the forces by the nodal forces of dP.
       */
      ElementStiffness
      shear_term_stiffness(const PartitionedTets::Part &part,
                           const std::size_t            c,
                           const double                *x) const
      {
        const double  two_mu = 2 * parameters.shear_modulus * part.youngs_modulus[c];
        const Matrix3 F      = part.deformation_gradient(c, x);
        Matrix3       S      = symmetric_product_deviator(F, F);
        for (double &entry : S)
          entry *= 0.5 * two_mu;
        // ∇N_j: row j - 1 of D_m⁻¹ for j = 1..3, minus their sum for j = 0.
        double gradient[4][3] = {};
        for (unsigned int j = 1; j < 4; ++j)
          for (unsigned int k = 0; k < 3; ++k)
          {
            gradient[j][k] = part.rest_inverse[3 * (j - 1) + k][c];
            gradient[0][k] -= gradient[j][k];
          }
        ElementStiffness K{};
        for (unsigned int j = 0; j < 4; ++j)
          for (unsigned int d = 0; d < 3; ++d)
          {
            Matrix3 dF{};
            for (unsigned int k = 0; k < 3; ++k)
              dF[3 * d + k] = gradient[j][k];
            Matrix3 dS = symmetric_product_deviator(F, dF);
            for (double &entry : dS)
              entry *= two_mu;
            Matrix3       dP  = first_piola(dF, S);
            const Matrix3 FdS = first_piola(F, dS);
            for (unsigned int k = 0; k < 9; ++k)
              dP[k] += FdS[k];
            double force[4][3];
            part.nodal_forces(c, dP, force);
            for (unsigned int i = 0; i < 4; ++i)
              for (unsigned int r = 0; r < 3; ++r)
                K[12 * (3 * i + r) + 3 * j + d] = -force[i][r];
          }
        return K;
      }

    public:
      /// The springs' partition and the copies of the tetrahedra.
      void
      serialize(Archive &archive) override
      {
        LinearSprings::serialize(archive);
        archive &tets;
      }

    private:
      double                 lattice_nu = 0.25;
      VolumeSpringParameters parameters;
      PartitionedTets        tets;
      /// The first particle of every range before a local change (scratch).
      std::vector<unsigned int> range_starts;
    };
  } // namespace

  LACERTA_REGISTER_FORCE_MODEL(
    VolumeSprings,
    "volume springs",
    "The paper's springs scaled to the moduli of 'Material/Poisson ratio' plus a "
    "volume (or, below the lattice's own ratio, a shear) energy per tetrahedron that "
    "supplies the rest of the bulk (shear) modulus (doc/physics.md): reproduces the "
    "Poisson ratio from 0 to nearly incompressible.");
} // namespace lacerta::physics
