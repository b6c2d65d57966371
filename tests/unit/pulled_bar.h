// The pulled bar that measures a model's lateral contraction (doc/accuracy.md).
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/scene/scene.h>
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <unistd.h>
#include <vector>

namespace lacerta::test_support
{
  /// The lateral contraction ν_eff = -ε_yy / ε_xx in the middle of a bar clamped at
  /// x = 0 and pulled at x = L, from the displacement @p u of the vertices.
  inline double
  effective_poisson_ratio(const mesh::TetMesh &mesh, const std::vector<double> &u)
  {
    // Least-squares slopes of u_x over x and of u_y over y in the middle fifth.
    double sxx = 0, sx = 0, sux = 0, sxu = 0, syy = 0, sy = 0, suy = 0, syu = 0;
    int    n = 0;
    for (unsigned int v = 0; v < mesh.n_vertices(); ++v)
    {
      const auto &x = mesh.vertex(v);
      if (x[0] < 0.08 || x[0] > 0.12)
        continue;
      sxx += x[0] * x[0];
      sx += x[0];
      sux += u[3 * v];
      sxu += x[0] * u[3 * v];
      syy += x[1] * x[1];
      sy += x[1];
      suy += u[3 * v + 1];
      syu += x[1] * u[3 * v + 1];
      ++n;
    }
    const double exx = (n * sxu - sx * sux) / (n * sxx - sx * sx);
    const double eyy = (n * syu - sy * suy) / (n * syy - sy * sy);
    return -eyy / exx;
  }


  /**
   * A bar 0.2 x 0.02 x 0.02 m (20 x 2 x 2 boxes), clamped at x = 0, pulled by 1 N at
   * x = L, with Poisson ratio @p poisson, spring stiffness @p stiffness (paper or
   * fitted), force model @p model and, for volume springs, the lattice's Poisson ratio
   * @p lattice_poisson.
   */
  inline std::unique_ptr<scene::Scene>
  pulled_bar(const std::string &poisson,
             const std::string &stiffness,
             const std::string &model           = "linear springs",
             const std::string &lattice_poisson = "0.25")
  {
    // The pulling constraint is a named instance: it must be in the file to exist. One
    // file per variant and process: tests run in parallel in one directory.
    std::string name = "pulled_bar_" + model + "_" + stiffness + "_" + poisson + "_"
                       + std::to_string(::getpid()) + ".prm";
    for (char &c : name)
      if (c == ' ')
        c = '_';
    const std::string file = (std::filesystem::temp_directory_path() / name).string();
    std::ofstream(file) << "include " << LACERTA_SCENE_DIR << "/cantilever.prm\n"
                        << "subsection Mesh\n subsection Box\n"
                        << "  set Upper corner = 0.2, 0.02, 0.02\n"
                        << "  set Repetitions = 20, 2, 2\n end\nend\n"
                        << "subsection Body forces\n set List of body forces =\nend\n"
                        << "subsection Material\n set Poisson ratio = " << poisson
                        << "\n set Spring stiffness = " << stiffness << "\nend\n"
                        << "subsection Force model\n set Model = " << model
                        << "\n subsection Volume springs\n  set Lattice Poisson ratio = "
                        << lattice_poisson << "\n end\nend\n"
                        << "subsection Constraints\n set Names = clamp, pull\n"
                        << " subsection pull\n  set Type = force handle\n"
                        << "  set Region = boundary id\n"
                        << "  subsection Boundary id\n   set Boundary ids = 1\n  end\n"
                        << "  subsection Force handle\n   set Force = 1; 0; 0\n  end\n"
                        << " end\nend\n";
    dealii::ParameterHandler prm;
    Simulator::read_parameters(file, prm);
    std::filesystem::remove(file);
    return std::make_unique<scene::Scene>(prm, 1);
  }
} // namespace lacerta::test_support
