#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>

#include <cstring>

namespace lacerta
{
  Archive::Archive(std::string &output)
      : output(&output)
  {
  }


  Archive::Archive(const std::string &input, std::string file_name)
      : input(&input)
      , name(std::move(file_name))
  {
  }


  void
  Archive::bytes(void *data, const std::size_t n)
  {
    if (n == 0)
      return;
    if (output != nullptr)
    {
      output->append(static_cast<const char *>(data), n);
      return;
    }
    if (n > input->size() - offset)
      throw_error("The checkpoint '",
                  name,
                  "' ends at byte ",
                  input->size(),
                  " in the middle of the state (",
                  n,
                  " bytes needed at byte ",
                  offset,
                  "): it is truncated or does not belong to this scene.");
    std::memcpy(data, input->data() + offset, n);
    offset += n;
  }


  void
  Archive::section(const std::string &tag)
  {
    std::string found = tag;
    std::size_t n     = tag.size();
    bytes(&n, sizeof(n));
    if (loading())
    {
      if (n > 256)
        throw_error("The checkpoint '",
                    name,
                    "' does not hold the part '",
                    tag,
                    "' at byte ",
                    offset,
                    ": it was written by another scene or another version of Lacerta.");
      found.resize(n);
    }
    bytes(found.data(), n);
    if (found != tag)
      throw_error("The checkpoint '",
                  name,
                  "' holds the part '",
                  found,
                  "' where '",
                  tag,
                  "' was expected: it was written by another scene or another version "
                  "of Lacerta.");
  }


  std::size_t
  Archive::size(const std::size_t n, const std::size_t element_bytes)
  {
    if (!loading())
      return n;
    if (element_bytes > 0 && n > (input->size() - offset) / element_bytes)
      throw_error("The checkpoint '",
                  name,
                  "' holds a size of ",
                  n,
                  " at byte ",
                  offset,
                  ", more than its remaining ",
                  input->size() - offset,
                  " bytes: it is corrupted or does not belong to this scene.");
    return n;
  }


  void
  Archive::finish() const
  {
    if (loading() && offset != input->size())
      throw_error("The checkpoint '",
                  name,
                  "' holds ",
                  input->size() - offset,
                  " bytes after the state of this scene: it was written by another "
                  "scene or another version of Lacerta.");
  }


  namespace internal
  {
    void
    check_presence(Archive &archive, const bool present)
    {
      bool written = present;
      archive.bytes(&written, sizeof(written));
      if (written != present)
        throw_error("The checkpoint '",
                    archive.file_name(),
                    "' ",
                    written ? "holds" : "lacks",
                    " a part of the state that this scene ",
                    present ? "has" : "lacks",
                    ": it was written by another scene.");
    }
  } // namespace internal
} // namespace lacerta
