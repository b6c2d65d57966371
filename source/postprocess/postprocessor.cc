#include <lacerta/postprocess/postprocessor.h>

#include <deal.II/base/utilities.h>

namespace lacerta::postprocess
{
  bool
  Postprocessor::needs_energies(double) const
  {
    return false;
  }


  bool
  Postprocessor::writes_state(double) const
  {
    return false;
  }


  void
  Postprocessor::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Postprocess");
    PostprocessorRegistry::declare_list(prm,
                                        "List of postprocessors",
                                        "vtu, statistics",
                                        "What the run writes into the output directory, "
                                        "separated by commas.");
    PostprocessorRegistry::declare_all_in_subsections(prm);
    prm.leave_subsection();
  }


  std::vector<std::unique_ptr<Postprocessor>>
  Postprocessor::create(dealii::ParameterHandler &prm)
  {
    std::vector<std::unique_ptr<Postprocessor>> list;
    prm.enter_subsection("Postprocess");
    for (const std::string &name :
         dealii::Utilities::split_string_list(prm.get("List of postprocessors")))
      list.push_back(PostprocessorRegistry::create_and_parse(name, prm));
    prm.leave_subsection();
    return list;
  }
} // namespace lacerta::postprocess
