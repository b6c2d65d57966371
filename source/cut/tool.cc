#include <lacerta/cut/tool.h>

namespace lacerta::cut
{
  void
  Tool::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Tool");
    prm.declare_entry("Type",
                      "none",
                      dealii::Patterns::Selection("none|"
                                                  + ToolRegistry::selection_pattern()),
                      ToolRegistry::documentation(
                        "The cutting tool. `none': no tool, the scene builds no cut "
                        "structure and runs as fast as without this subsystem."));
    ToolRegistry::declare_all_in_subsections(prm);
    prm.leave_subsection();
  }


  std::unique_ptr<Tool>
  Tool::create(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Tool");
    const std::string     name = prm.get("Type");
    std::unique_ptr<Tool> tool;
    if (name != "none")
      tool = ToolRegistry::create_and_parse(name, prm);
    prm.leave_subsection();
    return tool;
  }
} // namespace lacerta::cut
