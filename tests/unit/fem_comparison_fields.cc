// The fields of the `fem comparison` postprocessor (Time between fields): the files
// hold the mesh at rest and both displacements, consistent with the error it prints.
#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "simulator_test_support.h"
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace lacerta
{
  TEST(FemComparisonFields, FilesHoldBothDisplacementsAndTheirDifference)
  {
    const std::filesystem::path directory =
      std::filesystem::temp_directory_path()
      / ("lacerta_fem_comparison_fields_" + std::to_string(::getpid()));
    std::filesystem::remove_all(directory);
    std::ostringstream scene;
    scene << "include " LACERTA_SCENE_DIR "/square_pull_comparison.prm\n"
          << "set End time = 0.02\nset Test mode = true\n"
          << "set Output directory = " << directory.string() << "\n"
          << "subsection Postprocess\n  subsection Fem comparison\n"
          << "    set Time between fields = 0.01\n    set Number of frequencies = 0\n"
          << "  end\nend\n";
    test::run_scene_quietly(directory.string() + ".prm", scene.str());

    // Written at the first step and then every 0.01 s: 0.0005, 0.01, 0.02.
    for (const char *name :
         {"comparison-00000.vtu", "comparison-00001.vtu", "comparison-00002.vtu"})
      EXPECT_TRUE(std::filesystem::exists(directory / name)) << name;
    EXPECT_FALSE(std::filesystem::exists(directory / "comparison-00003.vtu"));

    auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
    reader->SetFileName((directory / "comparison-00002.vtu").c_str());
    reader->Update();
    vtkUnstructuredGrid *grid = reader->GetOutput();
    ASSERT_EQ(grid->GetNumberOfPoints(), 36);
    EXPECT_EQ(grid->GetNumberOfCells(), 60);
    vtkDataArray *springs    = grid->GetPointData()->GetArray("springs_displacement");
    vtkDataArray *fem        = grid->GetPointData()->GetArray("fem_displacement");
    vtkDataArray *difference = grid->GetPointData()->GetArray("springs_minus_fem");
    ASSERT_TRUE(springs && fem && difference);
    double squared_error = 0, squared_reference = 0;
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
      for (int d = 0; d < 3; ++d)
      {
        const double s = springs->GetComponent(i, d), f = fem->GetComponent(i, d);
        EXPECT_DOUBLE_EQ(difference->GetComponent(i, d), s - f);
        squared_error += (s - f) * (s - f);
        squared_reference += f * f;
      }
    EXPECT_GT(squared_reference, 0);
    // The same error as the table's row of that step.
    double table = -1;
    for (const test::ComparisonRow &row : test::read_comparison_rows(directory))
      if (std::abs(row.time - 0.02) < 1e-9)
        table = row.error_rel_l2;
    ASSERT_GT(table, 0);
    EXPECT_NEAR(std::sqrt(squared_error / squared_reference), table, 1e-5 * table);
    std::filesystem::remove_all(directory);
  }
} // namespace lacerta
