// Force model `volume springs`: the paper's springs, rescaled, plus a volume term per
// tetrahedron, so that the pair reproduces Young's modulus and the Poisson ratio.

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/linear_springs.h>
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


    /**
     * The paper's springs with their stiffness scaled by α(ν), plus the volume energy
     * ½ κ V0 (V/V0 - 1)² of every tetrahedron, κ = κ̂(ν) E at its centroid
     * (doc/physics.md derives α and κ̂). The springs are those of LinearSprings, on
     * the same particle ranges; every range also evaluates the tetrahedra that touch
     * it (PartitionedTets) and adds their forces to its own vertices only.
     *
     * After a cut or a tear the springs are updated locally (LinearSprings) but the
     * tetrahedra are copied again from the mesh: O(tetrahedra) per change.
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
          "springs' scale and the volume term are derived (doc/physics.md): 0.25 for "
          "an isotropic lattice (the orientation average), 0.117 measured on box "
          "meshes (hexahedra split into five tetrahedra). Asked ratios below it make "
          "the volume term negative.");
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
        copy_tets(system);
      }

      void
      springs_changed(const ParticleSystem            &system,
                      const std::vector<unsigned int> &changed) override
      {
        LinearSprings::springs_changed(system, changed);
        copy_tets(system);
      }

      void
      compute_acceleration(const ParticleSystem &system,
                           const double         *x,
                           const double         *v,
                           double               *a) const override
      {
        ranges.for_each_part(
          [&](const unsigned int p)
          {
            spring_forces_of_part(system, p, x, v, a);
            add_volume_forces(system, p, x, v, a);
            ranges.finish_accelerations(system, p, v, a);
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
            add_volume_forces(system, p, x, v, f);
          });
      }

      double
      elastic_energy(const ParticleSystem &system, const double *x) const override
      {
        double energy = LinearSprings::elastic_energy(system, x);
        for (unsigned int p = 0; p < ranges.n_parts(); ++p)
        {
          const PartitionedTets::Part &part = tets.part(p);
          for (std::size_t c = 0; c < part.size(); ++c)
            // Each tetrahedron once: in the range that owns its local vertex 0.
            if (part.owned[c] & 1u)
            {
              double       g[4][3];
              const double volume = volume_gradient(x + 3 * part.vertex[0][c],
                                                    x + 3 * part.vertex[1][c],
                                                    x + 3 * part.vertex[2][c],
                                                    x + 3 * part.vertex[3][c],
                                                    g);
              const double change = volume / part.rest_volume[c] - 1;
              energy += 0.5 * kappa[p][c] * part.rest_volume[c] * change * change;
            }
        }
        return energy;
      }

      void
      for_each_element_stiffness(
        const ParticleSystem &,
        const double                                                      *x,
        const std::function<void(unsigned int, const ElementStiffness &)> &visit)
        const override
      {
        for (unsigned int p = 0; p < ranges.n_parts(); ++p)
        {
          const PartitionedTets::Part &part = tets.part(p);
          for (std::size_t c = 0; c < part.size(); ++c)
            if (part.owned[c] & 1u)
              visit(part.tet[c], volume_term_stiffness(part, c, kappa[p][c], x));
        }
      }

    private:
      /// Copies the tetrahedra into the ranges, with κ = κ̂ E of each copy.
      void
      copy_tets(const ParticleSystem &system)
      {
        tets.build(system, ranges);
        kappa.assign(ranges.n_parts(), {});
        for (unsigned int p = 0; p < ranges.n_parts(); ++p)
          for (const double youngs : tets.part(p).youngs_modulus)
            kappa[p].push_back(parameters.volume_modulus * youngs);
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
        const double *__restrict k        = kappa[p].data();
        for (std::size_t c = 0; c < part.size(); ++c)
        {
          const unsigned int vertex[4] = {3 * v0[c], 3 * v1[c], 3 * v2[c], 3 * v3[c]};
          double             g[4][3];
          const double       volume = volume_gradient(
            x + vertex[0], x + vertex[1], x + vertex[2], x + vertex[3], g);
          // -∂E/∂V, E = ½ κ V0 (V/V0 - 1)², and the damping -β κ/V0 dV/dt.
          double pressure = -k[c] * (volume / rest[c] - 1);
          if (beta > 0)
          {
            double rate = 0;
            for (unsigned int i = 0; i < 4; ++i)
              for (unsigned int d = 0; d < 3; ++d)
                rate += g[i][d] * v[vertex[i] + d];
            pressure -= beta * k[c] / rest[c] * rate;
          }
          const unsigned char owned = part.owned[c];
          for (unsigned int i = 0; i < 4; ++i)
            if (owned & (1u << i))
              for (unsigned int d = 0; d < 3; ++d)
                f[vertex[i] + d] += pressure * g[i][d];
        }
      }

      /**
       * The tangent stiffness of copy @p c's volume term at @p x:
       * (κ/V0) ∇V ∇Vᵀ + κ (V/V0 - 1) ∇²V. With κ < 0 the first part is negative
       * semidefinite and is left out: it can only lower the highest eigenvalue.
       */
      static ElementStiffness
      volume_term_stiffness(const PartitionedTets::Part &part,
                            const std::size_t            c,
                            const double                 k,
                            const double                *x)
      {
        const double *y[4];
        for (unsigned int i = 0; i < 4; ++i)
          y[i] = x + 3 * part.vertex[i][c];
        double           g[4][3];
        const double     volume = volume_gradient(y[0], y[1], y[2], y[3], g);
        const double     v0     = part.rest_volume[c];
        ElementStiffness K{};
        if (k > 0)
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

      double                 lattice_nu = 0.25;
      VolumeSpringParameters parameters;
      PartitionedTets        tets;
      /// κ of every copy (Pa), per range.
      std::vector<std::vector<double>> kappa;
    };
  } // namespace

  LACERTA_REGISTER_FORCE_MODEL(
    VolumeSprings,
    "volume springs",
    "The paper's springs scaled to the shear modulus of 'Material/Poisson ratio' plus "
    "a volume energy per tetrahedron that supplies the rest of the bulk modulus "
    "(doc/physics.md): reproduces the Poisson ratio, nearly incompressible included.");
} // namespace lacerta::physics
