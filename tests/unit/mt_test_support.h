// Helpers shared by the Multi-Triangulation tests.
#pragma once

#include <lacerta/mt/lod_query.h>

#include <deal.II/base/parameter_handler.h>

#include <map>
#include <memory>
#include <string>

namespace lacerta::test_support
{
  /// A level of detail query from a name and parameters, as a scene would make it.
  inline std::unique_ptr<mt::LodQuery>
  make_query(const std::string &name, const std::map<std::string, std::string> &values)
  {
    dealii::ParameterHandler prm;
    mt::LodQueryRegistry::declare_all_in_subsections(prm);
    prm.enter_subsection(mt::LodQueryRegistry::subsection_name(name));
    for (const auto &[entry, value] : values)
      prm.set(entry, value);
    prm.leave_subsection();
    return mt::LodQueryRegistry::create_and_parse(name, prm);
  }
} // namespace lacerta::test_support
