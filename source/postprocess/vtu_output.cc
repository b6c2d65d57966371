// Postprocessor `vtu`: VTU files and a PVD time series for ParaView.

#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/spring_strain.h>
#include <lacerta/postprocess/output_schedule.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/postprocess/vtu_file.h>
#include <lacerta/scene/material.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace lacerta::postprocess
{
  namespace
  {
    /**
     * Writes the deformed mesh as solution-NNNNN.vtu (compressed binary) and the series
     * solution.pvd. Point data: displacement, velocity, mass, fixed; cell data: the
     * spring strain of largest magnitude among the cell's edges, density and Young's
     * modulus at the centroid.
     */
    class VtuOutput : public Postprocessor
    {
    public:
      static void
      declare_parameters(dealii::ParameterHandler &prm)
      {
        prm.declare_entry(
          "Time between outputs",
          "0.01",
          dealii::Patterns::Double(0.0),
          "Simulated time between two VTU files [s]; 0 writes every step. "
          "The initial state is always written.");
      }

      void
      parse_parameters(dealii::ParameterHandler &prm) override
      {
        schedule.set_interval(prm.get_double("Time between outputs"));
      }

      void
      initialize(const std::string &output_directory, bool) override
      {
        directory = output_directory;
      }

      bool
      writes_state(const double time) const override
      {
        return schedule.due(time);
      }

      void
      execute(const RunState &s) override
      {
        if (!writes_state(s.time))
          return;
        write(s);
        schedule.written(s.time);
      }

    private:
      void
      write(const RunState &s)
      {
        const mesh::TetMesh           &mesh   = *s.mesh;
        const physics::ParticleSystem &system = *s.system;
        const unsigned int             n      = system.n_particles();

        std::vector<double> displacement(3 * n), fixed(n);
        for (unsigned int i = 0; i < n; ++i)
        {
          for (unsigned int d = 0; d < 3; ++d)
            displacement[3 * i + d] =
              system.position[3 * i + d] - system.rest_position()[3 * i + d];
          fixed[i] = 1.0 - system.free[i];
        }

        // Springs are the mesh's edges, in the same order.
        std::vector<double> strain(system.springs.size());
        for (std::size_t e = 0; e < strain.size(); ++e)
          strain[e] = physics::spring_strain(system, static_cast<unsigned int>(e));

        std::vector<double> cell_strain(mesh.n_tets()), cell_density(mesh.n_tets()),
          cell_modulus(mesh.n_tets());
        for (unsigned int t = 0; t < mesh.n_tets(); ++t)
        {
          double largest = 0;
          for (const unsigned int e : mesh.tet_edges(t))
            if (std::abs(strain[e]) > std::abs(largest))
              largest = strain[e];
          cell_strain[t] = largest;
          dealii::Point<3> centroid;
          for (const unsigned int v : mesh.tet(t))
            for (unsigned int d = 0; d < 3; ++d)
              centroid[d] += 0.25 * mesh.vertex(v)[d];
          cell_density[t] = s.material->density().value(centroid);
          cell_modulus[t] = s.material->youngs_modulus().value(centroid);
        }

        // Each file, then the series that lists it, is replaced atomically: a write
        // that fails leaves every earlier file and the series valid.
        char name[64];
        std::snprintf(name, sizeof(name), "solution-%05u.vtu", n_written);
        write_vtu_file(directory + "/" + name,
                       mesh,
                       system.position,
                       {{"displacement", 3, &displacement},
                        {"velocity", 3, &system.velocity},
                        {"mass", 1, &system.mass},
                        {"fixed", 1, &fixed}},
                       {{"spring_strain", 1, &cell_strain},
                        {"density", 1, &cell_density},
                        {"youngs_modulus", 1, &cell_modulus}});
        ++n_written;

        series.emplace_back(s.time, name);
        std::ostringstream pvd;
        pvd.precision(12);
        pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n "
               " <Collection>\n";
        for (const auto &[time, file] : series)
          pvd << "    <DataSet timestep=\"" << time << "\" group=\"\" part=\"0\" file=\""
              << file << "\"/>\n";
        pvd << "  </Collection>\n</VTKFile>\n";
        write_file_atomically(directory + "/solution.pvd", pvd.str());
      }

      /// The schedule and the series written so far.
      void
      serialize(Archive &archive) override
      {
        archive(schedule, n_written, series);
      }

      OutputSchedule                              schedule;
      unsigned int                                n_written = 0;
      std::string                                 directory;
      std::vector<std::pair<double, std::string>> series;
    };
  } // namespace

  LACERTA_REGISTER_POSTPROCESSOR(
    VtuOutput,
    "vtu",
    "The deformed mesh as VTU files with a PVD time series "
    "(solution.pvd) for ParaView: displacement, velocity, mass, "
    "spring strain, density and Young's modulus "
    "('subsection Vtu').");
} // namespace lacerta::postprocess
