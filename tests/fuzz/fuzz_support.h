// What the libFuzzer targets share: the input as a file, and the rule for what counts
// as a finding.
#pragma once

#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>

#include <deal.II/base/exceptions.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <unistd.h>

namespace lacerta::fuzz
{
  /**
   * Writes @p size bytes at @p data to a file of this process with the extension
   * @p extension (the readers choose their format by it) and returns its name.
   */
  inline std::string
  input_file(const std::uint8_t *data,
             const std::size_t   size,
             const std::string  &extension)
  {
    const char       *directory = std::getenv("TMPDIR");
    const std::string name      = std::string(directory ? directory : "/tmp")
                             + "/lacerta-fuzz-" + std::to_string(::getpid()) + extension;
    std::FILE *file = std::fopen(name.c_str(), "wb");
    if (file == nullptr)
      std::abort();
    if (size > 0 && std::fwrite(data, 1, size, file) != size)
      std::abort();
    std::fclose(file);
    return name;
  }


  /**
   * Runs @p action on an input: the clear errors Lacerta promises for bad input (an
   * Error, or a deal.II exception naming the entry) are the expected outcome; anything
   * else (a crash, a sanitizer report, another exception, an abort) is a finding.
   */
  template <typename Action>
  void
  expect_clean(const Action &action)
  {
    try
    {
      action();
    }
    catch (const lacerta::Error &)
    {
    }
    catch (const dealii::ExceptionBase &)
    {
    }
  }


  /**
   * Writes the input to a file with the extension @p extension (input_file()) and runs
   * @p read on its name under expect_clean(): what every file-reading target does.
   */
  template <typename Read>
  void
  read_clean(const std::uint8_t *data,
             const std::size_t   size,
             const std::string  &extension,
             const Read         &read)
  {
    const std::string file = input_file(data, size, extension);
    expect_clean([&] { read(file); });
  }

  /**
   * A mesh that a reader accepted is usable: every neighbour index is in range (else
   * abort, a finding).
   */
  inline void
  check_usable(const mesh::TetMesh &m)
  {
    for (unsigned int t = 0; t < m.n_tets(); ++t)
      for (unsigned int f = 0; f < 4; ++f)
      {
        const unsigned int n = m.neighbor(t, f);
        if (n != mesh::invalid_index && n >= m.n_tets())
          std::abort();
      }
  }
} // namespace lacerta::fuzz
