/**
 * @file
 * Where a scene's mesh comes from: a plugin kind (`subsection Mesh`, `set Source`).
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/mesh/tet_mesh.h>

#include <memory>

namespace lacerta::mesh
{
  /**
   * A mesh source creates the rest configuration of the object as a TetMesh.
   */
  class MeshSource
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "mesh source";
    }

    virtual ~MeshSource() = default;

    /// Reads the plugin's parameters from its own subsection (already entered).
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /// Creates the mesh; errors in the input are reported as lacerta::Error.
    virtual TetMesh
    create_mesh() const = 0;

    /// Declares `subsection Mesh` with the `Source` selector and every plugin's entries.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Creates the source selected in `subsection Mesh` and reads its parameters.
    static std::unique_ptr<MeshSource>
    create(dealii::ParameterHandler &prm);
  };

  /// The registry of mesh sources.
  using MeshSourceRegistry = PluginRegistry<MeshSource>;
} // namespace lacerta::mesh

/// Registers a mesh source plugin.
#define LACERTA_REGISTER_MESH_SOURCE(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::mesh::MeshSource, classname, name, description)
