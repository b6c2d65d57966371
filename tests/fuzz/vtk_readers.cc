// libFuzzer target: the VTK readers (legacy and XML) on arbitrary files. The first byte
// chooses the format (even: legacy .vtk, odd: .vtu), the rest is the file. A malformed
// file must be an Error naming it; a crash or a sanitizer report is a finding.

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mesh/vtk_reader.h>

#include "fuzz_support.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
  using namespace lacerta;
  if (size < 1)
    return 0;
  fuzz::read_clean(data + 1,
                   size - 1,
                   data[0] % 2 ? ".vtu" : ".vtk",
                   [](const std::string &file)
                   { fuzz::check_usable(mesh::read_vtk_unstructured_grid(file)); });
  return 0;
}
