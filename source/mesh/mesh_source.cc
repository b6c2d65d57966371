#include <lacerta/mesh/mesh_source.h>

namespace lacerta::mesh
{
  void
  MeshSource::declare_parameters(dealii::ParameterHandler &prm)
  {
    MeshSourceRegistry::declare_selector_subsection(
      prm,
      "Mesh",
      "Source",
      "box",
      "Where the tetrahedral mesh of the object comes "
      "from. Each source reads the subsection of the "
      "same name (capitalised).");
  }


  std::unique_ptr<MeshSource>
  MeshSource::create(dealii::ParameterHandler &prm)
  {
    return MeshSourceRegistry::create_selected(prm, "Mesh", "Source");
  }
} // namespace lacerta::mesh
