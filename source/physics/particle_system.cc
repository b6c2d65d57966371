#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>

#include <chrono>

namespace lacerta::physics
{
  ParticleSystem::ParticleSystem(const std::vector<double> &rest_positions)
      : position(rest_positions)
      , velocity(rest_positions.size(), 0.0)
      , mass(rest_positions.size() / 3, 0.0)
      , mass_shift(rest_positions.size() / 3, 0.0)
      , free(rest_positions.size() / 3, 1.0)
      , external_force(rest_positions.size(), 0.0)
      , rest(rest_positions)
  {
  }


  ParticleSystem::~ParticleSystem() = default;


  void
  ParticleSystem::set_force_model(std::unique_ptr<ForceModel> model,
                                  const unsigned int          n_threads)
  {
    forces        = std::move(model);
    force_threads = n_threads;
    forces->initialize(*this, n_threads);
  }


  void
  ParticleSystem::reset(const std::vector<double> &rest_positions)
  {
    position = rest_positions;
    velocity.assign(rest_positions.size(), 0.0);
    mass.assign(rest_positions.size() / 3, 0.0);
    mass_shift.assign(rest_positions.size() / 3, 0.0);
    free.assign(rest_positions.size() / 3, 1.0);
    external_force.assign(rest_positions.size(), 0.0);
    springs.clear();
    // Body forces add their acceleration when initialised again on the new particles.
    body_acceleration = {{0, 0, 0}};
    rest              = rest_positions;
    changed.clear();
    listed.assign(n_particles(), 0);
    all_changed = true;
  }


  void
  ParticleSystem::reserve(const unsigned int n)
  {
    for (std::vector<double> *v : {&position, &velocity, &external_force, &rest})
      v->reserve(3 * std::size_t(n));
    mass.reserve(n);
    mass_shift.reserve(n);
    free.reserve(n);
  }


  void
  ParticleSystem::update_force_model(const unsigned int n_threads)
  {
    force_threads = n_threads;
    refresh_force_model();
  }


  void
  ParticleSystem::refresh_force_model()
  {
    forces->initialize(*this, force_threads);
  }


  void
  ParticleSystem::springs_changed(const std::vector<unsigned int> &changed_springs)
  {
    // Springs removed from the end since are listed too: they have no ends now.
    for (const unsigned int s : changed_springs)
      if (s < springs.size())
      {
        note_changed(springs.a[s]);
        note_changed(springs.b[s]);
      }
    forces->springs_changed(*this, changed_springs);
  }


  void
  ParticleSystem::masses_changed(const std::vector<unsigned int> &particles)
  {
    for (const unsigned int i : particles)
      note_changed(i);
    forces->masses_changed(*this, particles);
  }


  unsigned int
  ParticleSystem::add_particle(const std::array<double, 3> &rest_x,
                               const std::array<double, 3> &x,
                               const std::array<double, 3> &v)
  {
    for (unsigned int d = 0; d < 3; ++d)
    {
      position.push_back(x[d]);
      velocity.push_back(v[d]);
      external_force.push_back(0.0);
      rest.push_back(rest_x[d]);
    }
    mass.push_back(0.0);
    mass_shift.push_back(0.0);
    free.push_back(1.0);
    note_changed(n_particles() - 1);
    return n_particles() - 1;
  }


  void
  ParticleSystem::remove_particles(const std::vector<std::array<unsigned int, 2>> &moves,
                                   const unsigned int n_removed)
  {
    const std::size_t n = n_particles() - std::size_t(n_removed);
    for_each_particle_array(
      [&](std::vector<double> &values, const unsigned int width)
      {
        for (const auto &[to, from] : moves)
          for (unsigned int d = 0; d < width; ++d)
            values[width * std::size_t(to) + d] = values[width * std::size_t(from) + d];
        values.resize(width * n);
      });
    if (all_changed)
      return;
    // A slot that was listed and refilled holds a moved particle, which is listed
    // anyway; slots past the end go.
    std::size_t kept = 0;
    for (const unsigned int i : changed)
      if (i < n)
        changed[kept++] = i;
      else
        listed[i] = 0;
    changed.resize(kept);
    listed.resize(n, 0);
    for (const auto &move : moves)
      if (move[0] < n)
        note_changed(move[0]);
  }


  void
  ParticleSystem::renumber_particles(const std::vector<unsigned int> &new_index)
  {
    if (new_index.size() != n_particles())
      throw_error("ParticleSystem::renumber_particles: ",
                  new_index.size(),
                  " new indices for ",
                  n_particles(),
                  " particles.");
    std::vector<double> moved;
    for_each_particle_array(
      [&](std::vector<double> &values, const unsigned int width)
      {
        moved.resize(values.size());
        for (std::size_t i = 0; i < new_index.size(); ++i)
          for (unsigned int d = 0; d < width; ++d)
            moved[width * std::size_t(new_index[i]) + d] = values[width * i + d];
        values.swap(moved);
      });
    changed.clear();
    listed.assign(n_particles(), 0);
    all_changed = true;
  }


  template <typename Function>
  void
  ParticleSystem::for_each_particle_array(const Function &f)
  {
    for (std::vector<double> *v : {&position, &velocity, &external_force, &rest})
      f(*v, 3u);
    for (std::vector<double> *v : {&mass, &mass_shift, &free})
      f(*v, 1u);
  }


  void
  ParticleSystem::note_changed(const unsigned int i)
  {
    if (all_changed)
      return;
    if (listed.size() <= i)
      listed.resize(n_particles(), 0);
    if (listed[i] == 0)
    {
      listed[i] = 1;
      changed.push_back(i);
    }
  }


  void
  ParticleSystem::clear_changes()
  {
    for (const unsigned int i : changed)
      listed[i] = 0;
    changed.clear();
    all_changed = false;
  }


  void
  ParticleSystem::compute_acceleration(const double *x, const double *v, double *a) const
  {
    compute_acceleration(x, v, a, [](unsigned int, unsigned int) {});
  }


  void
  ParticleSystem::compute_acceleration(const double     *x,
                                       const double     *v,
                                       double           *a,
                                       const RangeUpdate update) const
  {
    const auto start = std::chrono::steady_clock::now();
    forces->compute_acceleration(*this, x, v, a, update);
    force_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }


  void
  ParticleSystem::enforce_constraints(const double t, double *x, double *v) const
  {
    prepare_constraints(t);
    prescribe_constraints(x, v, 0, n_particles());
  }


  double
  ParticleSystem::kinetic_energy() const
  {
    double sum = 0;
    for (unsigned int i = 0; i < n_particles(); ++i)
      sum +=
        mass[i]
        * (velocity[3 * i] * velocity[3 * i] + velocity[3 * i + 1] * velocity[3 * i + 1]
           + velocity[3 * i + 2] * velocity[3 * i + 2]);
    return 0.5 * sum;
  }


  double
  ParticleSystem::body_force_energy() const
  {
    double sum = 0;
    for (unsigned int i = 0; i < n_particles(); ++i)
      for (unsigned int d = 0; d < 3; ++d)
        sum -= mass[i] * body_acceleration[d] * (position[3 * i + d] - rest[3 * i + d]);
    return sum;
  }


  double
  ParticleSystem::elastic_energy() const
  {
    return forces->elastic_energy(*this, position.data());
  }


  void
  SpringSet::serialize(Archive &archive)
  {
    archive(a, b, stiffness, rest_length);
  }


  void
  ParticleSystem::serialize(Archive &archive)
  {
    archive.section("particle system");
    archive(position, velocity, mass, mass_shift, free, external_force, springs);
    archive(body_acceleration, mass_damping, spring_damping, poisson_ratio, rest);
    archive(cell_stiffness);
    archive(force_threads, changed, listed, all_changed);
    archive.section("force model");
    forces->serialize(archive);
  }
} // namespace lacerta::physics
