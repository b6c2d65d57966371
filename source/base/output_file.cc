#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <unistd.h>
#include <utility>

namespace lacerta
{
  namespace
  {
    [[noreturn]] void
    fail(const std::string &file_name, const int error)
    {
      throw_error("Cannot write '", file_name, "': ", std::strerror(error), ".");
    }


    // Writes all of @p text to @p descriptor, resuming after partial writes and
    // interruptions; returns 0 or the errno of the write that failed.
    int
    write_all(const int descriptor, std::string_view text)
    {
      while (!text.empty())
      {
        const ssize_t written = ::write(descriptor, text.data(), text.size());
        if (written < 0)
        {
          if (errno == EINTR)
            continue;
          return errno;
        }
        text.remove_prefix(static_cast<std::size_t>(written));
      }
      return 0;
    }


    // Creates or empties @p path; an error names @p file_name, the file the user asked
    // for, even when @p path is its temporary.
    int
    create(const std::string &path, const std::string &file_name)
    {
      const int descriptor =
        ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
      if (descriptor < 0)
        fail(file_name, errno);
      return descriptor;
    }
  } // namespace


  void
  create_output_directory(const std::string &directory)
  {
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    if (error)
      throw_error(
        "Output directory: cannot create '", directory, "': ", error.message(), ".");
  }


  void
  write_file_atomically(const std::string     &file_name,
                        const std::string_view contents,
                        const bool             to_disk)
  {
    const std::string temporary  = file_name + ".tmp";
    const int         descriptor = create(temporary, file_name);
    int               error      = write_all(descriptor, contents);
    if (error == 0 && to_disk && ::fsync(descriptor) != 0)
      error = errno;
    if (::close(descriptor) != 0 && error == 0)
      error = errno;
    if (error == 0 && std::rename(temporary.c_str(), file_name.c_str()) != 0)
      error = errno;
    if (error != 0)
    {
      ::unlink(temporary.c_str());
      fail(file_name, error);
    }
  }


  OutputFile::OutputFile(const std::string &file_name)
      : file_name(file_name)
      , descriptor(create(file_name, file_name))
  {
  }


  OutputFile::OutputFile(OutputFile &&other) noexcept
      : file_name(std::move(other.file_name))
      , descriptor(std::exchange(other.descriptor, -1))
      , written(std::exchange(other.written, 0))
  {
  }


  OutputFile &
  OutputFile::operator=(OutputFile &&other) noexcept
  {
    if (this != &other)
    {
      if (descriptor >= 0)
        ::close(descriptor);
      file_name  = std::move(other.file_name);
      descriptor = std::exchange(other.descriptor, -1);
      written    = std::exchange(other.written, 0);
    }
    return *this;
  }


  OutputFile::~OutputFile()
  {
    if (descriptor >= 0)
      ::close(descriptor);
  }


  void
  OutputFile::append(const std::string_view text)
  {
    if (descriptor < 0)
      throw_error("Cannot write '", file_name, "': the file is not open.");
    if (const int error = write_all(descriptor, text); error != 0)
      fail(file_name, error);
    written += text.size();
  }


  void
  OutputFile::serialize(Archive &archive)
  {
    if (descriptor < 0)
      throw_error("Cannot write '", file_name, "': the file is not open.");
    std::string contents;
    if (!archive.loading())
    {
      // Read back what this object wrote: the file is written, never read, so its
      // first `written` bytes are this object's.
      std::ifstream in(file_name, std::ios::binary);
      contents.resize(written);
      if (!in.read(contents.data(), static_cast<std::streamsize>(written)))
        throw_error("Checkpoint: cannot read back '",
                    file_name,
                    "' (",
                    written,
                    " bytes written so far): it was changed or removed during the run.");
    }
    archive &contents;
    if (archive.loading())
    {
      int error = 0;
      if (::ftruncate(descriptor, 0) != 0 || ::lseek(descriptor, 0, SEEK_SET) != 0)
        error = errno;
      if (error == 0)
        error = write_all(descriptor, contents);
      if (error != 0)
        fail(file_name, error);
      written = contents.size();
    }
  }


  const std::string &
  OutputFile::name() const
  {
    return file_name;
  }
} // namespace lacerta
