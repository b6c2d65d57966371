#include <lacerta/base/archive.h>
#include <lacerta/cut/boundary_face_tree.h>

#include <algorithm>
#include <cmath>
#include <utility>

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
  BoundaryFaceTree::track(const unsigned int v, const double *x)
  {
    if (v >= slot.size())
      slot.resize(std::max<std::size_t>(v + 1, 2 * slot.size()), mesh::invalid_index);
    if (slot[v] != mesh::invalid_index)
      return;
    slot[v] = static_cast<unsigned int>(vertices.size());
    vertices.push_back(v);
    for (unsigned int d = 0; d < 3; ++d)
      fitted.push_back(x[3 * std::size_t(v) + d]);
  }


  Box
  BoundaryFaceTree::fitted_box(const Face &f) const
  {
    Box b;
    for (const unsigned int v : f.vertices)
    {
      const double *p = fitted.data() + 3 * std::size_t(slot[v]);
      b.extend(Point{{p[0], p[1], p[2]}});
    }
    return b;
  }


  void
  BoundaryFaceTree::build(const mesh::TetMesh &mesh, const double *x)
  {
    added.clear();
    extra.clear();
    extra.reserve(1024);
    vertices.clear();
    fitted.clear();
    slot.assign(mesh.n_vertices(), mesh::invalid_index);
    std::vector<Face> faces;
    faces.reserve(mesh.get_boundary_faces().size());
    for (const auto &bf : mesh.get_boundary_faces())
    {
      faces.push_back(make_face(mesh, bf.tet, bf.face));
      for (const unsigned int v : faces.back().vertices)
        track(v, x);
    }
    // The margin: a quarter of the median face size, so that a vertex crosses it in
    // many time steps (a stable step moves it by a small part of an edge) while a
    // query gets few extra candidates from the inflated boxes.
    inflation = 0;
    if (!faces.empty())
    {
      sizes.resize(faces.size());
      for (std::size_t i = 0; i < faces.size(); ++i)
        sizes[i] = fitted_box(faces[i]).size();
      std::nth_element(sizes.begin(), sizes.begin() + sizes.size() / 2, sizes.end());
      inflation = 0.25 * sizes[sizes.size() / 2];
    }
    build_tree(boundary, std::move(faces));
  }


  void
  BoundaryFaceTree::build_tree(Tree &tree, std::vector<Face> &&faces)
  {
    tree.faces = std::move(faces);
    tree.nodes.clear();
    if (tree.faces.empty())
      return;
    // The faces with their boxes and centroids (sums of the three vertices), read
    // from the positions once instead of at every level of the tree.
    work.resize(tree.faces.size());
    for (std::size_t i = 0; i < tree.faces.size(); ++i)
    {
      const Face &f = tree.faces[i];
      work[i].face  = f;
      work[i].box   = fitted_box(f);
      for (unsigned int d = 0; d < 3; ++d)
      {
        work[i].centre[d] = 0;
        for (const unsigned int v : f.vertices)
          work[i].centre[d] += fitted[3 * std::size_t(slot[v]) + d];
      }
    }
    build_node(tree, 0, static_cast<unsigned int>(tree.faces.size()));
    for (std::size_t i = 0; i < tree.faces.size(); ++i)
      tree.faces[i] = work[i].face;
    fit_tree(tree);
  }


  unsigned int
  BoundaryFaceTree::build_node(Tree              &tree,
                               const unsigned int first,
                               const unsigned int count)
  {
    const unsigned int index = static_cast<unsigned int>(tree.nodes.size());
    tree.nodes.push_back({});
    Box box;
    for (unsigned int i = first; i < first + count; ++i)
      box.extend(work[i].box);
    if (count <= 4)
    {
      tree.nodes[index] = {box, first, count, 0, 0};
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
    const unsigned int left  = build_node(tree, first, half);
    const unsigned int right = build_node(tree, first + half, count - half);
    tree.nodes[index]        = {box, first, 0, left, right};
    return index;
  }


  bool
  BoundaryFaceTree::refit(const mesh::TetMesh &mesh, const double *x)
  {
    bool changed = false;
    // The boxes hold while every vertex is within the margin of where it was fitted
    // (written so that a NaN position refits too).
    for (std::size_t k = 0; k < vertices.size(); ++k)
    {
      const double *p = x + 3 * std::size_t(vertices[k]);
      const double *q = fitted.data() + 3 * k;
      if (!(std::abs(p[0] - q[0]) <= inflation && std::abs(p[1] - q[1]) <= inflation
            && std::abs(p[2] - q[2]) <= inflation))
      {
        for (std::size_t j = 0; j < vertices.size(); ++j)
          for (unsigned int d = 0; d < 3; ++d)
            fitted[3 * j + d] = x[3 * std::size_t(vertices[j]) + d];
        fit_tree(boundary);
        for (Tree &tree : added)
          fit_tree(tree);
        changed = true;
        break;
      }
    }
    if (extra.size() >= 64)
    {
      merge_added(mesh, x);
      changed = true;
    }
    return changed;
  }


  void
  BoundaryFaceTree::merge_added(const mesh::TetMesh &mesh, const double *x)
  {
    if (n_added_faces() + extra.size() > boundary.faces.size())
    {
      build(mesh, x);
      return;
    }
    // The level of a tree of m faces: floor(log2(m / 64)).
    const auto level = [](std::size_t m)
    {
      unsigned int k = 0;
      for (m /= 64; m > 1; m /= 2)
        ++k;
      return k;
    };
    std::vector<Face> faces;
    faces.reserve(2 * extra.size());
    for (const Face &f : extra)
      if (still_boundary(mesh, f))
      {
        faces.push_back(f);
        for (const unsigned int v : f.vertices)
          track(v, x);
      }
    extra.clear();
    // A binary counter: the new tree takes the trees of its size (and then of the
    // size of the union) in, until it finds a free level.
    unsigned int k = level(faces.size());
    while (k < added.size() && !added[k].faces.empty())
    {
      for (const Face &f : added[k].faces)
        if (still_boundary(mesh, f))
          faces.push_back(f);
      added[k] = Tree();
      k        = std::max(k + 1, level(faces.size()));
    }
    if (k >= added.size())
      added.resize(k + 1);
    build_tree(added[k], std::move(faces));
  }


  void
  BoundaryFaceTree::fit_tree(Tree &tree) const
  {
    // Children always come after their parent: one backward sweep refits the tree.
    for (std::size_t i = tree.nodes.size(); i-- > 0;)
    {
      Node &n = tree.nodes[i];
      n.box   = Box();
      if (n.count > 0)
      {
        for (unsigned int k = n.first; k < n.first + n.count; ++k)
          n.box.extend(fitted_box(tree.faces[k]));
        n.box.inflate(inflation);
      }
      else
      {
        n.box.extend(tree.nodes[n.left].box);
        n.box.extend(tree.nodes[n.right].box);
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


  std::size_t
  BoundaryFaceTree::size() const
  {
    return boundary.faces.size() + n_added_faces() + extra.size();
  }


  std::size_t
  BoundaryFaceTree::n_added_faces() const
  {
    std::size_t n = 0;
    for (const Tree &tree : added)
      n += tree.faces.size();
    return n;
  }


  unsigned int
  BoundaryFaceTree::n_added_trees() const
  {
    unsigned int n = 0;
    for (const Tree &tree : added)
      n += !tree.faces.empty();
    return n;
  }


  template <class Meets>
  void
  BoundaryFaceTree::query_tree(const Tree          &tree,
                               const mesh::TetMesh &mesh,
                               const double        *x,
                               const Meets         &meets,
                               std::vector<Face>   &hits)
  {
    if (tree.nodes.empty())
      return;
    unsigned int stack[64];
    unsigned int top = 0;
    stack[top++]     = 0;
    while (top > 0)
    {
      const Node &n = tree.nodes[stack[--top]];
      if (!meets(n.box))
        continue;
      if (n.count > 0)
      {
        for (unsigned int k = n.first; k < n.first + n.count; ++k)
          if (meets(face_box(tree.faces[k], x)) && still_boundary(mesh, tree.faces[k]))
            hits.push_back(tree.faces[k]);
      }
      else
      {
        stack[top++] = n.left;
        stack[top++] = n.right;
      }
    }
  }


  template <class Meets>
  void
  BoundaryFaceTree::collect(const mesh::TetMesh &mesh,
                            const double        *x,
                            const Meets         &meets,
                            std::vector<Face>   &hits) const
  {
    const std::size_t begin = hits.size();
    query_tree(boundary, mesh, x, meets, hits);
    for (const Tree &tree : added)
      query_tree(tree, mesh, x, meets, hits);
    for (const Face &f : extra)
      if (meets(face_box(f, x)) && still_boundary(mesh, f))
        hits.push_back(f);
    // In a canonical order, once each: what the trees hold, and how, does not change
    // the cutter's seeds. (A cut hands over every boundary face of the cells it makes,
    // and a cell that keeps its slot and a face keeps that face: it is then in two
    // trees.)
    const auto key = [](const Face &f) { return std::make_pair(f.tet, f.face); };
    std::sort(hits.begin() + begin,
              hits.end(),
              [&](const Face &a, const Face &b) { return key(a) < key(b); });
    hits.erase(std::unique(hits.begin() + begin,
                           hits.end(),
                           [&](const Face &a, const Face &b)
                           { return key(a) == key(b); }),
               hits.end());
  }


  void
  BoundaryFaceTree::query(const mesh::TetMesh &mesh,
                          const double        *x,
                          const Box           &box,
                          std::vector<Face>   &hits) const
  {
    collect(
      mesh, x, [&](const Box &b) { return b.overlaps(box); }, hits);
  }


  void
  BoundaryFaceTree::query(const mesh::TetMesh                       &mesh,
                          const double                              *x,
                          const std::array<std::array<Point, 3>, 2> &triangles,
                          std::vector<Face>                         &hits) const
  {
    Box all = Box::around(triangles[0]);
    all.extend(Box::around(triangles[1]));
    collect(
      mesh,
      x,
      [&](const Box &b)
      { return b.overlaps(all) && (b.meets(triangles[0]) || b.meets(triangles[1])); },
      hits);
  }


  void
  BoundaryFaceTree::Tree::serialize(Archive &archive)
  {
    archive(faces, nodes);
  }


  void
  BoundaryFaceTree::serialize(Archive &archive)
  {
    archive(boundary, added, extra, vertices, fitted, slot, inflation);
  }
} // namespace lacerta::cut
