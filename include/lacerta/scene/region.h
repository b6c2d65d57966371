/**
 * @file
 * Regions of the object that constraints act on (plugins).
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/mesh/tet_mesh.h>

#include <vector>

namespace lacerta::scene
{
  /**
   * A region selects particles of the mesh in its rest configuration.
   */
  class Region
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "region";
    }

    virtual ~Region() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /// The particles (vertex ids, sorted) of @p mesh inside the region.
    virtual std::vector<unsigned int>
    select(const mesh::TetMesh &mesh) const = 0;
  };

  /// The registry of regions.
  using RegionRegistry = PluginRegistry<Region>;
} // namespace lacerta::scene

/// Registers a region plugin.
#define LACERTA_REGISTER_REGION(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::scene::Region, classname, name, description)
