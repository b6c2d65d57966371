#include <lacerta/physics/force_model.h>

namespace lacerta::physics
{
  void
  ForceModel::parse_parameters(dealii::ParameterHandler &)
  {
  }


  void
  ForceModel::compute_acceleration(const ParticleSystem &system,
                                   const double         *x,
                                   const double         *v,
                                   double               *a) const
  {
    compute_acceleration(system, x, v, a, [](unsigned int, unsigned int) {});
  }


  double
  ForceModel::spring_stiffness_scale() const
  {
    return 1.0;
  }


  bool
  ForceModel::has_element_stiffness() const
  {
    return false;
  }


  void
  ForceModel::for_each_element_stiffness(
    const ParticleSystem &,
    const double *,
    const std::function<void(unsigned int, const ElementStiffness &)> &) const
  {
  }


  void
  ForceModel::for_each_element_stiffness_of(
    const ParticleSystem &,
    const double *,
    const std::vector<unsigned int> &,
    const std::function<void(unsigned int, const ElementStiffness &)> &) const
  {
  }


  void
  ForceModel::declare_parameters(dealii::ParameterHandler &prm)
  {
    ForceModelRegistry::declare_selector_subsection(
      prm,
      "Force model",
      "Model",
      "linear springs",
      "How the particles' positions turn into elastic forces: the paper's "
      "springs, springs with a volume term per tetrahedron that reproduce "
      "'Material/Poisson ratio', or corotated linear FEM on the tetrahedra "
      "(doc/physics.md; doc/manual.md says how to choose).");
  }


  std::unique_ptr<ForceModel>
  ForceModel::create(dealii::ParameterHandler &prm)
  {
    return ForceModelRegistry::create_selected(prm, "Force model", "Model");
  }
} // namespace lacerta::physics
