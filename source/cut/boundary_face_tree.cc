#include <lacerta/cut/boundary_face_tree.h>

#include <algorithm>

namespace lacerta::cut
{
  namespace
  {
    /// Whether (tet, face) of @p mesh still is the boundary face with these vertices.
    bool
    still_boundary(const mesh::TetMesh &mesh, const BoundaryFaceTree::Face &f)
    {
      if (f.tet >= mesh.n_tets() || mesh.neighbor(f.tet, f.face) != mesh::invalid_index)
        return false;
      const mesh::Tet &t = mesh.tet(f.tet);
      for (unsigned int k = 0; k < 3; ++k)
        if (t[mesh::TetMesh::face_vertices[f.face][k]] != f.vertices[k])
          return false;
      return true;
    }

    BoundaryFaceTree::Face
    make_face(const mesh::TetMesh &mesh, const unsigned int tet, const unsigned int face)
    {
      const mesh::Tet &t = mesh.tet(tet);
      return {tet,
              face,
              {{t[mesh::TetMesh::face_vertices[face][0]],
                t[mesh::TetMesh::face_vertices[face][1]],
                t[mesh::TetMesh::face_vertices[face][2]]}}};
    }
  } // namespace


  std::array<Point, 3>
  BoundaryFaceTree::triangle(const Face &f, const double *x)
  {
    std::array<Point, 3> p;
    for (unsigned int k = 0; k < 3; ++k)
      p[k] = {{x[3 * f.vertices[k]], x[3 * f.vertices[k] + 1], x[3 * f.vertices[k] + 2]}};
    return p;
  }


  Box
  BoundaryFaceTree::face_box(const Face &f, const double *x)
  {
    Box b;
    for (const Point &p : triangle(f, x))
      b.extend(p);
    return b;
  }


  void
  BoundaryFaceTree::build(const mesh::TetMesh &mesh, const double *x)
  {
    faces.clear();
    extra.clear();
    nodes.clear();
    for (const auto &bf : mesh.get_boundary_faces())
      faces.push_back(make_face(mesh, bf.tet, bf.face));
    if (!faces.empty())
      build_node(0, static_cast<unsigned int>(faces.size()), x);
  }


  unsigned int
  BoundaryFaceTree::build_node(const unsigned int first,
                               const unsigned int count,
                               const double      *x)
  {
    const unsigned int index = static_cast<unsigned int>(nodes.size());
    nodes.push_back({});
    Box box;
    for (unsigned int i = first; i < first + count; ++i)
      box.extend(face_box(faces[i], x));
    if (count <= 4)
    {
      nodes[index] = {box, first, count, 0, 0};
      return index;
    }
    // Median split along the longest side of the box, by face centroid.
    unsigned int axis = 0;
    for (unsigned int d = 1; d < 3; ++d)
      if (box.upper[d] - box.lower[d] > box.upper[axis] - box.lower[axis])
        axis = d;
    const auto centre = [&](const Face &f)
    {
      return x[3 * f.vertices[0] + axis] + x[3 * f.vertices[1] + axis]
             + x[3 * f.vertices[2] + axis];
    };
    const unsigned int half = count / 2;
    std::nth_element(faces.begin() + first,
                     faces.begin() + first + half,
                     faces.begin() + first + count,
                     [&](const Face &a, const Face &b) { return centre(a) < centre(b); });
    const unsigned int left  = build_node(first, half, x);
    const unsigned int right = build_node(first + half, count - half, x);
    nodes[index]             = {box, first, 0, left, right};
    return index;
  }


  void
  BoundaryFaceTree::refit(const mesh::TetMesh &mesh, const double *x)
  {
    if (extra.size() > 64 + faces.size() / 10)
    {
      build(mesh, x);
      return;
    }
    // Children always come after their parent: one backward sweep refits the tree.
    for (std::size_t i = nodes.size(); i-- > 0;)
    {
      Node &n = nodes[i];
      n.box   = Box();
      if (n.count > 0)
        for (unsigned int k = n.first; k < n.first + n.count; ++k)
          n.box.extend(face_box(faces[k], x));
      else
      {
        n.box.extend(nodes[n.left].box);
        n.box.extend(nodes[n.right].box);
      }
    }
  }


  void
  BoundaryFaceTree::add_face(const mesh::TetMesh &mesh,
                             const unsigned int   tet,
                             const unsigned int   face)
  {
    extra.push_back(make_face(mesh, tet, face));
  }


  void
  BoundaryFaceTree::query(const mesh::TetMesh &mesh,
                          const double        *x,
                          const Box           &box,
                          std::vector<Face>   &hits) const
  {
    if (!nodes.empty())
    {
      unsigned int stack[64];
      unsigned int top = 0;
      stack[top++]     = 0;
      while (top > 0)
      {
        const Node &n = nodes[stack[--top]];
        if (!n.box.overlaps(box))
          continue;
        if (n.count > 0)
        {
          for (unsigned int k = n.first; k < n.first + n.count; ++k)
            if (face_box(faces[k], x).overlaps(box) && still_boundary(mesh, faces[k]))
              hits.push_back(faces[k]);
        }
        else
        {
          stack[top++] = n.left;
          stack[top++] = n.right;
        }
      }
    }
    for (const Face &f : extra)
      if (face_box(f, x).overlaps(box) && still_boundary(mesh, f))
        hits.push_back(f);
  }
} // namespace lacerta::cut
