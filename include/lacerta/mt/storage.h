/**
 * @file
 * The Multi-Triangulation on disk: a compact, versioned binary file and a cache keyed
 * by the mesh and the builder's parameters.
 */
#pragma once

#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/builder.h>
#include <lacerta/mt/multi_triangulation.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace lacerta::mt
{
  /// Version of the file format; a file of another version is stale.
  constexpr std::uint32_t file_format_version = 2;

  /**
   * A 64-bit hash (FNV-1a) of everything the MT depends on: the mesh's vertices and
   * tetrahedra, the builder's parameters, the locked vertices and the format version.
   */
  std::uint64_t
  cache_key(const mesh::TetMesh             &mesh,
            const BuilderParameters         &parameters,
            const std::vector<unsigned int> &locked);

  /**
   * Writes @p mt to @p file: magic, version, key, array sizes, the arrays as raw
   * little-endian data, and a checksum of all of it. Throws a lacerta::Error naming
   * the file if it cannot be written.
   */
  void
  save(const MultiTriangulation &mt, std::uint64_t key, const std::string &file);

  /**
   * Reads the MT in @p file if it is a complete, uncorrupted file of this version
   * made for @p key; otherwise returns nothing and says why in @p reason.
   */
  std::optional<MultiTriangulation>
  load(const std::string &file, std::uint64_t key, std::string &reason);

  /**
   * What load_or_build() did.
   */
  struct CacheReport
  {
    /// The cache file.
    std::string file;
    /// Whether the MT came from the file.
    bool loaded = false;
    /// Why the file was not used (missing, stale, corrupted), empty if it was.
    std::string reason;
    /// Wall time of the build or of the load (s).
    double seconds = 0;
  };

  /**
   * The MT of @p mesh: loaded from `<directory>/mt-<key>.lmt` if that file is valid,
   * otherwise built and written there (an empty @p directory disables the cache).
   */
  MultiTriangulation
  load_or_build(const mesh::TetMesh             &mesh,
                const BuilderParameters         &parameters,
                const std::vector<unsigned int> &locked,
                const std::string               &directory,
                CacheReport                     &report);
} // namespace lacerta::mt
