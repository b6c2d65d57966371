#include <lacerta/postprocess/postprocessor.h>

#include <deal.II/base/utilities.h>

#include <algorithm>

namespace lacerta::postprocess
{
  void
  Postprocessor::parse_parameters(dealii::ParameterHandler &)
  {
  }


  void
  Postprocessor::subscribe(scene::Scene &)
  {
  }


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
  Postprocessor::finish(const RunState &)
  {
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
  Postprocessor::create(dealii::ParameterHandler       &prm,
                        const std::vector<std::string> &required)
  {
    std::vector<std::unique_ptr<Postprocessor>> list;
    prm.enter_subsection("Postprocess");
    std::vector<std::string> names =
      dealii::Utilities::split_string_list(prm.get("List of postprocessors"));
    for (auto r = required.rbegin(); r != required.rend(); ++r)
      if (std::find(names.begin(), names.end(), *r) == names.end())
        names.insert(names.begin(), *r);
    for (const std::string &name : names)
      list.push_back(PostprocessorRegistry::create_and_parse(name, prm));
    prm.leave_subsection();
    return list;
  }
} // namespace lacerta::postprocess
