#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/spring_strain.h>
#include <lacerta/view/surface_field.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>

#include <algorithm>
#include <cmath>

namespace lacerta::view
{
  namespace
  {
    /// The longest rest edge of tetrahedron @p t.
    double
    longest_rest_edge(const mesh::TetMesh &mesh, const unsigned int t)
    {
      double longest = 0;
      for (const auto &e : mesh::TetMesh::edge_vertices)
      {
        const auto &p = mesh.vertex(mesh.tet(t)[e[0]]);
        const auto &q = mesh.vertex(mesh.tet(t)[e[1]]);
        longest = std::max(longest, std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]));
      }
      return longest;
    }
  } // namespace


  std::string
  field_names()
  {
    return "displacement|spring strain|cell size";
  }


  Field
  field_from_name(const std::string &name)
  {
    if (name == "displacement")
      return Field::displacement;
    if (name == "spring strain")
      return Field::spring_strain;
    if (name == "cell size")
      return Field::cell_size;
    throw_error("Unknown field '", name, "'; the fields are ", field_names(), ".");
  }


  std::string
  field_title(const Field field)
  {
    switch (field)
    {
      case Field::displacement:
        return "displacement [m]";
      case Field::spring_strain:
        return "spring strain";
      case Field::cell_size:
        return "cell size [m]";
    }
    return "";
  }


  vtkSmartPointer<vtkPolyData>
  surface_with_field(const mesh::TetMesh           &mesh,
                     const physics::ParticleSystem &system,
                     const Field                    field)
  {
    const unsigned int n = system.n_particles();
    vtkNew<vtkPoints>  points;
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints(n);
    for (unsigned int i = 0; i < n; ++i)
      points->SetPoint(i, &system.position[3 * i]);

    const auto          &faces = mesh.get_boundary_faces();
    vtkNew<vtkCellArray> triangles;
    triangles->AllocateExact(faces.size(), 3 * faces.size());
    vtkNew<vtkDoubleArray> values;
    values->SetName("field");
    for (const auto &face : faces)
    {
      const mesh::Tet &tet = mesh.tet(face.tet);
      vtkIdType        ids[3];
      for (unsigned int i = 0; i < 3; ++i)
        ids[i] = tet[mesh::TetMesh::face_vertices[face.face][i]];
      triangles->InsertNextCell(3, ids);
      if (field == Field::cell_size)
        values->InsertNextValue(longest_rest_edge(mesh, face.tet));
      else if (field == Field::spring_strain)
      {
        // The face's edges are those of its tetrahedron that avoid the opposite vertex.
        double largest = 0;
        for (unsigned int e = 0; e < 6; ++e)
        {
          const auto &ends = mesh::TetMesh::edge_vertices[e];
          if (ends[0] == face.face || ends[1] == face.face)
            continue;
          const double strain =
            physics::spring_strain(system, mesh.tet_edges(face.tet)[e]);
          if (std::abs(strain) > std::abs(largest))
            largest = strain;
        }
        values->InsertNextValue(largest);
      }
    }

    auto surface = vtkSmartPointer<vtkPolyData>::New();
    surface->SetPoints(points);
    surface->SetPolys(triangles);
    if (field == Field::displacement)
    {
      values->SetNumberOfTuples(n);
      const std::vector<double> &rest = system.rest_position();
      for (unsigned int i = 0; i < n; ++i)
        values->SetValue(i,
                         std::hypot(system.position[3 * i] - rest[3 * i],
                                    system.position[3 * i + 1] - rest[3 * i + 1],
                                    system.position[3 * i + 2] - rest[3 * i + 2]));
      surface->GetPointData()->SetScalars(values);
    }
    else
      surface->GetCellData()->SetScalars(values);
    return surface;
  }
} // namespace lacerta::view
