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
    prm.enter_subsection("Force model");
    ForceModelRegistry::declare_selector(prm,
                                         "Model",
                                         "linear springs",
                                         "How the springs turn elongation into force.");
    ForceModelRegistry::declare_all_in_subsections(prm);
    prm.leave_subsection();
  }


  std::unique_ptr<ForceModel>
  ForceModel::create(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Force model");
    auto model = ForceModelRegistry::create_and_parse(prm.get("Model"), prm);
    prm.leave_subsection();
    return model;
  }
} // namespace lacerta::physics
