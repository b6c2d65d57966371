#include <lacerta/mesh/mesh_source.h>

namespace lacerta::mesh
{
  void
  MeshSource::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh");
    MeshSourceRegistry::declare_selector(prm,
                                         "Source",
                                         "box",
                                         "Where the tetrahedral mesh of the object comes "
                                         "from. Each source reads the subsection of the "
                                         "same name (capitalised).");
    MeshSourceRegistry::declare_all_in_subsections(prm);
    prm.leave_subsection();
  }


  std::unique_ptr<MeshSource>
  MeshSource::create(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh");
    auto source = MeshSourceRegistry::create_and_parse(prm.get("Source"), prm);
    prm.leave_subsection();
    return source;
  }
} // namespace lacerta::mesh
