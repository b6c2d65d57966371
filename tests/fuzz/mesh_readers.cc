// libFuzzer target: the mesh readers (gmsh 2 and 4, legacy VTK, VTU) on arbitrary files.
// The first byte chooses the reader, the rest is the file. A malformed file must be an
// Error naming it; a crash or a sanitizer report is a finding.

#include <lacerta/mesh/gmsh_reader.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mesh/vtk_reader.h>

#include "fuzz_support.h"

extern "C" int
LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
  using namespace lacerta;
  if (size < 1)
    return 0;
  static const char *extensions[] = {".msh", ".vtk", ".vtu"};
  const unsigned int format       = data[0] % 3;
  const std::string  file = fuzz::input_file(data + 1, size - 1, extensions[format]);
  fuzz::expect_clean(
    [&]
    {
      const mesh::TetMesh m = format == 0
                                ? (mesh::check_gmsh_file(file), mesh::read_gmsh(file))
                                : mesh::read_vtk_unstructured_grid(file);
      // A mesh that was accepted is usable: every query stays in range.
      for (unsigned int t = 0; t < m.n_tets(); ++t)
        for (unsigned int f = 0; f < 4; ++f)
        {
          const unsigned int n = m.neighbor(t, f);
          if (n != mesh::invalid_index && n >= m.n_tets())
            std::abort();
        }
    });
  return 0;
}
