#include <lacerta/cut/invariants.h>
#include <lacerta/physics/particle_system.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>

namespace lacerta::cut
{
  std::string
  check_invariants(const mesh::TetMesh           &mesh,
                   const physics::ParticleSystem &system,
                   const double                   volume,
                   const double                   integral_of_density)
  {
    std::ostringstream problem;
    using mesh::TetMesh;
    const auto &x = mesh.get_vertices();
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
    {
      const mesh::Tet &c = mesh.tet(t);
      double           h = 0;
      for (const auto &e : TetMesh::edge_vertices)
        h = std::max(h,
                     std::hypot(x[c[e[1]]][0] - x[c[e[0]]][0],
                                x[c[e[1]]][1] - x[c[e[0]]][1],
                                x[c[e[1]]][2] - x[c[e[0]]][2]));
      if (!(mesh.volume(t) > 1e-9 * h * h * h))
      {
        problem << "tetrahedron " << t << " (vertices " << c[0] << ", " << c[1] << ", "
                << c[2] << ", " << c[3] << ") is inverted or flat (volume "
                << mesh.volume(t) << ", longest edge " << h << ")";
        return problem.str();
      }
      for (unsigned int f = 0; f < 4; ++f)
      {
        const unsigned int n = mesh.neighbor(t, f);
        if (n == mesh::invalid_index)
          continue;
        unsigned int back = 0, shared = 0;
        for (unsigned int g = 0; g < 4; ++g)
          back += mesh.neighbor(n, g) == t;
        for (const unsigned int v : TetMesh::face_vertices[f])
          shared += std::count(mesh.tet(n).begin(), mesh.tet(n).end(), c[v]);
        if (back != 1 || shared != 3)
        {
          problem << "tetrahedra " << t << " and " << n << " are neighbours across face "
                  << f << " but do not share it";
          return problem.str();
        }
      }
    }
    // The boundary closes up: every edge of the boundary faces is used an even number
    // of times (a hanging vertex or an unmatched face breaks this).
    std::map<std::pair<unsigned int, unsigned int>, unsigned int> boundary_edges;
    unsigned int                                                  n_open = 0;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(t, f) == mesh::invalid_index)
        {
          ++n_open;
          const auto &fv = TetMesh::face_vertices[f];
          for (unsigned int k = 0; k < 3; ++k)
          {
            const unsigned int a = mesh.tet(t)[fv[k]], b = mesh.tet(t)[fv[(k + 1) % 3]];
            ++boundary_edges[{std::min(a, b), std::max(a, b)}];
          }
        }
    if (n_open != mesh.get_boundary_faces().size())
      return "the boundary face list does not match the faces without neighbour";
    for (const auto &[e, count] : boundary_edges)
      if (count % 2 != 0)
      {
        problem << "the boundary does not close up at edge " << e.first << "-" << e.second
                << " (a hanging vertex?)";
        return problem.str();
      }
    if (std::abs(mesh.total_volume() - volume) > 1e-9 * std::abs(volume))
    {
      problem << "volume " << mesh.total_volume() << " differs from " << volume;
      return problem.str();
    }
    if (system.springs.size() != mesh.n_edges())
      return "the springs are not the edges";
    for (unsigned int e = 0; e < mesh.n_edges(); ++e)
    {
      const auto &edge = mesh.get_edges()[e];
      if (std::min(system.springs.a[e], system.springs.b[e]) != edge[0]
          || std::max(system.springs.a[e], system.springs.b[e]) != edge[1]
          || !(system.springs.stiffness[e] > 0))
      {
        problem << "spring " << e << " does not match edge " << edge[0] << "-" << edge[1]
                << " or has no stiffness";
        return problem.str();
      }
    }
    double total = 0;
    for (unsigned int i = 0; i < system.n_particles(); ++i)
    {
      if (!(system.mass[i] > 0))
      {
        problem << "particle " << i << " has mass " << system.mass[i];
        return problem.str();
      }
      total += system.mass[i];
    }
    if (std::abs(total - integral_of_density) > 1e-9 * integral_of_density)
    {
      problem << "total mass " << total << " differs from the integral of the density "
              << integral_of_density;
      return problem.str();
    }
    return {};
  }


  std::vector<double>
  component_volumes(const mesh::TetMesh &mesh)
  {
    std::vector<unsigned int> parent(mesh.n_tets());
    std::iota(parent.begin(), parent.end(), 0u);
    const auto find = [&](unsigned int i)
    {
      while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
      return i;
    };
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      for (unsigned int f = 0; f < 4; ++f)
        if (mesh.neighbor(t, f) != mesh::invalid_index)
          parent[find(t)] = find(mesh.neighbor(t, f));
    std::map<unsigned int, double> volumes;
    for (unsigned int t = 0; t < mesh.n_tets(); ++t)
      volumes[find(t)] += mesh.volume(t);
    std::vector<double> result;
    for (const auto &[root, v] : volumes)
      result.push_back(v);
    std::sort(result.begin(), result.end());
    return result;
  }


  unsigned int
  count_components(const mesh::TetMesh &mesh)
  {
    return static_cast<unsigned int>(component_volumes(mesh).size());
  }
} // namespace lacerta::cut
