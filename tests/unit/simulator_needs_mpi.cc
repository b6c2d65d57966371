// Which runs initialise MPI (Simulator::needs_mpi()): studies and the FEM reference,
// not the scenes of springs alone, so that those do not depend on the MPI runtime.
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include <string>

namespace lacerta
{
  namespace
  {
    bool
    needs_mpi(const std::string &scene)
    {
      dealii::ParameterHandler prm;
      Simulator::read_parameters(std::string(LACERTA_SCENE_DIR) + "/" + scene, prm);
      return Simulator::needs_mpi(prm);
    }
  } // namespace


  TEST(Simulator, OnlyStudiesAndTheFemReferenceNeedMpi)
  {
    EXPECT_FALSE(needs_mpi("square_cut.prm"));
    EXPECT_FALSE(needs_mpi("kidney_cut.prm"));
    EXPECT_FALSE(needs_mpi("square_tear_lod.prm"));
    EXPECT_TRUE(needs_mpi("square_pull_comparison.prm"));
    EXPECT_TRUE(needs_mpi("cantilever_accuracy.prm"));
  }
} // namespace lacerta
