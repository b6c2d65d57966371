#include <lacerta/base/checkpoint_file.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/fnv_hash.h>
#include <lacerta/base/output_file.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace lacerta
{
  namespace
  {
    /// The first bytes of every checkpoint, and the version of the state's layout.
    constexpr std::string_view magic          = "LACERTA CHECKPOINT\n";
    constexpr std::uint32_t    format_version = 7;
    constexpr std::size_t      header_bytes =
      magic.size() + sizeof(std::uint32_t) + 2 * sizeof(std::uint64_t);

    /// FNV-1a of @p bytes: enough to tell a damaged file from a whole one.
    std::uint64_t
    checksum(const std::string_view bytes)
    {
      FnvHash hash;
      hash.add(bytes.data(), bytes.size());
      return hash.value;
    }

    template <class T>
    void
    append_number(std::string &out, const T value)
    {
      out.append(reinterpret_cast<const char *>(&value), sizeof(value));
    }

    template <class T>
    T
    number_at(const std::string &in, const std::size_t offset)
    {
      T value;
      std::memcpy(&value, in.data() + offset, sizeof(value));
      return value;
    }
  } // namespace


  void
  write_checkpoint_file(const std::string &file_name, const std::string_view payload)
  {
    std::string contents;
    contents.reserve(header_bytes + payload.size());
    contents.append(magic);
    append_number(contents, format_version);
    append_number(contents, static_cast<std::uint64_t>(payload.size()));
    append_number(contents, checksum(payload));
    contents.append(payload);

    // Keep the current checkpoint as the previous one: a second name for the same
    // file, renamed into place, so that `file_name` itself is never missing.
    const std::string previous = file_name + ".previous";
    if (::access(file_name.c_str(), F_OK) == 0)
    {
      const std::string link_name = previous + ".tmp";
      ::unlink(link_name.c_str());
      if (::link(file_name.c_str(), link_name.c_str()) != 0
          || std::rename(link_name.c_str(), previous.c_str()) != 0)
      {
        const int error = errno;
        ::unlink(link_name.c_str());
        throw_error("Cannot write '", previous, "': ", std::strerror(error), ".");
      }
    }
    write_file_atomically(file_name, contents, true);
  }


  std::string
  read_checkpoint_file(const std::string &file_name)
  {
    std::ifstream in(file_name, std::ios::binary);
    if (!in)
      throw_error(
        "Checkpoint: cannot read '", file_name, "': ", std::strerror(errno), ".");
    const std::string contents((std::istreambuf_iterator<char>(in)),
                               std::istreambuf_iterator<char>());
    if (contents.compare(0, magic.size(), magic) != 0)
      throw_error("Checkpoint: '", file_name, "' is not a Lacerta checkpoint.");
    if (contents.size() < header_bytes)
      throw_error("Checkpoint: '",
                  file_name,
                  "' is truncated: ",
                  contents.size(),
                  " bytes, less than its header.");
    const auto version = number_at<std::uint32_t>(contents, magic.size());
    if (version != format_version)
      throw_error("Checkpoint: '",
                  file_name,
                  "' has format version ",
                  version,
                  "; this Lacerta reads version ",
                  format_version,
                  ".");
    const auto length = number_at<std::uint64_t>(contents, magic.size() + 4);
    const auto sum    = number_at<std::uint64_t>(contents, magic.size() + 12);
    if (contents.size() - header_bytes != length)
      throw_error("Checkpoint: '",
                  file_name,
                  "' is truncated: it holds ",
                  contents.size() - header_bytes,
                  " bytes of state where its header "
                  "announces ",
                  length,
                  ".");
    std::string payload = contents.substr(header_bytes);
    if (checksum(payload) != sum)
      throw_error("Checkpoint: '",
                  file_name,
                  "' is corrupted: its checksum does not "
                  "match its contents.");
    return payload;
  }
} // namespace lacerta
