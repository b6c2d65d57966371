// libFuzzer target: a scene's parameter file, read as `lacerta scene.prm` reads it
// (declarations of every plugin, includes, ranges). A malformed file must be an Error
// naming the file and the entry; a crash or a sanitizer report is a finding.

#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include "fuzz_support.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
  using namespace lacerta;
  fuzz::read_clean(data,
                   size,
                   ".prm",
                   [](const std::string &file)
                   {
                     dealii::ParameterHandler prm;
                     Simulator::read_parameters(file, prm);
                   });
  return 0;
}
