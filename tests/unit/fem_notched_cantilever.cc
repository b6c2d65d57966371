// Accuracy after a cut (doc/accuracy.md): prm/notched_cantilever.prm on the coarse mesh
// of cantilever.prm, compared with FEM P2 before the notch (uncut mesh) and after it
// (cut mesh). The FEM on the cut mesh must see the crack: a beam notched on its side in
// tension deflects more than the intact one, which a comparison that kept the uncut
// mesh, or merged the crack's duplicated vertices again, would not show.
#include <gtest/gtest.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include "simulator_test_support.h"
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <string>
#include <unistd.h>
#include <vector>

namespace lacerta
{
  namespace
  {
    /// What a run gives: the rows of comparison.csv, and the largest difference of the
    /// FEM displacements of two vertices at the same rest position (the two sides of
    /// the crack) over that of any vertex, in the fields of the last comparison.
    struct Result
    {
      std::vector<test::ComparisonRow> rows;
      double                           crack_opening = 0, largest_displacement = 0;
    };

    /// The crack opening and largest displacement of fem_displacement in @p file.
    void
    read_crack_opening(const std::filesystem::path &file, Result &result)
    {
      auto reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
      reader->SetFileName(file.c_str());
      reader->Update();
      vtkUnstructuredGrid *grid = reader->GetOutput();
      vtkDataArray        *fem  = grid->GetPointData()->GetArray("fem_displacement");
      ASSERT_TRUE(fem);
      std::map<std::array<double, 3>, vtkIdType> seen;
      for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
      {
        std::array<double, 3> x{}, u{};
        grid->GetPoint(i, x.data());
        fem->GetTuple(i, u.data());
        result.largest_displacement =
          std::max(result.largest_displacement, std::hypot(u[0], u[1], u[2]));
        const auto [other, fresh] = seen.emplace(x, i);
        if (fresh)
          continue;
        std::array<double, 3> v{};
        fem->GetTuple(other->second, v.data());
        result.crack_opening =
          std::max(result.crack_opening,
                   std::hypot(u[0] - v[0], u[1] - v[1], u[2] - v[2]));
      }
    }

    /**
     * Runs the notched cantilever on 10 x 2 x 2 boxes with @p model (the lines that
     * choose it): settled at 0.5 s, notched until 0.6 s, compared at 0.5 s (uncut) and
     * 1.2 s (cut).
     */
    Result
    run_notched_cantilever(const std::string &name, const std::string &model)
    {
      const std::filesystem::path directory =
        std::filesystem::temp_directory_path()
        / ("lacerta_notched_" + name + "_" + std::to_string(::getpid()));
      std::filesystem::remove_all(directory);
      test::run_scene_quietly(
        directory.string() + ".prm",
        "include " LACERTA_SCENE_DIR "/notched_cantilever.prm\n"
        "set Test mode = true\n"
        "set Output directory = "
          + directory.string()
          + "\n"
            "subsection Mesh\n subsection Box\n  set Repetitions = 10, 2, 2\n end\nend\n"
            "subsection Postprocess\n set List of postprocessors = fem comparison\n"
            " subsection Fem comparison\n  set Time between fields = 0.6\n end\nend\n"
          + model);
      Result result;
      result.rows = test::read_comparison_rows(directory);
      // Fields at the two comparisons: 00000 before the cut, 00001 after it.
      read_crack_opening(directory / "comparison-00001.vtu", result);
      std::filesystem::remove_all(directory);
      return result;
    }

    /// The checks every model must pass: two comparisons, the FEM tip (probe at the
    /// free end's centre) lower after the notch, the crack open in the FEM field (its
    /// two sides apart by more than 2 % of the largest displacement: about 0.5 of 6 mm
    /// at the top of the notch), the error after the cut below @p bound.
    void
    check_notched(const Result &result, const double bound)
    {
      EXPECT_GT(result.crack_opening, 0.02 * result.largest_displacement);
      const std::vector<test::ComparisonRow> &rows = result.rows;
      ASSERT_EQ(rows.size(), 2u);
      EXPECT_NEAR(rows[0].time, 0.5, 1e-9);
      EXPECT_NEAR(rows[1].time, 1.2, 1e-9);
      ASSERT_EQ(rows[0].probe.size(), 6u);
      ASSERT_EQ(rows[1].probe.size(), 6u);
      // Probe columns: springs u_x, FEM u_x, springs u_y, FEM u_y, springs u_z, FEM u_z.
      const double fem_before = rows[0].probe[5], fem_after = rows[1].probe[5];
      EXPECT_LT(fem_before, 0);
      // The notch takes up to 9 of the 20 mm of depth near the clamp: the tip sags
      // more. The crack opens in the cells the blade cut through (in these 10 mm
      // cells, the top layer): 4.7 % more sag than before.
      EXPECT_LT(fem_after, 1.03 * fem_before);
      for (const test::ComparisonRow &r : rows)
      {
        EXPECT_TRUE(std::isfinite(r.error_rel_l2));
        EXPECT_GT(r.error_rel_l2, 0);
      }
      EXPECT_LT(rows[1].error_rel_l2, bound);
    }
  } // namespace


  // The paper's springs: 0.31 from FEM P2 on the intact coarse beam, 0.13 on the cut one
  // (doc/accuracy.md, "Accuracy after a cut"); against the intact mesh's FEM the springs'
  // notched tip (5.5 mm) would be about 0.45 off (3.8 mm).
  TEST(NotchedCantilever, SpringsAgainstFemOnTheCutMesh)
  {
    check_notched(run_notched_cantilever("springs", ""), 0.25);
  }


  // Corotated FEM is P1 on the cut tetrahedra, which locks in bending: 0.32 before the
  // cut and 0.40 after it on this mesh; bounded by 0.5.
  TEST(NotchedCantilever, CorotatedFemAgainstFemOnTheCutMesh)
  {
    check_notched(
      run_notched_cantilever("corotated",
                             "subsection Force model\n set Model = corotated fem\nend\n"),
      0.5);
  }
} // namespace lacerta
