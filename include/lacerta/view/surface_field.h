/**
 * @file
 * The tissue's surface as VTK polygons, coloured by a field (for pictures and the
 * viewer).
 */
#pragma once

#include <vtkSmartPointer.h>

#include <string>

class vtkPolyData;

namespace lacerta::mesh
{
  class TetMesh;
}
namespace lacerta::physics
{
  class ParticleSystem;
}

namespace lacerta::view
{
  /// What colours the surface.
  enum class Field
  {
    /// |x - X| at the particles [m].
    displacement,
    /// Elongation over rest length of the spring most stretched or compressed among
    /// a face's three edges: the laceration criterion (Section 7).
    spring_strain,
    /// The longest rest edge of the tetrahedron a face belongs to [m]: shows the level
    /// of detail.
    cell_size
  };

  /// The names of the fields, as a `Patterns::Selection` string.
  std::string
  field_names();

  /// The field called @p name (one of field_names()).
  Field
  field_from_name(const std::string &name);

  /// The name of @p field, with its unit, for titles and colour bars.
  std::string
  field_title(Field field);

  /**
   * The boundary faces of @p mesh at the positions of @p system (one triangle per face,
   * outward), with @p field as the scalars: point data for the displacement, cell data
   * otherwise. The springs are the mesh's edges, in the same order.
   */
  vtkSmartPointer<vtkPolyData>
  surface_with_field(const mesh::TetMesh           &mesh,
                     const physics::ParticleSystem &system,
                     Field                          field);
} // namespace lacerta::view
