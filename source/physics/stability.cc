#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lacerta::physics
{
  namespace
  {
    /// Largest eigenvalue of a symmetric 3x3 matrix (trigonometric closed form).
    double
    largest_eigenvalue(const std::array<double, 6> &m) // xx, yy, zz, xy, xz, yz
    {
      const double p1 = m[3] * m[3] + m[4] * m[4] + m[5] * m[5];
      const double q  = (m[0] + m[1] + m[2]) / 3.0;
      if (p1 <= 1e-30 * (q * q + 1e-300))
        return std::max({m[0], m[1], m[2]});
      const double a = m[0] - q, b = m[1] - q, c = m[2] - q;
      const double p = std::sqrt((a * a + b * b + c * c + 2 * p1) / 6.0);
      // det((M - qI)/p) / 2
      const double det = a * (b * c - m[5] * m[5]) - m[3] * (m[3] * c - m[5] * m[4])
                         + m[4] * (m[3] * m[5] - b * m[4]);
      const double r = std::clamp(det / (2 * p * p * p), -1.0, 1.0);
      return q + 2 * p * std::cos(std::acos(r) / 3.0);
    }


    std::string
    describe_particle(const ParticleSystem &system, const unsigned int i)
    {
      std::ostringstream s;
      s.precision(6);
      const auto &x = system.rest_position();
      s << "particle " << i << " (rest position " << x[3 * i] << ", " << x[3 * i + 1]
        << ", " << x[3 * i + 2] << ")";
      return s.str();
    }


    /// Energies far below a spring stretched to twice its length are noise.
    double
    noise_energy(const ParticleSystem &system)
    {
      double spring_energy = 0;
      for (std::size_t s = 0; s < system.springs.size(); ++s)
        spring_energy += system.springs.stiffness[s] * system.springs.rest_length[s]
                         * system.springs.rest_length[s];
      return 1e-12 * spring_energy;
    }
  } // namespace


  namespace
  {
    /// Adds the symmetric 3x3 block @p b (xx, yy, zz, xy, xz, yz) to @p sum.
    void
    add_block(std::array<double, 6> &sum, const std::array<double, 6> &b)
    {
      for (unsigned int c = 0; c < 6; ++c)
        sum[c] += b[c];
    }


    /**
     * Adds the terms of the force model's per-tetrahedron stiffness (if it has any) to
     * the diagonal @p blocks and to the @p pair_norm of every spring (mesh edge): the
     * diagonal blocks of each element stiffness, and the spectral norm of each
     * off-diagonal block to the spring of its edge.
     */
    void
    add_element_terms(const ParticleSystem               &system,
                      const double                       *x,
                      std::vector<std::array<double, 6>> &blocks,
                      std::vector<double>                &pair_norm)
    {
      system.force_model().for_each_element_stiffness(
        system,
        x,
        [&](const unsigned int t, const ForceModel::ElementStiffness &K)
        {
          const mesh::Tet &tet = system.mesh->tet(t);
          const auto       at =
            [&](unsigned int a, unsigned int r, unsigned int b, unsigned int c)
          { return K[12 * (3 * a + r) + 3 * b + c]; };
          for (unsigned int a = 0; a < 4; ++a)
            add_block(blocks[tet[a]],
                      {at(a, 0, a, 0),
                       at(a, 1, a, 1),
                       at(a, 2, a, 2),
                       0.5 * (at(a, 0, a, 1) + at(a, 1, a, 0)),
                       0.5 * (at(a, 0, a, 2) + at(a, 2, a, 0)),
                       0.5 * (at(a, 1, a, 2) + at(a, 2, a, 1))});
          for (unsigned int e = 0; e < 6; ++e)
          {
            const auto [a, b] = mesh::TetMesh::edge_vertices[e];
            // ||K_ab||² = λ_max(K_abᵀ K_ab).
            std::array<double, 6> gram{};
            const unsigned int    pairs[6][2] = {
                 {0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
            for (unsigned int g = 0; g < 6; ++g)
              for (unsigned int r = 0; r < 3; ++r)
                gram[g] += at(a, r, b, pairs[g][0]) * at(a, r, b, pairs[g][1]);
            pair_norm[system.mesh->tet_edges(t)[e]] +=
              std::sqrt(std::max(0.0, largest_eigenvalue(gram)));
          }
        });
    }
  } // namespace


  GershgorinTerms
  gershgorin_terms(const ParticleSystem &system, const double *x)
  {
    const unsigned int n       = system.n_particles();
    const SpringSet   &springs = system.springs;
    // A system without a force model yet (a bare spring network) is bounded by its
    // springs as they are.
    const double scale =
      system.has_force_model() ? system.force_model().spring_stiffness_scale() : 1.0;
    std::vector<std::array<double, 6>> blocks(n, std::array<double, 6>{});
    std::vector<double>                pair_norm(springs.size(), 0.0);
    GershgorinTerms                    terms;
    terms.diagonal.assign(n, 0.0);
    terms.coupling.assign(springs.size(), 0.0);
    terms.stiffest_spring.assign(n, 0);

    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      double             d[3]   = {x[3 * j] - x[3 * i],
                                   x[3 * j + 1] - x[3 * i + 1],
                                   x[3 * j + 2] - x[3 * i + 2]};
      const double       length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double &c : d)
        c /= length;
      const double k         = scale * springs.stiffness[s];
      const double geometric = k * (1.0 - springs.rest_length[s] / length);
      // K_e = (k - g) n nᵀ + g I, g the geometric stiffness.
      const std::array<double, 6> block = {(k - geometric) * d[0] * d[0] + geometric,
                                           (k - geometric) * d[1] * d[1] + geometric,
                                           (k - geometric) * d[2] * d[2] + geometric,
                                           (k - geometric) * d[0] * d[1],
                                           (k - geometric) * d[0] * d[2],
                                           (k - geometric) * d[1] * d[2]};
      pair_norm[s]                      = std::max(k, std::abs(geometric));
      add_block(blocks[i], block);
      add_block(blocks[j], block);
    }
    if (system.has_force_model())
      add_element_terms(system, x, blocks, pair_norm);

    std::vector<double> stiffest(n, 0.0);
    for (std::size_t s = 0; s < springs.size(); ++s)
    {
      const unsigned int i = springs.a[s], j = springs.b[s];
      if (system.free[i] > 0 && system.free[j] > 0)
        terms.coupling[s] = pair_norm[s];
      for (const unsigned int p : {i, j})
        if (pair_norm[s] > stiffest[p])
        {
          stiffest[p]              = pair_norm[s];
          terms.stiffest_spring[p] = s;
        }
    }
    for (unsigned int i = 0; i < n; ++i)
      terms.diagonal[i] = largest_eigenvalue(blocks[i]);
    return terms;
  }


  namespace
  {
    /// The squares of particle_frequency_bounds() from the system's Gershgorin
    /// @p terms.
    std::vector<double>
    squared_frequencies(const ParticleSystem &system, const GershgorinTerms &terms)
    {
      const unsigned int  n = system.n_particles();
      std::vector<double> off_diagonal(n, 0.0);
      for (std::size_t s = 0; s < system.springs.size(); ++s)
        if (terms.coupling[s] > 0)
        {
          const unsigned int i = system.springs.a[s], j = system.springs.b[s];
          const double c = terms.coupling[s] / std::sqrt(system.mass[i] * system.mass[j]);
          off_diagonal[i] += c;
          off_diagonal[j] += c;
        }
      std::vector<double> lambda(n, 0.0);
      for (unsigned int i = 0; i < n; ++i)
        if (system.free[i] > 0 && system.mass[i] > 0)
          lambda[i] = terms.diagonal[i] / system.mass[i] + off_diagonal[i];
      return lambda;
    }
  } // namespace


  std::vector<double>
  particle_frequency_bounds(const ParticleSystem &system)
  {
    std::vector<double> omega =
      squared_frequencies(system, gershgorin_terms(system, system.position.data()));
    for (double &w : omega)
      w = std::sqrt(w);
    return omega;
  }


  FrequencyBound
  bound_highest_frequency(const ParticleSystem &system)
  {
    const GershgorinTerms     terms  = gershgorin_terms(system, system.position.data());
    const std::vector<double> lambda = squared_frequencies(system, terms);
    FrequencyBound            bound;
    double                    largest = 0;
    for (unsigned int i = 0; i < lambda.size(); ++i)
      if (lambda[i] > largest)
      {
        largest        = lambda[i];
        bound.particle = i;
        bound.spring   = terms.stiffest_spring[i];
      }
    bound.omega = std::sqrt(largest);
    return bound;
  }


  double
  multirate_evaluation_share(const ParticleSystem &system)
  {
    const std::vector<double> omega   = particle_frequency_bounds(system);
    const double              highest = *std::max_element(omega.begin(), omega.end());
    if (system.springs.size() == 0 || !(highest > 0))
      return 1;
    double evaluations = 0;
    for (std::size_t s = 0; s < system.springs.size(); ++s)
    {
      const double fastest =
        std::max(omega[system.springs.a[s]], omega[system.springs.b[s]]);
      // A spring steps at the single-rate step times the largest power of two that
      // keeps ω h below the bound at both its particles (ω h scales as 1/ω).
      double step = 1;
      // Ties (a regular mesh's boundary has particles at exactly half the frequency)
      // count as allowed whatever the rounding, so the share is the same on every
      // compiler.
      while (fastest > 0 && 2 * step * fastest <= highest * (1 + 1e-9) && step < 1024)
        step *= 2;
      if (fastest == 0)
        step = 1024;
      evaluations += 1 / step;
    }
    return evaluations / system.springs.size();
  }


  std::string
  describe_spring(const ParticleSystem &system, const unsigned int s)
  {
    const SpringSet   &springs = system.springs;
    const double      *x       = system.position.data();
    const unsigned int i = springs.a[s], j = springs.b[s];
    std::ostringstream text;
    text.precision(6);
    text << "spring " << s << " between " << describe_particle(system, i) << " and "
         << describe_particle(system, j) << ", stiffness " << springs.stiffness[s]
         << " N/m, rest length " << springs.rest_length[s] << " m, length "
         << std::hypot(x[3 * j] - x[3 * i],
                       x[3 * j + 1] - x[3 * i + 1],
                       x[3 * j + 2] - x[3 * i + 2])
         << " m";
    return text.str();
  }


  BlowUpMonitor::BlowUpMonitor(const ParticleSystem &system, const double tolerance)
      : tolerance(tolerance)
      , energy_scale(system.kinetic_energy() + system.elastic_energy())
      , energy_floor(noise_energy(system))
  {
    start_ledger(system);
  }


  void
  BlowUpMonitor::start_ledger(const ParticleSystem &system)
  {
    initial_energy =
      system.kinetic_energy() + system.elastic_energy() + system.body_force_energy();
    work              = 0;
    previous_position = system.position;
    load.assign(system.position.size(), 0.0);
    compute_load_forces(system);
    previous_load = load;
  }


  void
  BlowUpMonitor::compute_load_forces(const ParticleSystem &system)
  {
    // Prescribed particles push with the reaction to the spring forces on them;
    // free particles receive the external forces.
    system.force_model().compute_spring_forces(system,
                                               system.position.data(),
                                               system.velocity.data(),
                                               load.data());
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
        load[3 * i + d] =
          system.free[i] > 0 ? system.external_force[3 * i + d] : -load[3 * i + d];
  }


  void
  BlowUpMonitor::check_finite(const ParticleSystem &system,
                              const unsigned int    step,
                              const double          time,
                              const std::string    &after) const
  {
    for (unsigned int i = 0; i < system.n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
        if (!std::isfinite(system.position[3 * i + d])
            || !std::isfinite(system.velocity[3 * i + d]))
          throw_error("The simulation blew up at step ",
                      step,
                      ", time ",
                      time,
                      " s",
                      after,
                      ": ",
                      describe_particle(system, i),
                      " has a position or velocity that is not a finite number. Reduce "
                      "'Time step' or raise 'Stability/Safety factor' margin.");
  }


  double
  BlowUpMonitor::check_energy(const ParticleSystem &system,
                              const unsigned int    step,
                              const double          time,
                              const std::string    &after) const
  {
    const double kinetic = system.kinetic_energy();
    const double elastic = system.elastic_energy();
    const double body    = system.body_force_energy();
    const double energy  = kinetic + elastic + body;
    const double excess  = energy - initial_energy - work;
    // The scale: the largest energy of the states already accepted, or the energy the
    // system may have now, not the energy under test.
    const double scale =
      std::max(energy_scale, std::abs(initial_energy) + std::abs(work));
    // Written so that a NaN energy (an infinite spring force) also stops the run.
    if (!(excess <= tolerance * scale + energy_floor || excess <= energy_floor))
    {
      unsigned int fastest = 0;
      double       speed   = 0;
      for (unsigned int i = 0; i < system.n_particles(); ++i)
      {
        const double *v = &system.velocity[3 * i];
        const double  s = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (s > speed)
        {
          speed   = s;
          fastest = i;
        }
      }
      throw_error("The simulation blew up at step ",
                  step,
                  ", time ",
                  time,
                  " s",
                  after,
                  ": the mechanical energy (",
                  energy,
                  " J) exceeds the initial energy plus the work of the loads (",
                  initial_energy + work,
                  " J) by ",
                  excess,
                  " J, more than 'Energy growth tolerance' allows. The fastest is ",
                  describe_particle(system, fastest),
                  " at ",
                  speed,
                  " m/s. Reduce 'Time step' or add damping.");
    }
    return kinetic + elastic + std::abs(body);
  }


  void
  BlowUpMonitor::check(const ParticleSystem &system,
                       const unsigned int    step,
                       const double          time)
  {
    check_finite(system, step, time, "");

    compute_load_forces(system);
    const std::vector<double> &x = system.position;
    for (std::size_t c = 0; c < x.size(); ++c)
      work += 0.5 * (previous_load[c] + load[c]) * (x[c] - previous_position[c]);
    previous_position = x;
    previous_load     = load;

    // The scale is the largest energy of the states already accepted: had it included
    // the state under test, the excess could never exceed it with a tolerance of 1
    // (the default), and a run reached 1e127 J unstopped.
    energy_scale =
      std::max(energy_scale, check_energy(system, step, time, "") + std::abs(work));
  }


  void
  BlowUpMonitor::restart(const ParticleSystem &system,
                         const unsigned int    step,
                         const double          time,
                         const std::string    &cause)
  {
    const std::string after = " (right after " + cause + ")";
    check_finite(system, step, time, after);
    energy_floor = std::max(energy_floor, noise_energy(system));
    energy_scale = std::max(energy_scale, check_energy(system, step, time, after));
    // The ledger starts again from the new state: the work of the loads since the
    // last check is lost with the old particles, and carrying an excess over many
    // changes (a stroke changes the system at every step) accumulated that loss into
    // false alarms.
    start_ledger(system);
  }
} // namespace lacerta::physics
