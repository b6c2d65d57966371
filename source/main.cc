// lacerta: runs a scene described by a parameter file.

#include <lacerta/base/exceptions.h>
#include <lacerta/fem/study.h>
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/mpi.h>

#include <iostream>
#include <optional>

int
main(int argc, char **argv)
{
  dealii::deal_II_exceptions::disable_abort_on_exception();
  dealii::deal_II_exceptions::suppress_stacktrace_in_exceptions();

  const std::string first = argc > 1 ? argv[1] : "";
  if (first == "--help" || first == "-h")
  {
    lacerta::Simulator::print_help(std::cout);
    return 0;
  }
  if (argc != 2)
  {
    std::cerr << "Usage: lacerta <scene.prm>   (lacerta --help prints every parameter)\n";
    return 2;
  }

  return lacerta::run_reporting_errors(
    [&]
    {
      dealii::ParameterHandler prm;
      lacerta::Simulator::read_parameters(argv[1], prm);
      // MPI only where it is used: its runtime's start can fail on a busy machine
      // ("Local abort before MPI_INIT completed"), and a scene of springs alone must
      // not depend on it.
      std::optional<dealii::Utilities::MPI::MPI_InitFinalize> mpi;
      if (lacerta::Simulator::needs_mpi(prm))
        mpi.emplace(argc, argv);
      if (prm.get("Mode") == "study")
        lacerta::fem::Study(prm).run();
      else
      {
        lacerta::Simulator simulator(prm, argv[1]);
        simulator.run();
      }
      return 0;
    });
}
