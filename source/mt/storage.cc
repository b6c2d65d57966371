#include <lacerta/base/exceptions.h>
#include <lacerta/base/fnv_hash.h>
#include <lacerta/base/output_file.h>
#include <lacerta/mt/storage.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

namespace lacerta::mt
{
  namespace
  {
    constexpr char magic[8] = {'L', 'A', 'C', 'E', 'R', 'T', 'M', 'T'};

    /// Applies @p f to every array of @p mt, in file order.
    template <typename MT, typename F>
    void
    for_each_array(MT &mt, F &&f)
    {
      f(mt.vertices);
      f(mt.tets);
      f(mt.creator);
      f(mt.destroyer);
      f(mt.fine_begin);
      f(mt.coarse_begin);
      f(mt.coarse_list);
      f(mt.node_vertex);
      f(mt.vertex_node);
      f(mt.error);
      f(mt.ball);
      f(mt.own_error);
      f(mt.own_ball);
    }
  } // namespace


  std::uint64_t
  cache_key(const mesh::TetMesh             &mesh,
            const BuilderParameters         &parameters,
            const std::vector<unsigned int> &locked)
  {
    FnvHash hash;
    hash.add(&file_format_version, sizeof(file_format_version));
    hash.add_vector(mesh.get_vertices());
    hash.add_vector(mesh.get_tets());
    hash.add(&parameters.minimum_quality, sizeof(double));
    hash.add(&parameters.maximum_boundary_error, sizeof(double));
    hash.add(&parameters.boundary_error_weight, sizeof(double));
    hash.add_vector(locked);
    return hash.value;
  }


  void
  save(const MultiTriangulation &mt, const std::uint64_t key, const std::string &file)
  {
    // Written in memory first so that the checksum covers every byte before it.
    std::string buffer(magic, sizeof(magic));
    const auto  put = [&buffer](const void *data, const std::size_t bytes)
    { buffer.append(static_cast<const char *>(data), bytes); };
    put(&file_format_version, sizeof(file_format_version));
    put(&key, sizeof(key));
    for_each_array(mt,
                   [&](const auto &v)
                   {
                     const std::uint64_t n = v.size();
                     put(&n, sizeof(n));
                   });
    for_each_array(mt, [&](const auto &v) { put(v.data(), v.size() * sizeof(v[0])); });
    FnvHash hash;
    hash.add(buffer.data(), buffer.size());
    put(&hash.value, sizeof(hash.value));

    // Replaced atomically: a crash or a full disk never leaves a half-written cache.
    write_file_atomically(file, buffer);
  }


  std::optional<MultiTriangulation>
  load(const std::string &file, const std::uint64_t key, std::string &reason)
  {
    std::ifstream in(file, std::ios::binary);
    if (!in)
    {
      reason = "missing";
      return std::nullopt;
    }
    const std::string buffer((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
    std::size_t       at   = 0;
    const auto        take = [&](void *data, const std::size_t bytes)
    {
      if (buffer.size() - at < bytes)
        return false;
      std::memcpy(data, buffer.data() + at, bytes);
      at += bytes;
      return true;
    };
    char          head[sizeof(magic)];
    std::uint32_t version = 0;
    std::uint64_t stored  = 0;
    if (!take(head, sizeof(head)) || std::memcmp(head, magic, sizeof(magic)) != 0)
    {
      reason = "corrupted (not an MT file)";
      return std::nullopt;
    }
    if (!take(&version, sizeof(version)) || !take(&stored, sizeof(stored)))
    {
      reason = "corrupted (truncated)";
      return std::nullopt;
    }
    if (version != file_format_version || stored != key)
    {
      reason = version != file_format_version
                 ? "stale (format version " + std::to_string(version) + ")"
                 : "stale (made for another mesh or "
                   "other builder parameters)";
      return std::nullopt;
    }
    if (buffer.size() < at + sizeof(std::uint64_t))
    {
      reason = "corrupted (truncated)";
      return std::nullopt;
    }
    FnvHash hash;
    hash.add(buffer.data(), buffer.size() - sizeof(std::uint64_t));
    std::uint64_t checksum = 0;
    std::memcpy(&checksum,
                buffer.data() + buffer.size() - sizeof(checksum),
                sizeof(checksum));
    if (checksum != hash.value)
    {
      reason = "corrupted (checksum mismatch)";
      return std::nullopt;
    }
    MultiTriangulation mt;
    bool               ok = true;
    for_each_array(mt,
                   [&](auto &v)
                   {
                     std::uint64_t n = 0;
                     ok = ok && take(&n, sizeof(n)) && n <= buffer.size() / sizeof(v[0]);
                     if (ok)
                       v.resize(n);
                   });
    for_each_array(mt,
                   [&](auto &v) { ok = ok && take(v.data(), v.size() * sizeof(v[0])); });
    if (!ok || at + sizeof(std::uint64_t) != buffer.size())
    {
      reason = "corrupted (bad array sizes)";
      return std::nullopt;
    }
    try
    {
      mt.check(file);
    }
    catch (const Error &e)
    {
      reason = std::string("corrupted (") + e.what() + ")";
      return std::nullopt;
    }
    return mt;
  }


  MultiTriangulation
  load_or_build(const mesh::TetMesh             &mesh,
                const BuilderParameters         &parameters,
                const std::vector<unsigned int> &locked,
                const std::string               &directory,
                CacheReport                     &report)
  {
    const auto          start = std::chrono::steady_clock::now();
    const std::uint64_t key   = cache_key(mesh, parameters, locked);
    const auto          since = [&start]
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
    };
    report = CacheReport();
    if (!directory.empty())
    {
      std::ostringstream name;
      name << "mt-" << std::hex << key << ".lmt";
      report.file = (std::filesystem::path(directory) / name.str()).string();
      if (auto mt = load(report.file, key, report.reason))
      {
        report.loaded  = true;
        report.seconds = since();
        return std::move(*mt);
      }
    }
    MultiTriangulation mt = build_multi_triangulation(mesh, parameters, locked);
    report.seconds        = since();
    if (!directory.empty())
    {
      std::error_code error;
      std::filesystem::create_directories(directory, error);
      if (error)
        throw_error("Multiresolution/Cache directory: cannot create '", directory, "'.");
      save(mt, key, report.file);
    }
    return mt;
  }
} // namespace lacerta::mt
