#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/scene/constraint.h>
#include <lacerta/scene/region.h>

#include <deal.II/base/utilities.h>

#include <algorithm>

namespace lacerta::scene
{
  void
  Constraint::initialize(const std::vector<unsigned int> &selected,
                         physics::ParticleSystem         &system)
  {
    particles = selected;
    std::sort(particles.begin(), particles.end());
    if (prescribes_motion())
      for (const unsigned int i : particles)
        system.free[i] = 0.0;
  }


  void
  Constraint::follow_copies(const std::vector<std::array<unsigned int, 2>> &copies,
                            physics::ParticleSystem                        &system)
  {
    std::vector<unsigned int> extended = particles;
    std::sort(extended.begin(), extended.end());
    // Copies have the largest ids so far: appending keeps the list sorted.
    for (const auto &[original, copy] : copies)
      if (std::binary_search(extended.begin(), extended.end(), original))
        extended.insert(std::upper_bound(extended.begin(), extended.end(), copy), copy);
    initialize(extended, system);
  }


  void
  Constraint::follow_renumbering(const std::vector<unsigned int> &new_index,
                                 physics::ParticleSystem         &system)
  {
    std::vector<unsigned int> renamed = particles;
    for (unsigned int &p : renamed)
    {
      if (!new_index.empty()
          && (p >= new_index.size() || new_index[p] >= system.n_particles()))
        throw_error("Constraint '",
                    name,
                    "': internal error, its particle ",
                    p,
                    " was removed by a change of the level of detail.");
      if (!new_index.empty())
        p = new_index[p];
    }
    initialize(renamed, system);
  }


  std::pair<std::size_t, std::size_t>
  Constraint::particles_in(const unsigned int begin, const unsigned int end) const
  {
    const auto first = std::lower_bound(particles.begin(), particles.end(), begin);
    const auto last  = std::lower_bound(first, particles.end(), end);
    return {first - particles.begin(), last - particles.begin()};
  }


  void
  Constraint::prepare(double, const double *)
  {
  }


  void
  Constraint::prescribe(const double *,
                        double *,
                        double *,
                        const unsigned int,
                        const unsigned int) const
  {
  }


  void
  Constraint::add_forces(double, physics::ParticleSystem &) const
  {
  }


  void
  Constraint::declare_parameters(dealii::ParameterHandler       &prm,
                                 const std::vector<std::string> &names)
  {
    prm.enter_subsection("Constraints");
    prm.declare_entry("Names",
                      "",
                      dealii::Patterns::List(dealii::Patterns::Anything()),
                      "Names of the constraints of the scene, separated by commas. Each "
                      "name has a subsection of its own with 'Type', 'Region' and the "
                      "subsections of the plugins ('lacerta --help' shows them under the "
                      "placeholder name '<name>').");
    for (const std::string &name : names)
    {
      prm.enter_subsection(name);
      ConstraintRegistry::declare_selector(prm,
                                           "Type",
                                           "fixed",
                                           "What the constraint does.");
      RegionRegistry::declare_selector(prm,
                                       "Region",
                                       "box",
                                       "Which particles the constraint acts on, selected "
                                       "in the rest configuration.");
      ConstraintRegistry::declare_all_in_subsections(prm);
      RegionRegistry::declare_all_in_subsections(prm);
      prm.leave_subsection();
    }
    prm.leave_subsection();
  }


  std::vector<std::string>
  Constraint::names(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Constraints");
    const std::vector<std::string> list =
      dealii::Utilities::split_string_list(prm.get("Names"));
    prm.leave_subsection();
    return list;
  }


  std::vector<std::unique_ptr<Constraint>>
  Constraint::create(dealii::ParameterHandler &prm, const mesh::TetMesh &mesh)
  {
    std::vector<std::unique_ptr<Constraint>> constraints;
    const std::vector<std::string>           list = names(prm);
    prm.enter_subsection("Constraints");
    for (const std::string &name : list)
    {
      prm.enter_subsection(name);
      auto constraint       = ConstraintRegistry::create_and_parse(prm.get("Type"), prm);
      auto region           = RegionRegistry::create_and_parse(prm.get("Region"), prm);
      constraint->name      = name;
      constraint->particles = region->select(mesh);
      constraint->region    = std::move(region);
      if (constraint->particles.empty())
        throw_error("Constraints/",
                    name,
                    ": the region ('",
                    prm.get("Region"),
                    "') contains no particle of the mesh.");
      prm.leave_subsection();
      constraints.push_back(std::move(constraint));
    }
    prm.leave_subsection();
    return constraints;
  }


  void
  Constraint::serialize(Archive &archive)
  {
    archive &particles;
  }
} // namespace lacerta::scene
