#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/invariants.h>
#include <lacerta/cut/lacerator.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability.h>
#include <lacerta/physics/topology_update.h>
#include <lacerta/scene/region.h>
#include <lacerta/scene/scene.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>

namespace lacerta::scene
{
  void
  Scene::declare_parameters(dealii::ParameterHandler       &prm,
                            const std::vector<std::string> &constraint_names)
  {
    mesh::MeshSource::declare_parameters(prm);
    Material::declare_parameters(prm);
    physics::ForceModel::declare_parameters(prm);
    BodyForce::declare_parameters(prm);
    Constraint::declare_parameters(prm, constraint_names);
    mt::Multiresolution::declare_parameters(prm);
    cut::Tool::declare_parameters(prm);
    cut::Cutter::declare_parameters(prm);
    cut::Lacerator::declare_parameters(prm);
  }


  Scene::Scene(dealii::ParameterHandler &prm, const unsigned int n_threads)
      : n_threads(n_threads)
  {
    mesh = mesh::MeshSource::create(prm)->create_mesh();
    mesh.sort_spatially();
    material.parse_parameters(prm);
    integral_of_density = physics::integrate_over_mesh(mesh, material.density());
    body_forces         = BodyForce::create(prm);
    for (auto &force : body_forces)
      has_varying_loads |= force->varies();
    constraints = Constraint::create(prm, mesh);
    for (auto &constraint : constraints)
      has_varying_loads |= !constraint->prescribes_motion();
    tool = cut::Tool::create(prm);
    if (mt::Multiresolution::enabled(prm))
    {
      // Constrained particles stay in every level of detail: the scene holds them.
      std::vector<unsigned int> locked;
      for (const auto &constraint : constraints)
        locked.insert(locked.end(),
                      constraint->particles.begin(),
                      constraint->particles.end());
      std::sort(locked.begin(), locked.end());
      locked.erase(std::unique(locked.begin(), locked.end()), locked.end());
      const std::optional<cut::Blade> blade =
        tool ? std::optional<cut::Blade>(tool->blade(0.0)) : std::nullopt;
      multiresolution = std::make_unique<mt::Multiresolution>(prm,
                                                              mesh,
                                                              locked,
                                                              blade ? &*blade : nullptr);
      multiresolution->set_stiffness_rule(
        [this](const std::array<mesh::Point3, 4> &x)
        {
          const double E = material.youngs_modulus().value(
            dealii::Point<3>((x[0][0] + x[1][0] + x[2][0] + x[3][0]) / 4,
                             (x[0][1] + x[1][1] + x[2][1] + x[3][1]) / 4,
                             (x[0][2] + x[1][2] + x[2][2] + x[3][2]) / 4));
          return material.fitted_springs
                   ? physics::fitted_edge_stiffnesses(x, E, material.poisson_ratio)
                   : physics::paper_edge_stiffnesses(x, E);
        });
    }
    system = std::make_unique<physics::ParticleSystem>(std::vector<double>());
    if (multiresolution)
    {
      // The full mesh's stability, to set the level of detail's against (issue 17):
      // assembled once, then replaced by the level of detail.
      assemble(mesh, 0.0);
      system->set_force_model(physics::ForceModel::create(prm), n_threads);
      full_mesh_stability.omega = physics::bound_highest_frequency(*system).omega;
      full_mesh_stability.multirate_share = physics::multirate_evaluation_share(*system);
      assemble(active_mesh(), 0.0);
      system->update_force_model(n_threads);
    }
    else
    {
      assemble(active_mesh(), 0.0);
      system->set_force_model(physics::ForceModel::create(prm), n_threads);
    }
    initial_volume    = mesh.total_volume();
    cutter_parameters = cut::Cutter::parse_parameters(prm);
    if (tool)
    {
      // On a multiresolution model the cutter cuts the level of detail at once; its
      // records update the MT once the stroke is over (doc/mt-cutting.md).
      cutter = std::make_unique<cut::Cutter>(mesh_to_cut(),
                                             *system,
                                             material.density(),
                                             material.youngs_modulus(),
                                             integral_of_density,
                                             cutter_parameters,
                                             tool->blade(0.0));
      if (multiresolution)
        cutter->set_recorder(&cut_records);
    }
    if (cut::Lacerator::enabled(prm))
    {
      // On a multiresolution model a tear cuts the level of detail like the scalpel
      // and its records update the MT after it (doc/lacerations.md).
      lacerator = std::make_unique<cut::Lacerator>(mesh_to_cut(),
                                                   *system,
                                                   material.density(),
                                                   material.youngs_modulus(),
                                                   material.maximum_elongation(),
                                                   integral_of_density,
                                                   cutter_parameters,
                                                   cut::Lacerator::parse_parameters(prm));
      if (multiresolution)
        lacerator->set_recorder(&cut_records);
    }
    system_changed.connect([this](const SystemChange &change) { follow_change(change); });
  }


  void
  Scene::follow_change(const SystemChange &change)
  {
    // A change of level has made the constraints follow its renumbering already.
    if (change.cause != SystemChange::Cause::level_of_detail)
      for (auto &constraint : constraints)
        constraint->follow_copies(change.copied_particles(), *system);
    if (change.cause == SystemChange::Cause::cut && lacerator)
      lacerator->mesh_changed();
    if (change.cause != SystemChange::Cause::cut)
      restart_cutter();
    if (change.cause == SystemChange::Cause::level_of_detail && lacerator)
    {
      // Particles the MT's cuts created: among them the lacerator finds those of its
      // tears again.
      const std::size_t first = multiresolution->multi_triangulation().first_cut_vertex();
      const std::vector<std::uint32_t> &ids = multiresolution->active_vertices();
      std::vector<std::uint8_t>         created(ids.size());
      for (std::size_t i = 0; i < ids.size(); ++i)
        created[i] = ids[i] >= first;
      lacerator->particles_replaced(created);
    }
  }


  cut::CutStepStatistics
  Scene::cut(const cut::Blade &blade, const double t)
  {
    if (!cutter)
      throw_error("Scene::cut(): the scene has no tool.");
    cut::CutStepStatistics statistics = cutter->move_blade(blade);
    if (statistics.changed)
    {
      SystemChange change{SystemChange::Cause::cut, t};
      change.cut = &statistics;
      system_changed(change);
    }
    return statistics;
  }


  cut::LacerationStatistics
  Scene::lacerate(const double t)
  {
    if (!lacerator)
      throw_error("Scene::lacerate(): the scene has no lacerations.");
    cut::LacerationStatistics statistics = lacerator->check();
    if (statistics.changed)
    {
      SystemChange change{SystemChange::Cause::laceration, t};
      change.tear = &statistics;
      system_changed(change);
    }
    return statistics;
  }


  void
  Scene::restart_cutter()
  {
    if (!cutter)
      return;
    const cut::Blade blade = cutter->blade();
    cutter.reset();
    cutter = std::make_unique<cut::Cutter>(mesh_to_cut(),
                                           *system,
                                           material.density(),
                                           material.youngs_modulus(),
                                           integral_of_density,
                                           cutter_parameters,
                                           blade);
    if (multiresolution)
      cutter->set_recorder(&cut_records);
  }


  mesh::TetMesh &
  Scene::mesh_to_cut()
  {
    return multiresolution ? multiresolution->mesh_to_cut() : mesh;
  }


  const std::vector<unsigned int> &
  Scene::move_to_level_of_detail(const double t)
  {
    if (!level_update)
      level_update =
        std::make_unique<physics::TopologyUpdate>(multiresolution->mesh_to_cut(),
                                                  *system,
                                                  material.density(),
                                                  material.youngs_modulus(),
                                                  level_mass_scale);
    const double                     volume_before = level_update->volume_delta();
    const std::vector<unsigned int> &new_index =
      multiresolution->apply_change(*level_update, *system);
    level_of_detail_volume += level_update->volume_delta() - volume_before;
    for (auto &constraint : constraints)
      constraint->follow_renumbering(new_index, *system);
    system->enforce_constraints(t, system->position.data(), system->velocity.data());
    update_loads(t);
    return new_index;
  }


  std::optional<MultiresolutionCut>
  Scene::update_multiresolution_after_cut(const double t)
  {
    // Tears are complete strokes: only a scalpel's stroke in progress makes it wait.
    if (!multiresolution || cut_records.empty()
        || (cutter && !cutter->active_tets().empty()))
      return std::nullopt;
    MultiresolutionCut result;
    result.update = multiresolution->apply_cut(cut_records);
    cut_records.clear();
    result.n_tets      = active_mesh().n_tets();
    result.n_particles = system->n_particles();
    result.pieces      = cut::count_components(active_mesh());
    result.time        = t;
    multi_triangulation_cut(result);
    return result;
  }


  const mesh::TetMesh &
  Scene::active_mesh() const
  {
    return multiresolution ? multiresolution->active_mesh() : mesh;
  }


  void
  Scene::assemble(const mesh::TetMesh &active, const double t)
  {
    std::vector<double> rest(3 * active.n_vertices());
    for (unsigned int v = 0; v < active.n_vertices(); ++v)
      for (unsigned int d = 0; d < 3; ++d)
        rest[3 * v + d] = active.vertex(v)[d];
    system->reset(rest);
    system->mass = physics::compute_masses(active, material.density());
    if (&active != &mesh)
    {
      level_of_detail_volume = active.total_volume();
      // A coarser boundary covers a slightly different volume; the total mass stays
      // the integral of the density over the object (Section 3.1).
      const double total = std::accumulate(system->mass.begin(), system->mass.end(), 0.0);
      level_mass_scale   = integral_of_density / total;
      for (double &m : system->mass)
        m *= level_mass_scale;
    }
    for (unsigned int i = 0; i < system->n_particles(); ++i)
      if (!(system->mass[i] > 0) || !std::isfinite(system->mass[i]))
        throw_error("Material/Density: particle ",
                    i,
                    " at (",
                    rest[3 * i],
                    ", ",
                    rest[3 * i + 1],
                    ", ",
                    rest[3 * i + 2],
                    ") gets mass ",
                    system->mass[i],
                    " kg; the density must be positive and finite on the object.");

    system->cell_stiffness.clear();
    if (&active != &mesh && multiresolution->has_coarse_stiffness())
    {
      system->cell_stiffness = multiresolution->active_cell_stiffnesses();
      system->springs        = physics::compute_springs(active, system->cell_stiffness);
    }
    else
      system->springs = material.fitted_springs
                          ? physics::compute_fitted_springs(active,
                                                            material.youngs_modulus(),
                                                            material.poisson_ratio)
                          : physics::compute_springs(active, material.youngs_modulus());
    for (std::size_t s = 0; s < system->springs.size(); ++s)
      if (!(system->springs.stiffness[s] > 0)
          || !std::isfinite(system->springs.stiffness[s]))
        throw_error("Material/Youngs modulus: the spring between particles ",
                    system->springs.a[s],
                    " and ",
                    system->springs.b[s],
                    " gets stiffness ",
                    system->springs.stiffness[s],
                    " N/m; Young's modulus must be positive and finite on the object.");
    system->mass_damping   = material.mass_damping;
    system->spring_damping = material.spring_damping;
    system->mesh           = &active;
    system->youngs_modulus = &material.youngs_modulus();
    system->poisson_ratio  = material.poisson_ratio;
    system->fitted_springs = material.fitted_springs;
    for (auto &force : body_forces)
      force->initialize(*system);
    for (auto &constraint : constraints)
      constraint->initialize(&active == &mesh ? constraint->particles
                                              : constraint->region->select(active),
                             *system);
    system->prepare_constraints = [this](const double time)
    {
      for (const auto &constraint : constraints)
        constraint->prepare(time, system->rest_position().data());
    };
    system->prescribe_constraints =
      [this](double *x, double *v, const unsigned int begin, const unsigned int end)
    {
      for (const auto &constraint : constraints)
        constraint->prescribe(system->rest_position().data(), x, v, begin, end);
    };
    system->enforce_constraints(t, system->position.data(), system->velocity.data());
    update_loads(t);
  }


  bool
  Scene::update_level_of_detail(const double       t,
                                const unsigned int step,
                                std::ostream      &out)
  {
    // While a cut waits for its MT update the level of detail is the cutter's mesh,
    // whose new particles the MT does not know yet: re-extraction waits for the update.
    if (!multiresolution || cut_pending())
      return false;
    if (!multiresolution->update(t, step, cutter ? &cutter->blade() : nullptr))
      return false;
    const std::vector<unsigned int> &new_index = move_to_level_of_detail(t);
    multiresolution->print_change(
      out, t, std::accumulate(system->mass.begin(), system->mass.end(), 0.0));
    SystemChange change{SystemChange::Cause::level_of_detail, t};
    change.particle_renumbering = &new_index;
    system_changed(change);
    return true;
  }


  Scene::~Scene() = default;


  void
  Scene::update_loads(const double t)
  {
    if (!has_varying_loads)
      return;
    std::fill(system->external_force.begin(), system->external_force.end(), 0.0);
    for (const auto &force : body_forces)
      if (force->varies())
        force->add_forces(t, *system);
    for (const auto &constraint : constraints)
      constraint->add_forces(t, *system);
  }


  void
  Scene::print_summary(std::ostream &out) const
  {
    const mesh::TetMesh &mesh    = active_mesh();
    const auto           lengths = mesh.edge_length_range();
    const auto          &k       = system->springs.stiffness;
    const double total = std::accumulate(system->mass.begin(), system->mass.end(), 0.0);
    out << "Mesh: " << mesh.n_tets() << " tetrahedra, " << mesh.n_vertices()
        << " particles, " << mesh.n_edges() << " springs, "
        << mesh.get_boundary_faces().size() << " boundary faces\n"
        << "Volume: " << mesh.total_volume() << " m^3; edge length " << lengths[0]
        << " .. " << lengths[1] << " m\n"
        << "Mass: total " << total << " kg (integral of the density "
        << integral_of_density << " kg)\n"
        << "Spring stiffness: " << *std::min_element(k.begin(), k.end()) << " .. "
        << *std::max_element(k.begin(), k.end()) << " N/m\n";
    for (const auto &constraint : constraints)
      out << "Constraint '" << constraint->name << "': " << constraint->particles.size()
          << " particles, "
          << (constraint->prescribes_motion() ? "prescribed motion" : "applied force")
          << "\n";
  }


  const std::vector<std::array<unsigned int, 2>> &
  SystemChange::copied_particles() const
  {
    static const std::vector<std::array<unsigned int, 2>> none;
    return cut ? cut->copied_particles : tear ? tear->copied_particles : none;
  }


  std::string
  SystemChange::describe() const
  {
    switch (cause)
    {
      case Cause::cut:
        return "the cut";
      case Cause::laceration:
        return "the laceration";
      case Cause::level_of_detail:
        return "the re-extraction of the level of detail";
    }
    return "a change of the particle system";
  }


  void
  Scene::serialize(Archive &archive)
  {
    // The mesh and the particle system first: the cutters are made on them.
    archive.section("scene");
    archive(
      mesh, integral_of_density, initial_volume, level_of_detail_volume, cut_records);
    archive &level_mass_scale;
    archive(multiresolution, *system);
    archive.section("constraints");
    for (auto &constraint : constraints)
      constraint->serialize(archive);
    archive(cutter, lacerator);
  }
} // namespace lacerta::scene
