#include <lacerta/scene/body_force.h>

#include <deal.II/base/utilities.h>

namespace lacerta::scene
{
  void
  BodyForce::initialize(physics::ParticleSystem &)
  {
  }


  bool
  BodyForce::varies() const
  {
    return false;
  }


  void
  BodyForce::add_forces(double, physics::ParticleSystem &) const
  {
  }


  void
  BodyForce::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Body forces");
    BodyForceRegistry::declare_list(prm,
                                    "List of body forces",
                                    "",
                                    "The body forces of the scene, separated by commas.");
    BodyForceRegistry::declare_all_in_subsections(prm);
    prm.leave_subsection();
  }


  std::vector<std::unique_ptr<BodyForce>>
  BodyForce::create(dealii::ParameterHandler &prm)
  {
    std::vector<std::unique_ptr<BodyForce>> forces;
    prm.enter_subsection("Body forces");
    for (const std::string &name :
         dealii::Utilities::split_string_list(prm.get("List of body forces")))
      forces.push_back(BodyForceRegistry::create_and_parse(name, prm));
    prm.leave_subsection();
    return forces;
  }
} // namespace lacerta::scene
