#include <lacerta/base/exceptions.h>
#include <lacerta/cut/cutter.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mesh/mesh_source.h>
#include <lacerta/physics/assembly.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/scene.h>

#include <algorithm>
#include <cmath>
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
    cut::Tool::declare_parameters(prm);
    cut::Cutter::declare_parameters(prm);
  }


  Scene::Scene(dealii::ParameterHandler &prm, const unsigned int n_threads)
  {
    mesh = mesh::MeshSource::create(prm)->create_mesh();
    mesh.sort_spatially();
    material.parse_parameters(prm);

    std::vector<double> rest(3 * mesh.n_vertices());
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      for (unsigned int d = 0; d < 3; ++d)
        rest[3 * v + d] = mesh.vertex(v)[d];
    system = std::make_unique<physics::ParticleSystem>(rest);

    system->mass        = physics::compute_masses(mesh, material.density());
    integral_of_density = physics::integrate_over_mesh(mesh, material.density());
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

    system->springs = physics::compute_springs(mesh, material.youngs_modulus());
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

    body_forces = BodyForce::create(prm);
    for (auto &force : body_forces)
    {
      force->initialize(*system);
      has_varying_loads |= force->varies();
    }
    constraints = Constraint::create(prm, mesh);
    for (auto &constraint : constraints)
    {
      constraint->initialize(constraint->particles, *system);
      has_varying_loads |= !constraint->prescribes_motion();
    }
    system->enforce_constraints = [this](const double t, double *x, double *v)
    {
      for (const auto &constraint : constraints)
        constraint->prescribe(t, system->rest_position().data(), x, v);
    };
    system->enforce_constraints(0.0, system->position.data(), system->velocity.data());
    update_loads(0.0);

    system->set_force_model(physics::ForceModel::create(prm), n_threads);
    initial_volume = mesh.total_volume();
    tool           = cut::Tool::create(prm);
    if (tool)
      cutter = std::make_unique<cut::Cutter>(mesh,
                                             *system,
                                             material.density(),
                                             material.youngs_modulus(),
                                             integral_of_density,
                                             cut::Cutter::parse_parameters(prm),
                                             tool->blade(0.0));
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
    const auto   lengths = mesh.edge_length_range();
    const auto  &k       = system->springs.stiffness;
    const double total   = std::accumulate(system->mass.begin(), system->mass.end(), 0.0);
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
} // namespace lacerta::scene
