// libFuzzer target: the gmsh reader (formats 2 and 4) on arbitrary files. A malformed
// file must be an Error naming it; a crash or a sanitizer report is a finding.

#include <lacerta/mesh/gmsh_reader.h>
#include <lacerta/mesh/tet_mesh.h>

#include "fuzz_support.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
  using namespace lacerta;
  fuzz::read_clean(data,
                   size,
                   ".msh",
                   [](const std::string &file)
                   {
                     mesh::check_gmsh_file(file);
                     fuzz::check_usable(mesh::read_gmsh(file));
                   });
  return 0;
}
