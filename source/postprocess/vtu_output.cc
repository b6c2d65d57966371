// Postprocessor `vtu`: VTU files and a PVD time series for ParaView.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/spring_strain.h>
#include <lacerta/postprocess/output_schedule.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/scene/material.h>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace lacerta::postprocess
{
  namespace
  {
    vtkSmartPointer<vtkDoubleArray>
    make_array(const char *name, const int components, const vtkIdType tuples)
    {
      auto array = vtkSmartPointer<vtkDoubleArray>::New();
      array->SetName(name);
      array->SetNumberOfComponents(components);
      array->SetNumberOfTuples(tuples);
      return array;
    }


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

        vtkNew<vtkPoints> points;
        points->SetDataTypeToDouble();
        points->SetNumberOfPoints(n);
        auto displacement = make_array("displacement", 3, n);
        auto velocity     = make_array("velocity", 3, n);
        auto mass         = make_array("mass", 1, n);
        auto fixed        = make_array("fixed", 1, n);
        for (unsigned int i = 0; i < n; ++i)
        {
          const double *x = &system.position[3 * i];
          points->SetPoint(i, x);
          for (unsigned int d = 0; d < 3; ++d)
            displacement->SetComponent(i, d, x[d] - system.rest_position()[3 * i + d]);
          velocity->SetTuple(i, &system.velocity[3 * i]);
          mass->SetValue(i, system.mass[i]);
          fixed->SetValue(i, 1.0 - system.free[i]);
        }

        // Springs are the mesh's edges, in the same order.
        std::vector<double> strain(system.springs.size());
        for (std::size_t e = 0; e < strain.size(); ++e)
          strain[e] = physics::spring_strain(system, static_cast<unsigned int>(e));

        vtkNew<vtkCellArray> cells;
        auto                 cell_strain  = make_array("spring_strain", 1, mesh.n_tets());
        auto                 cell_density = make_array("density", 1, mesh.n_tets());
        auto cell_modulus = make_array("youngs_modulus", 1, mesh.n_tets());
        for (unsigned int t = 0; t < mesh.n_tets(); ++t)
        {
          const vtkIdType ids[4] = {mesh.tet(t)[0],
                                    mesh.tet(t)[1],
                                    mesh.tet(t)[2],
                                    mesh.tet(t)[3]};
          cells->InsertNextCell(4, ids);
          double largest = 0;
          for (const unsigned int e : mesh.tet_edges(t))
            if (std::abs(strain[e]) > std::abs(largest))
              largest = strain[e];
          cell_strain->SetValue(t, largest);
          dealii::Point<3> centroid;
          for (const unsigned int v : mesh.tet(t))
            for (unsigned int d = 0; d < 3; ++d)
              centroid[d] += 0.25 * mesh.vertex(v)[d];
          cell_density->SetValue(t, s.material->density().value(centroid));
          cell_modulus->SetValue(t, s.material->youngs_modulus().value(centroid));
        }

        vtkNew<vtkUnstructuredGrid> grid;
        grid->SetPoints(points);
        grid->SetCells(VTK_TETRA, cells);
        for (auto *array : {displacement.Get(), velocity.Get(), mass.Get(), fixed.Get()})
          grid->GetPointData()->AddArray(array);
        for (auto *array : {cell_strain.Get(), cell_density.Get(), cell_modulus.Get()})
          grid->GetCellData()->AddArray(array);

        // The file is composed in memory and then replaced atomically, like the
        // series after it: a write that fails leaves every earlier file and the series
        // that lists them valid.
        char name[64];
        std::snprintf(name, sizeof(name), "solution-%05u.vtu", n_written);
        vtkNew<vtkXMLUnstructuredGridWriter> writer;
        writer->WriteToOutputStringOn();
        writer->SetInputData(grid);
        writer->SetDataModeToAppended();
        writer->SetCompressorTypeToZLib();
        if (writer->Write() != 1)
          throw_error(
            "Cannot write '", directory, "/", name, "': VTK failed to encode it.");
        write_file_atomically(directory + "/" + name, writer->GetOutputString());
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
