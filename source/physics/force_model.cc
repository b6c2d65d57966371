#include <lacerta/physics/force_model.h>

namespace lacerta::physics
{
  void
  ForceModel::parse_parameters(dealii::ParameterHandler &)
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
      "How the springs turn elongation into force.");
  }


  std::unique_ptr<ForceModel>
  ForceModel::create(dealii::ParameterHandler &prm)
  {
    return ForceModelRegistry::create_selected(prm, "Force model", "Model");
  }
} // namespace lacerta::physics
