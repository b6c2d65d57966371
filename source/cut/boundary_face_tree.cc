#include <lacerta/cut/boundary_face_tree.h>

#include <algorithm>
#include <cmath>

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
    // The faces added until the next rebuild (refit() rebuilds past 64 + a tenth of
    // the tree, one cut step later at most): reserved so that a cut copies none.
    extra.reserve(128 + faces.size() / 5);
    // The vertices of the faces: the boundary vertices, in order.
    vertices.clear();
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
      if (mesh.is_boundary_vertex(v))
        vertices.push_back(v);
    fitted.resize(3 * vertices.size());
    inflation = 0;
    if (!faces.empty())
    {
      // The faces with their boxes and centroids (sums of the three vertices), read
      // from the positions once instead of at every level of the tree.
      work.resize(faces.size());
      sizes.resize(faces.size());
      for (std::size_t i = 0; i < faces.size(); ++i)
      {
        const Face &f = faces[i];
        work[i].face  = f;
        work[i].box   = face_box(f, x);
        for (unsigned int d = 0; d < 3; ++d)
          work[i].centre[d] = x[3 * f.vertices[0] + d] + x[3 * f.vertices[1] + d]
                              + x[3 * f.vertices[2] + d];
        sizes[i] = work[i].box.size();
      }
      // The margin: a quarter of the median face size, so that a vertex crosses it
      // in many time steps (a stable step moves it by a small part of an edge) while
      // a query gets few extra candidates from the inflated boxes.
      std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
      inflation = 0.25 * sizes[sizes.size() / 2];
      build_node(0, static_cast<unsigned int>(faces.size()));
      for (std::size_t i = 0; i < faces.size(); ++i)
        faces[i] = work[i].face;
    }
    fit(x);
  }


  unsigned int
  BoundaryFaceTree::build_node(const unsigned int first, const unsigned int count)
  {
    const unsigned int index = static_cast<unsigned int>(nodes.size());
    nodes.push_back({});
    Box box;
    for (unsigned int i = first; i < first + count; ++i)
      box.extend(work[i].box);
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
    const unsigned int half = count / 2;
    std::nth_element(work.begin() + first,
                     work.begin() + first + half,
                     work.begin() + first + count,
                     [&](const Entry &a, const Entry &b)
                     { return a.centre[axis] < b.centre[axis]; });
    const unsigned int left  = build_node(first, half);
    const unsigned int right = build_node(first + half, count - half);
    nodes[index]             = {box, first, 0, left, right};
    return index;
  }


  bool
  BoundaryFaceTree::refit(const mesh::TetMesh &mesh, const double *x)
  {
    if (extra.size() > 64 + faces.size() / 10)
    {
      build(mesh, x);
      return true;
    }
    // The boxes hold while every vertex is within the margin of where it was fitted
    // (written so that a NaN position refits too).
    for (std::size_t k = 0; k < vertices.size(); ++k)
    {
      const double *p = x + 3 * std::size_t(vertices[k]);
      const double *q = fitted.data() + 3 * k;
      if (!(std::abs(p[0] - q[0]) <= inflation && std::abs(p[1] - q[1]) <= inflation
            && std::abs(p[2] - q[2]) <= inflation))
      {
        fit(x);
        return true;
      }
    }
    return false;
  }


  void
  BoundaryFaceTree::fit(const double *x)
  {
    // Children always come after their parent: one backward sweep refits the tree.
    for (std::size_t i = nodes.size(); i-- > 0;)
    {
      Node &n = nodes[i];
      n.box   = Box();
      if (n.count > 0)
      {
        for (unsigned int k = n.first; k < n.first + n.count; ++k)
          n.box.extend(face_box(faces[k], x));
        n.box.inflate(inflation);
      }
      else
      {
        n.box.extend(nodes[n.left].box);
        n.box.extend(nodes[n.right].box);
      }
    }
    for (std::size_t k = 0; k < vertices.size(); ++k)
      for (unsigned int d = 0; d < 3; ++d)
        fitted[3 * k + d] = x[3 * std::size_t(vertices[k]) + d];
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
